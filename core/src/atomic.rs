//! Atomic file output: every file the project writes goes first to a temporary file in
//! the same directory and is renamed into place only when complete, so an interrupted
//! run never leaves a half-written output under the final name. What is not a regular
//! file is never renamed over: a character device (`/dev/null`, `/dev/full`) is written
//! where it is, and its errors reported; anything else (a directory, a pipe, a socket, a
//! block device) is refused. An output that names one of its inputs is refused
//! ([`refuse_overwriting_inputs`]): an output never replaces what it is made from.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{CoreError, Result};

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// The temporary name `path` is written under before the rename.
fn temporary_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".to_string());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.{}.{n}.tmp", std::process::id()))
}

/// Whether `a` and `b` describe one file (the same device and inode).
pub(crate) fn same_inode(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino()
}

/// Refuses to write `output` where it is one of `inputs` (the same file, by whatever
/// path: links and `./` included): an output never replaces what it is made from.
/// Inputs that do not exist are not compared.
pub fn refuse_overwriting_inputs(output: &Path, inputs: &[&Path]) -> Result<()> {
    let Ok(out) = std::fs::metadata(output) else {
        return Ok(());
    };
    for input in inputs {
        if std::fs::metadata(input).is_ok_and(|m| same_inode(&m, &out)) {
            return Err(CoreError::BadOutput {
                path: output.to_path_buf(),
                problem: format!(
                    "is {}, an input of this command: an output never replaces its input; \
                     give another path",
                    input.display()
                ),
            });
        }
    }
    Ok(())
}

/// Writes `path` where it is not a regular file (see the module docs): a character
/// device written in place, anything else refused.
fn write_in_place<F>(path: &Path, meta: &std::fs::Metadata, write: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    use std::os::unix::fs::FileTypeExt;
    if !meta.file_type().is_char_device() {
        return Err(CoreError::BadOutput {
            path: path.to_path_buf(),
            problem: "is not a regular file (a directory, pipe, socket or block device): \
                      refused rather than replaced; give a file's path"
                .into(),
        });
    }
    let file = std::fs::OpenOptions::new()
        .write(true)
        .open(path)
        .map_err(|e| CoreError::io(path, e))?;
    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    writer.flush().map_err(|e| CoreError::io(path, e))
}

/// Writes `path` atomically: `write` fills a buffered temporary file, which is then
/// flushed and renamed to `path`. Parent directories are created. On any error the
/// temporary file is removed and `path` is left as it was; errors name `path`, the output
/// asked for, not the temporary name. Where `path` is not a regular file, nothing is
/// renamed over it (see the module docs).
pub fn write_atomic<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    if let Ok(meta) = std::fs::metadata(path)
        && !meta.is_file()
    {
        return write_in_place(path, &meta, write);
    }
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(|e| CoreError::io(parent, e))?;
    }
    let tmp = temporary_path(path);
    let outcome = (|| {
        let file = File::create(&tmp).map_err(|e| CoreError::io(path, e))?;
        let mut writer = BufWriter::new(file);
        write(&mut writer)?;
        writer.flush().map_err(|e| CoreError::io(path, e))?;
        drop(writer);
        std::fs::rename(&tmp, path).map_err(|e| CoreError::io(path, e))
    })();
    if outcome.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    outcome
}

/// Writes `bytes` to `path` atomically.
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic(path, |w| {
        w.write_all(bytes).map_err(|e| CoreError::io(path, e))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An output that is not a regular file is not renamed over: a directory is
    /// refused by name and stays a directory; a hard link to an input is the input.
    #[test]
    fn a_directory_is_refused_and_a_link_to_an_input_is_the_input() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        let e = write_bytes_atomic(&sub, b"x").unwrap_err();
        assert!(e.to_string().contains("not a regular file"), "{e}");
        assert!(sub.is_dir());
        let input = dir.path().join("in.bin");
        std::fs::write(&input, b"data").unwrap();
        let link = dir.path().join("link.bin");
        std::fs::hard_link(&input, &link).unwrap();
        let e = refuse_overwriting_inputs(&link, &[&input]).unwrap_err();
        assert!(e.to_string().contains("in.bin"), "{e}");
        let other = dir.path().join("other.bin");
        std::fs::write(&other, b"data").unwrap();
        assert!(refuse_overwriting_inputs(&other, &[&input]).is_ok());
        assert!(refuse_overwriting_inputs(&dir.path().join("new.bin"), &[&input]).is_ok());
    }

    #[test]
    fn failed_write_leaves_nothing_behind() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/out.bin");
        let err = write_atomic(&path, |w| {
            w.write_all(b"partial").unwrap();
            Err(CoreError::invalid("test", "abort"))
        });
        let e = err.unwrap_err().to_string();
        assert!(e.contains("test") && e.contains("abort"), "{e}");
        assert!(!path.exists());
        let leftovers: Vec<_> = std::fs::read_dir(path.parent().unwrap()).unwrap().collect();
        assert!(leftovers.is_empty(), "temporary file left behind");
    }

    #[test]
    fn successful_write_replaces_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.bin");
        write_bytes_atomic(&path, b"one").unwrap();
        write_bytes_atomic(&path, b"two").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
    }
}
