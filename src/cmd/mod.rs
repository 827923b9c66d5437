//! One module per subcommand.

pub mod flow;
pub mod stage;
