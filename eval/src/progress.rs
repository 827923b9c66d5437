//! How long evaluations say how far they are: a phase of so many steps, then each step
//! done. The command line draws bars ([`Progress`] for indicatif in `frf`); tests pass
//! [`Silent`].

/// Progress of a long evaluation.
pub trait Progress: Sync {
    /// A new phase of `total` steps, named `what` (e.g. `truth frames`).
    fn phase(&self, what: &str, total: usize);
    /// One step of the current phase done.
    fn step(&self);
    /// The current phase is over.
    fn finish(&self) {}
}

/// Progress that shows nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Progress for Silent {
    fn phase(&self, _what: &str, _total: usize) {}
    fn step(&self) {}
}
