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

use std::collections::BTreeMap;
use std::path::Path;

use frf_core::env::EnvSource;
use frf_reflectance::FieldFile;
use serde::Serialize;
use serde_json::Value;

use crate::error::Result;
use crate::{BackdropSpec, MAX_FILE_BYTES, Scene};

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

/// A file a render reads, by its canonical path and content.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FileIdentity {
    /// Bytes.
    pub bytes: u64,
    /// CRC-32 of its bytes (every file but the field).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crc32: Option<u32>,
    /// CRC-32 of the field's index (which lists every chunk's CRC-32).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub index_crc32: Option<u32>,
    /// Absolute, links resolved.
    pub path: String,
}

impl FileIdentity {
    /// The file at `path`, its bytes read for their CRC-32.
    fn of(path: &Path) -> Result<Self> {
        let (bytes, crc32) = frf_core::io::content_identity(path)?;
        Ok(Self {
            bytes,
            crc32: Some(crc32),
            index_crc32: None,
            path: canonical(path),
        })
    }
}

/// What a render directory's frames are made from (see the module text); `settings.json`
/// is this with the shot's frame count.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RenderSettings {
    /// The command's arguments that change a frame, paths canonical.
    pub args: Value,
    /// Every file the frames read, by name (`field`, `environment N`, `plate`, `camera
    /// path`).
    pub files: BTreeMap<String, FileIdentity>,
    /// The scene file's text (`None` for a field rendered by flags).
    pub scene: Option<String>,
    /// Frame width and height.
    pub size: (u32, u32),
}

/// `path` made absolute with its links resolved, as text (as given when that fails).
fn canonical(path: &Path) -> String {
    std::fs::canonicalize(path)
        .unwrap_or_else(|_| path.to_path_buf())
        .to_string_lossy()
        .into_owned()
}

impl RenderSettings {
    /// The settings of a render of `scene` from `field` at `size` with `args` (the
    /// command's arguments as JSON, sections `camera`, `scene` and `lighting` holding the
    /// flags of `flagged`'s files; see the module text).
    pub fn new(
        (mut args, flagged): (Value, FlagFiles),
        scene: &Scene,
        field: &FieldFile,
        is_scene_file: bool,
        size: (u32, u32),
    ) -> Result<Self> {
        if let Some(a) = args.as_object_mut() {
            for key in ["out", "frames", "input", "field"] {
                a.remove(key);
            }
        }
        // Paths named by flags, made canonical (their content is under "files").
        let mut set = |section: &str, key: &str, path: Option<&Path>| {
            if let (Some(p), Some(v)) = (path, args.pointer_mut(&format!("/{section}/{key}"))) {
                *v = canonical(p).into();
            }
        };
        set("camera", "camera", flagged.camera);
        set("scene", "plate", flagged.plate);
        set("lighting", "env", flagged.env);

        let (bytes, index_crc32) = field.identity();
        let mut files = BTreeMap::new();
        let field = FileIdentity {
            bytes,
            crc32: None,
            index_crc32: Some(index_crc32),
            path: canonical(field.path()),
        };
        files.insert("field".to_string(), field);
        let mut envs: Vec<&Path> = Vec::new();
        for key in &scene.lighting {
            if let EnvSource::File(p) = &key.env
                && !envs.contains(&p.as_path())
            {
                envs.push(p);
            }
        }
        for (i, p) in envs.iter().enumerate() {
            files.insert(format!("environment {}", i + 1), FileIdentity::of(p)?);
        }
        if let BackdropSpec::Plate(p) = &scene.backdrop {
            files.insert("plate".into(), FileIdentity::of(p)?);
        }
        if let Some(p) = flagged.camera {
            files.insert("camera path".into(), FileIdentity::of(p)?);
        }
        let scene = match is_scene_file {
            true => Some(frf_core::io::read_text(flagged.input, MAX_FILE_BYTES)?),
            false => None,
        };
        Ok(Self {
            args,
            files,
            scene,
            size,
        })
    }
}
