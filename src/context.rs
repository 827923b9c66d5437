//! What a command was doing when a library failed, kept with the library's error: the
//! message names both ("environment sky.hdr: ..."), and the exit status stays the
//! library's fault (a map that fails to load is damaged data or I/O, not a usage error),
//! where a message built with `format!` would have lost it.

use std::error::Error;
use std::fmt;

/// A library's error with what the command was doing.
#[derive(Debug)]
pub struct Context {
    what: String,
    source: Box<dyn Error + Send + Sync>,
}

impl Context {
    /// The library's error.
    pub fn inner(&self) -> &(dyn Error + 'static) {
        self.source.as_ref()
    }
}

impl fmt::Display for Context {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.what, self.source)
    }
}

impl Error for Context {
    /// The library's error's own causes (its message is in this one's).
    fn source(&self) -> Option<&(dyn Error + 'static)> {
        self.source.source()
    }
}

/// For `map_err`: `e` with what the command was doing.
pub fn context<E: Into<Box<dyn Error + Send + Sync>>>(
    what: impl Into<String>,
) -> impl FnOnce(E) -> Context {
    let what = what.into();
    move |e| Context {
        what,
        source: e.into(),
    }
}
