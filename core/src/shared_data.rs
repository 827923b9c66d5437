//! Where the real third-party data (Middlebury flow, Sintel, Middlebury multi-view rings,
//! HDR light probes; see `docs/data.md`) lives on this machine.
//!
//! Looked up in order: the `FRF_DATA_DIR` environment variable, then `shared/data` in the
//! workspace's parent directory and its ancestors, then `/work/shared/data`. Tests on real
//! data call [`shared_data_dir`] and skip, saying so on stderr, when it returns `None`.

use std::path::{Path, PathBuf};

/// The shared data directory, if present.
///
/// # Panics
/// When `FRF_DATA_DIR` is set but is not a directory: a mistyped path must fail the tests
/// that read the data, not skip every one of them.
pub fn shared_data_dir() -> Option<PathBuf> {
    match explicit_dir(std::env::var_os("FRF_DATA_DIR")) {
        Ok(Some(dir)) => return Some(dir),
        Ok(None) => {}
        Err(e) => panic!("{e}"),
    }
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).parent()?;
    workspace
        .ancestors()
        .map(|a| a.join("shared/data"))
        .chain([PathBuf::from("/work/shared/data")])
        .find(|d| d.join("README.md").is_file())
}

/// The directory `FRF_DATA_DIR` names (`value`), `None` when unset, an error naming it
/// when it is not a directory.
fn explicit_dir(value: Option<std::ffi::OsString>) -> Result<Option<PathBuf>, String> {
    let Some(value) = value else {
        return Ok(None);
    };
    let dir = PathBuf::from(value);
    if dir.is_dir() {
        Ok(Some(dir))
    } else {
        Err(format!(
            "FRF_DATA_DIR={} is not a directory (unset it to look for shared/data)",
            dir.display()
        ))
    }
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

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test
mod tests {
    use super::*;

    #[test]
    fn a_data_dir_that_is_not_a_directory_is_an_error_naming_it() {
        let file = std::env::current_exe().unwrap();
        let e = explicit_dir(Some(file.clone().into_os_string())).unwrap_err();
        assert!(
            e.contains(&file.display().to_string()) && e.contains("not a directory"),
            "{e}"
        );
        let missing = PathBuf::from("/nonexistent/frf-data");
        let e = explicit_dir(Some(missing.into_os_string()))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("/nonexistent/frf-data") && e.contains("not a directory"),
            "{e}"
        );
        let dir = std::env::temp_dir();
        assert_eq!(
            explicit_dir(Some(dir.clone().into_os_string())),
            Ok(Some(dir))
        );
        assert_eq!(explicit_dir(None), Ok(None));
    }
}
