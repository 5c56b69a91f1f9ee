//! The program's progress bars: the libraries report through [`color::progress::Progress`]
//! and this draws it on stderr (indicatif hides it when stderr is not a terminal).

use indicatif::{ProgressBar, ProgressStyle};

/// An indicatif bar as a library progress reporter.
pub struct Bar(pub ProgressBar);

impl color::progress::Progress for Bar {
    fn stage(&self, what: Option<&str>, total: u64) {
        if let Some(w) = what {
            self.0.set_message(w.to_string());
        }
        self.0.set_length(total);
        self.0.set_position(0);
    }
    fn inc(&self, n: u64) {
        self.0.inc(n);
    }
    fn finish(&self) {
        self.0.finish();
    }
}

/// A bar for a table fit called `what`.
pub fn fit_bar(what: &str) -> Bar {
    let pb = ProgressBar::new(0);
    if let Ok(style) =
        ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} rows, {elapsed} (eta {eta})")
    {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_message(what.to_string());
    Bar(pb)
}

/// Installs [`fit_bar`] as the reporter of fits the colour library starts on its own (the
/// default table's first use).
pub fn install() {
    color::progress::install(|what| Box::new(fit_bar(what)));
}
