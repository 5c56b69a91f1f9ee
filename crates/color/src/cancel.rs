//! The process's one cancellation token.
//!
//! The binary installs the Ctrl-C handler that sets it; long computations anywhere in the
//! workspace (table fits, the path tracer's sample loops, GPU waits, benchmarks) poll it and
//! return an "interrupted" error, writing nothing. It lives here, in the lowest crate, so that
//! every crate can poll the same flag without depending on a signal-handling crate; a library
//! never installs a handler itself (that would fight the program's own).

use std::sync::atomic::{AtomicBool, Ordering};

static CANCELLED: AtomicBool = AtomicBool::new(false);

/// The token itself, for APIs that take a `&AtomicBool` (so tests can pass their own).
pub fn token() -> &'static AtomicBool {
    &CANCELLED
}

/// True once cancellation was requested (Ctrl-C in the `spectra` binary).
pub fn is_cancelled() -> bool {
    CANCELLED.load(Ordering::Relaxed)
}

/// Requests cancellation: what the signal handler calls.
pub fn cancel() {
    CANCELLED.store(true, Ordering::SeqCst);
}

static HOLDS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Work that must not be cut short once begun — writing the samples a checkpoint keeps — holds
/// off the binary's forced exit (the one that ends a command that has not stopped in time)
/// while the guard lives. Cancellation itself is unaffected.
#[must_use = "the hold lasts as long as the guard"]
pub struct Hold(());

/// Starts a [`Hold`].
pub fn hold() -> Hold {
    HOLDS.fetch_add(1, Ordering::SeqCst);
    Hold(())
}

impl Drop for Hold {
    fn drop(&mut self) {
        HOLDS.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Whether some [`Hold`] is alive.
pub fn held() -> bool {
    HOLDS.load(Ordering::SeqCst) > 0
}
