//! Progress drawn as bars (indicatif) on standard error, hidden when it is not a
//! terminal: [`bar`] for a count of steps, [`Bars`] for a [`Progress`] of phases.

use std::sync::Mutex;

use crate::progress::Progress;
use indicatif::{ProgressBar, ProgressStyle};

/// A bar with a message, position/length, elapsed time and ETA.
pub fn bar(message: &str) -> ProgressBar {
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({elapsed}, eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_message(message.to_string());
    // The elapsed time moves while a long step (a large frame) runs.
    bar.enable_steady_tick(std::time::Duration::from_secs(1));
    bar
}

/// An evaluation's progress as one bar per phase ([`bar`]).
#[derive(Default)]
pub struct Bars(Mutex<Option<ProgressBar>>);

impl Bars {
    fn with(&self, f: impl FnOnce(&mut Option<ProgressBar>)) {
        // A poisoned lock only means a bar was being drawn when a thread panicked.
        let mut guard = self.0.lock().unwrap_or_else(|e| e.into_inner());
        f(&mut guard);
    }
}

impl Progress for Bars {
    fn phase(&self, what: &str, total: usize) {
        self.with(|b| {
            if let Some(old) = b.take() {
                old.finish_and_clear();
            }
            let new = bar(what);
            new.set_length(total as u64);
            *b = Some(new);
        });
    }

    fn step(&self) {
        self.with(|b| {
            if let Some(b) = b {
                b.inc(1);
            }
        });
    }

    fn finish(&self) {
        self.with(|b| {
            if let Some(old) = b.take() {
                old.finish_and_clear();
            }
        });
    }

    fn note(&self, what: &str) {
        self.with(|b| match b {
            Some(b) => b.suspend(|| eprintln!("{what}")),
            None => eprintln!("{what}"),
        });
    }
}

impl Drop for Bars {
    fn drop(&mut self) {
        self.finish();
    }
}
