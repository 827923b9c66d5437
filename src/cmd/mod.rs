//! One module per subcommand, plus shared progress reporting.

pub mod progress;
pub mod stage;
