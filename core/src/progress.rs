//! How long work says how far it is: a phase of so many steps, then each step done. The
//! libraries (evaluation, the shot loop) take a `&dyn Progress` from their callers; the
//! command line draws bars (indicatif, in `frf`); tests pass [`Silent`].

/// Progress of long work.
pub trait Progress: Sync {
    /// A new phase of `total` steps, named `what` (e.g. `truth frames`).
    fn phase(&self, what: &str, total: usize);
    /// One step of the current phase done.
    fn step(&self);
    /// The current phase is over.
    fn finish(&self) {}
    /// Something a person should read while the work goes on (e.g. a frame rendered
    /// again); on standard error by default.
    fn note(&self, what: &str) {
        eprintln!("{what}");
    }
}

/// Progress that shows nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Progress for Silent {
    fn phase(&self, _what: &str, _total: usize) {}
    fn step(&self) {}
    fn note(&self, _what: &str) {}
}
