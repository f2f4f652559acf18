//! Progress on stderr for long commands: an `indicatif` bar with rate and ETA on a terminal;
//! elsewhere (a log file, a cluster job's output) a line when the step changes and at most one
//! every ten seconds, with the same rate and ETA.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How often a log line is written when stderr is not a terminal.
const LOG_EVERY: Duration = Duration::from_secs(10);

/// A progress report of `total` steps counted in `unit`s.
pub(crate) struct Progress {
    bar: ProgressBar,
    unit: &'static str,
    terminal: bool,
    what: String,
    logged: Option<Instant>,
}

impl Progress {
    pub(crate) fn new(total: usize, unit: &'static str) -> Self {
        let terminal = std::io::stderr().is_terminal();
        let target = if terminal {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        let bar = ProgressBar::with_draw_target(Some(total as u64), target);
        let template =
            format!("[{{bar:30}}] {{pos:>5}}/{{len}} {unit}, {{per_sec}}, ETA {{eta}}  {{msg}}");
        bar.set_style(
            ProgressStyle::with_template(&template)
                .expect("a valid template")
                .progress_chars("#>."),
        );
        Self {
            bar,
            unit,
            terminal,
            what: String::new(),
            logged: None,
        }
    }

    /// `done` steps finished, working on `what` now.
    pub(crate) fn update(&mut self, done: usize, what: &str) {
        self.bar.set_position(done as u64);
        let changed = what != self.what;
        if changed {
            self.what = what.to_string();
            self.bar.set_message(what.to_string());
        }
        let finished = Some(done as u64) == self.bar.length();
        if finished {
            self.bar.finish();
        }
        if self.terminal {
            return;
        }
        let due = self.logged.is_none_or(|t| t.elapsed() >= LOG_EVERY);
        if changed || due || finished {
            let total = self.bar.length().unwrap_or(0);
            let rate = self.bar.per_sec();
            let eta = if finished || rate <= 0.0 {
                String::new()
            } else {
                format!(", ETA {}", indicatif::HumanDuration(self.bar.eta()))
            };
            eprintln!("[{done}/{total} {}, {rate:.2}/s{eta}] {what}", self.unit);
            self.logged = Some(Instant::now());
        }
    }
}

/// A progress callback for `bench` and `compare`'s frames.
pub(crate) fn frames() -> impl FnMut(fisheye_rt::report::Progress<'_>) {
    let mut progress: Option<Progress> = None;
    move |p: fisheye_rt::report::Progress<'_>| {
        progress
            .get_or_insert_with(|| Progress::new(p.total, "frames"))
            .update(p.done, p.what)
    }
}
