//! One module per subcommand, plus shared progress reporting.

pub mod flow;
pub mod info;
pub mod ingest;
pub mod progress;
pub mod stage;
pub mod stage_field;
