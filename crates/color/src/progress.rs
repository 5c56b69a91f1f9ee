//! How long computations report progress without drawing anything: the library calls a
//! [`Progress`]; the program decides what it looks like (`spectra` shows an indicatif bar on
//! stderr). Like [`crate::cancel`], the library owns the hook and the binary fills it.

use std::sync::OnceLock;

/// Receives the progress of one computation; calls may come from several threads.
pub trait Progress: Sync {
    /// A stage of `total` steps begins; `what`, when given, says what it is.
    fn stage(&self, what: Option<&str>, total: u64);
    /// `n` more steps are done.
    fn inc(&self, n: u64);
    /// The computation is over (its last stage may have ended early).
    fn finish(&self) {}
}

/// Reports nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Progress for Silent {
    fn stage(&self, _: Option<&str>, _: u64) {}
    fn inc(&self, _: u64) {}
}

/// Makes a reporter for a computation the library starts on its own (the first fit of a
/// default table): the program installs one with [`install`]; without it those are silent.
pub type Reporter = fn(&str) -> Box<dyn Progress>;

static REPORTER: OnceLock<Reporter> = OnceLock::new();

/// Installs the program's reporter (the first call wins; later ones are ignored).
pub fn install(reporter: Reporter) {
    let _ = REPORTER.set(reporter);
}

/// A reporter for a computation called `what`: the installed one's, else [`Silent`].
pub fn reporter(what: &str) -> Box<dyn Progress> {
    match REPORTER.get() {
        Some(r) => r(what),
        None => Box::new(Silent),
    }
}
