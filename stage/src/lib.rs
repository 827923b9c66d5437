//! The virtual light stage.
