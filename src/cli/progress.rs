//! The library's progress reports as progress bars and spinners on
//! stderr, and its warnings as one line each.

use std::io::IsTerminal;
use std::sync::{Arc, Mutex, Weak};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use kneeform::Progress;
use kneeform::sanity::Warning;

/// Draws the current stage of a library call on stderr: a bar where the
/// number of steps is known, a spinner where it is not. Off a terminal
/// (a scheduler's log, CI), where no bar is drawn, a line at most every
/// [`LOG_EVERY`]: the stage, done/total, elapsed and remaining.
pub struct Bars {
    bar: Mutex<Option<ProgressBar>>,
    /// The stage as logged off a terminal; `None` on a terminal.
    log: Option<Arc<Mutex<Logged>>>,
}

/// How often a progress line is printed off a terminal, unless the
/// environment's `KNEEFORM_PROGRESS_EVERY` gives other seconds.
pub const LOG_EVERY: Duration = Duration::from_secs(10);

/// [`LOG_EVERY`], or `KNEEFORM_PROGRESS_EVERY` seconds (0.05 to 86400).
fn log_every() -> Duration {
    std::env::var("KNEEFORM_PROGRESS_EVERY")
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|s| (0.05..=86_400.0).contains(s))
        .map_or(LOG_EVERY, Duration::from_secs_f64)
}

/// The stage in progress, for the progress lines off a terminal.
struct Logged {
    what: String,
    total: Option<u64>,
    done: u64,
    began: Instant,
    active: bool,
    last_line: Instant,
    every: Duration,
}

impl Logged {
    /// The line for the stage now, when one is due ([`LOG_EVERY`] since
    /// the last), marking it printed.
    fn due_line(&mut self) -> Option<String> {
        let now = Instant::now();
        if !self.active || now.duration_since(self.last_line) < self.every {
            return None;
        }
        self.last_line = now;
        let elapsed = now.duration_since(self.began).as_secs_f64();
        Some(match self.total {
            Some(total) if self.done > 0 => {
                let left = elapsed * (total.saturating_sub(self.done)) as f64 / self.done as f64;
                format!(
                    "kneeform: {}: {}/{total}, {} elapsed, about {} left",
                    self.what,
                    self.done,
                    kneeform::limits::duration_words(elapsed),
                    kneeform::limits::duration_words(left)
                )
            }
            Some(total) => format!(
                "kneeform: {}: 0/{total}, {} elapsed",
                self.what,
                kneeform::limits::duration_words(elapsed)
            ),
            None => format!(
                "kneeform: {}: {} elapsed",
                self.what,
                kneeform::limits::duration_words(elapsed)
            ),
        })
    }
}

/// The progress ticker's stack: it formats a line and sleeps.
const TICKER_STACK_BYTES: usize = 64 * 1024;

impl Default for Bars {
    fn default() -> Bars {
        let log = (!std::io::stderr().is_terminal()).then(|| {
            let now = Instant::now();
            let every = log_every();
            let log = Arc::new(Mutex::new(Logged {
                what: String::new(),
                total: None,
                done: 0,
                began: now,
                active: false,
                last_line: now,
                every,
            }));
            // A stage whose steps are slow (or that has none) still gets
            // its line: a ticker that ends with the bars. Where the system
            // gives no thread (`ulimit -v` leaves no room for its stack),
            // the lines come with the steps alone.
            let weak: Weak<Mutex<Logged>> = Arc::downgrade(&log);
            let _ = std::thread::Builder::new()
                .name("progress".into())
                .stack_size(TICKER_STACK_BYTES)
                .spawn(move || {
                    loop {
                        std::thread::sleep((every / 2).min(Duration::from_secs(1)));
                        let Some(log) = weak.upgrade() else { return };
                        let line = log.lock().unwrap_or_else(|e| e.into_inner()).due_line();
                        if let Some(line) = line {
                            eprintln!("{line}");
                        }
                    }
                });
            log
        });
        Bars {
            bar: Mutex::new(None),
            log,
        }
    }
}

impl Bars {
    fn current(&self) -> std::sync::MutexGuard<'_, Option<ProgressBar>> {
        // A panic elsewhere while drawing must not hide the real error.
        self.bar.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The logged stage, off a terminal.
    fn logged(&self) -> Option<std::sync::MutexGuard<'_, Logged>> {
        self.log
            .as_ref()
            .map(|l| l.lock().unwrap_or_else(|e| e.into_inner()))
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
        if let Some(mut log) = self.logged() {
            log.what = what.to_string();
            log.total = total;
            log.done = 0;
            log.began = Instant::now();
            log.active = true;
        }
        if let Some(old) = self.current().replace(bar) {
            old.finish_and_clear();
        }
    }

    fn step(&self) {
        if let Some(bar) = self.current().as_ref() {
            bar.inc(1);
        }
        let line = self.logged().and_then(|mut log| {
            log.done += 1;
            log.due_line()
        });
        if let Some(line) = line {
            eprintln!("{line}");
        }
    }

    fn end(&self) {
        if let Some(mut log) = self.logged() {
            log.active = false;
        }
        if let Some(bar) = self.current().take() {
            bar.finish_and_clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_progress_line_says_done_total_elapsed_and_left() {
        let long_ago = Instant::now() - Duration::from_secs(120);
        let mut log = Logged {
            what: "exact oracle".into(),
            total: Some(400),
            done: 100,
            began: long_ago,
            active: true,
            last_line: long_ago,
            every: LOG_EVERY,
        };
        assert_eq!(
            log.due_line().as_deref(),
            Some("kneeform: exact oracle: 100/400, 2m00s elapsed, about 6m00s left")
        );
        // At most one line every LOG_EVERY.
        assert_eq!(log.due_line(), None);
        assert_eq!(kneeform::limits::duration_words(3725.0), "1h02m05s");
    }
}
