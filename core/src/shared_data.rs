//! Where the real third-party data (Middlebury flow, Sintel, Middlebury multi-view rings,
//! HDR light probes; see `docs/data.md`) lives on this machine.
//!
//! Looked up in order: the `FRF_DATA_DIR` environment variable, then `shared/data` in the
//! workspace's parent directory and its ancestors, then `/work/shared/data`. Tests on real
//! data call [`shared_data_dir`] and skip, saying so on stderr, when it returns `None`.

use std::path::{Path, PathBuf};

/// The shared data directory, if present.
pub fn shared_data_dir() -> Option<PathBuf> {
    if let Some(dir) = std::env::var_os("FRF_DATA_DIR") {
        let dir = PathBuf::from(dir);
        return dir.is_dir().then_some(dir);
    }
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).parent()?;
    workspace
        .ancestors()
        .map(|a| a.join("shared/data"))
        .chain([PathBuf::from("/work/shared/data")])
        .find(|d| d.join("README.md").is_file())
}

/// `shared_data_dir()/relative` if it exists; otherwise prints why the caller skips.
pub fn shared_data(relative: &str) -> Option<PathBuf> {
    let found = shared_data_dir()
        .map(|d| d.join(relative))
        .filter(|p| p.exists());
    if found.is_none() {
        eprintln!("shared data {relative:?} not found (set FRF_DATA_DIR); skipping");
    }
    found
}
