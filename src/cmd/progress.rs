//! Progress bars for long commands (indicatif), drawn on stderr and hidden when stderr
//! is not a terminal.

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
    bar
}
