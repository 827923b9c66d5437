//! One module per subcommand.

pub mod stage;
