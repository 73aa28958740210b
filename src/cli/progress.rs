//! The library's progress reports as progress bars and spinners on
//! stderr, and its warnings as one line each.

use std::sync::Mutex;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use kneeform::Progress;
use kneeform::sanity::Warning;

/// Draws the current stage of a library call on stderr: a bar where the
/// number of steps is known, a spinner where it is not.
#[derive(Default)]
pub struct Bars {
    bar: Mutex<Option<ProgressBar>>,
}

impl Bars {
    fn current(&self) -> std::sync::MutexGuard<'_, Option<ProgressBar>> {
        // A panic elsewhere while drawing must not hide the real error.
        self.bar.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl Bars {
    /// A line on stderr, above the bar if one is shown.
    fn say(&self, line: &str) {
        match self.current().as_ref() {
            Some(bar) => bar.suspend(|| eprintln!("{line}")),
            None => eprintln!("{line}"),
        }
    }
}

impl Progress for Bars {
    fn warn(&self, warning: &Warning) {
        self.say(&format!("kneeform: warning: {warning}"));
    }

    fn note(&self, line: &str) {
        self.say(&format!("kneeform: {line}"));
    }

    fn begin(&self, what: &str, total: Option<u64>) {
        let bar = match total {
            Some(n) => ProgressBar::new(n).with_style(
                ProgressStyle::with_template(
                    "{prefix} [{bar:30}] {pos}/{len}, {elapsed} ({eta} left)",
                )
                .expect("static template")
                .progress_chars("=> "),
            ),
            None => {
                let spinner = ProgressBar::new_spinner().with_style(
                    ProgressStyle::with_template("{spinner} {prefix} {elapsed}")
                        .expect("static template"),
                );
                spinner.enable_steady_tick(Duration::from_millis(120));
                spinner
            }
        };
        bar.set_prefix(what.to_string());
        if let Some(old) = self.current().replace(bar) {
            old.finish_and_clear();
        }
    }

    fn step(&self) {
        if let Some(bar) = self.current().as_ref() {
            bar.inc(1);
        }
    }

    fn end(&self) {
        if let Some(bar) = self.current().take() {
            bar.finish_and_clear();
        }
    }
}
