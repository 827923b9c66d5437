//! What a render directory's frames are made from, as `settings.json` keeps it and a rerun
//! compares it (`Output::open` resumes only when they are equal): the arguments that change
//! a frame, every path in them made canonical (`shot/` and `$PWD/shot/` are one
//! directory, `scene.toml` and `./scene.toml` one file); the scene file's text; and the
//! identity of every file the frames read — the field by its size and the CRC-32 of its
//! index (which lists every chunk's CRC-32), the environments, the plate and the camera
//! path by their size and the CRC-32 of their bytes. A field rewritten in place is
//! therefore other settings, not a resume.
//!
//! Left out: the output directory (it is where the settings are), the frame range (the
//! tasks of a farm job share a directory) and the flags that do not change a frame.

use std::path::Path;

use frf_core::env::EnvSource;
use frf_reflectance::FieldFile;
use frf_scene::{BackdropSpec, Scene};
use serde_json::{Value, json};

use crate::CliResult;

/// The files a render's flags name: their paths are made canonical in the settings, and
/// their content identified.
pub struct FlagFiles<'a> {
    /// The scene file or field given.
    pub input: &'a Path,
    /// `--camera`.
    pub camera: Option<&'a Path>,
    /// `--plate`.
    pub plate: Option<&'a Path>,
    /// `--env`, when a file.
    pub env: Option<&'a Path>,
}

/// `path` made absolute with its links resolved, as text (as given when that fails).
fn canonical(path: &Path) -> String {
    std::fs::canonicalize(path)
        .unwrap_or_else(|_| path.to_path_buf())
        .to_string_lossy()
        .into_owned()
}

/// A file by its canonical path and content.
fn file_entry(path: &Path) -> CliResult<Value> {
    let (bytes, crc32) = frf_core::io::content_identity(path)?;
    Ok(json!({ "path": canonical(path), "bytes": bytes, "crc32": crc32 }))
}

/// The settings of a render of `scene` from `field` at `size` with `args` (the command's
/// arguments; `flagged`, the files they name; see the module text).
pub fn render_settings(
    (args, flagged): (&impl serde::Serialize, FlagFiles),
    scene: &Scene,
    field: &FieldFile,
    is_scene_file: bool,
    size: (u32, u32),
) -> CliResult<Value> {
    let mut args_json = serde_json::to_value(args)?;
    if let Some(a) = args_json.as_object_mut() {
        for key in ["out", "frames", "input", "field"] {
            a.remove(key);
        }
    }
    // Paths named by flags, made canonical (their content is under "files").
    let mut set = |section: &str, key: &str, path: Option<&Path>| {
        if let (Some(p), Some(v)) = (path, args_json.pointer_mut(&format!("/{section}/{key}"))) {
            *v = canonical(p).into();
        }
    };
    set("camera", "camera", flagged.camera);
    set("scene", "plate", flagged.plate);
    set("lighting", "env", flagged.env);

    let (bytes, index_crc32) = field.identity();
    let mut files = serde_json::Map::new();
    files.insert(
        "field".into(),
        json!({ "path": canonical(field.path()), "bytes": bytes, "index_crc32": index_crc32 }),
    );
    let mut envs: Vec<&Path> = Vec::new();
    for key in &scene.lighting {
        if let EnvSource::File(p) = &key.env
            && !envs.contains(&p.as_path())
        {
            envs.push(p);
        }
    }
    for (i, p) in envs.iter().enumerate() {
        files.insert(format!("environment {}", i + 1), file_entry(p)?);
    }
    if let BackdropSpec::Plate(p) = &scene.backdrop {
        files.insert("plate".into(), file_entry(p)?);
    }
    if let Some(p) = flagged.camera {
        files.insert("camera path".into(), file_entry(p)?);
    }
    let scene_text = match is_scene_file {
        true => Some(frf_core::io::read_text(
            flagged.input,
            frf_scene::MAX_FILE_BYTES,
        )?),
        false => None,
    };
    Ok(json!({
        "args": args_json,
        "scene": scene_text,
        "size": size,
        "files": files,
    }))
}
