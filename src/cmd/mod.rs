//! One module per subcommand, plus shared argument parsing.

pub mod args;
pub mod bench;
pub mod claim;
pub mod env_sh;
pub mod eval;
pub mod export;
pub mod flow;
pub mod for_scene;
pub mod hull;
pub mod info;
pub mod ingest;
pub mod merge;
pub mod olat;
pub mod render;
pub mod report;
pub mod stage;
pub mod stage_field;
pub mod view;
