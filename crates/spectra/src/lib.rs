//! spectra's commands as a library: the `spectra` binary (`main.rs`) parses the command line
//! and calls them, and the Python package (`python/`) calls the same code, so a render, a
//! truth or an evaluation from Python is the command's.
//!
//! Each subcommand lives in its own file under `cmd/`; the evaluation's suite, measurements
//! and report under `eval/`; the interactive viewer under `view/` (feature `viewer`).

pub mod cmd;
pub mod eval;
pub mod progress;
#[cfg(feature = "viewer")]
pub mod view;
