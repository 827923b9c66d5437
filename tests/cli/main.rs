//! The command-line tests: every verb of the `frf` binary run as a user runs it, the
//! bad-input corpus, and interruption. One test binary holds them all (one link of the
//! whole program instead of one per file); each module is one verb or concern.

mod common;

mod adapter;
mod bad_input;
mod bench;
mod export;
mod interrupt;
mod olat;
mod outputs;
mod player;
mod player_ktx2;
mod player_mask;
mod player_motion;
mod player_scene;
mod player_sun;
mod render;
mod report;
mod resume;
mod ring;
mod scene;
mod sh;
mod stage;
mod status;
mod time;
mod verbs;
mod view;
