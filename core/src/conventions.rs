//! The conventions every crate follows (axes, frames, units, pixel and flow
//! coordinates, colour). The text lives in `docs/conventions.md` so that it can be read
//! on its own; it is included here so that every crate can link to it.
#![doc = include_str!("../../docs/conventions.md")]
