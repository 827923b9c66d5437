//! The field file: one container with an index, so that one pose, or one view of one
//! pose, is read without reading the rest (docs/design.md section 3.5).
//!
//! ```text
//! preamble  "FRFFIELD" | version u32 | 0 u32                         16 bytes
//! chunks    basis mosaics, alpha planes, flow maps, shadow maps, hulls   any order
//! index     zstd(JSON { header, chunks: [{ key, offset, length, crc32 }] })
//! footer    index offset u64 | index length u64 | index crc32 u32 | version u32 | "FRFEND\0\0"
//! ```
//!
//! Every chunk and the index carry a CRC-32; a damaged or truncated file is refused with
//! an error naming the chunk. Reading trusts nothing in the file: offsets must lie inside
//! it, and sizes are bounded before anything is allocated. Writing goes to a temporary
//! file renamed into place by [`FieldWriter::finish`]; a writer dropped before that leaves
//! nothing behind.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use serde::{Deserialize, Serialize};

pub use crate::chunk::{ChunkKey, ChunkKind};
use crate::error::{ReflectanceError, Result};
use crate::field::FieldHeader;
use crate::imagecodec::ZSTD_LEVEL;

/// Version of the file layout this code reads and writes.
pub const VERSION: u32 = 1;
const MAGIC: &[u8; 8] = b"FRFFIELD";
const END_MAGIC: &[u8; 8] = b"FRFEND\0\0";
const PREAMBLE_BYTES: u64 = 16;
const FOOTER_BYTES: u64 = 32;
/// Largest decompressed index accepted (a 36x3 grid of 30 poses needs ~2 MB).
const MAX_INDEX_BYTES: usize = 256 << 20;
/// Largest chunk accepted (a 4096x4096 mosaic of 26 tiles is far below).
const MAX_CHUNK_BYTES: u64 = 1 << 30;

/// Whether checksums are verified: always, except in fuzzing builds (`--cfg fuzzing`,
/// set by `cargo fuzz`), where a mutated byte would otherwise stop nearly every input
/// at the checksum and the decoders behind it would never be reached.
const fn checksums_checked() -> bool {
    !cfg!(fuzzing)
}

/// Where a chunk is and its checksum.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ChunkEntry {
    /// Which chunk.
    pub key: ChunkKey,
    /// Byte offset in the file.
    pub offset: u64,
    /// Length in bytes.
    pub length: u64,
    /// CRC-32 (IEEE) of the bytes.
    pub crc32: u32,
}

#[derive(Serialize, Deserialize)]
struct Index {
    header: FieldHeader,
    chunks: Vec<ChunkEntry>,
}

/// Random-access reading of a field's bytes (a file, or memory in tests and fuzzing).
pub trait ReadAt: Send + Sync {
    /// Fills `buf` from `offset`.
    fn read_exact_at(&self, offset: u64, buf: &mut [u8]) -> std::io::Result<()>;
    /// Total length in bytes.
    fn size(&self) -> u64;
}

/// A file opened for [`ReadAt`].
pub struct FileSource {
    file: Mutex<File>,
    size: u64,
}

impl ReadAt for FileSource {
    fn read_exact_at(&self, offset: u64, buf: &mut [u8]) -> std::io::Result<()> {
        let mut f = self
            .file
            .lock()
            .map_err(|_| std::io::Error::other("file lock poisoned"))?;
        f.seek(SeekFrom::Start(offset))?;
        f.read_exact(buf)
    }
    fn size(&self) -> u64 {
        self.size
    }
}

impl ReadAt for Vec<u8> {
    fn read_exact_at(&self, offset: u64, buf: &mut [u8]) -> std::io::Result<()> {
        let start = usize::try_from(offset).map_err(std::io::Error::other)?;
        let src = start
            .checked_add(buf.len())
            .and_then(|end| self.get(start..end))
            .ok_or_else(|| std::io::Error::from(std::io::ErrorKind::UnexpectedEof))?;
        buf.copy_from_slice(src);
        Ok(())
    }
    fn size(&self) -> u64 {
        self.len() as u64
    }
}

/// Writes a field file chunk by chunk.
pub struct FieldWriter {
    path: PathBuf,
    tmp: PathBuf,
    out: Option<BufWriter<File>>,
    offset: u64,
    header: FieldHeader,
    chunks: BTreeMap<ChunkKey, ChunkEntry>,
}

impl FieldWriter {
    /// Starts writing `path` (through a temporary file beside it).
    pub fn create(path: &Path, header: FieldHeader) -> Result<Self> {
        header.validate().map_err(ReflectanceError::Misuse)?;
        if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(parent).map_err(|e| io(parent, e))?;
        }
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let tmp = path.with_file_name(format!(".{name}.{}.tmp", std::process::id()));
        let file = File::create(&tmp).map_err(|e| io(&tmp, e))?;
        let mut out = BufWriter::new(file);
        let mut preamble = Vec::with_capacity(PREAMBLE_BYTES as usize);
        preamble.extend_from_slice(MAGIC);
        preamble.extend_from_slice(&VERSION.to_le_bytes());
        preamble.extend_from_slice(&0u32.to_le_bytes());
        out.write_all(&preamble).map_err(|e| io(&tmp, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            tmp,
            out: Some(out),
            offset: PREAMBLE_BYTES,
            header,
            chunks: BTreeMap::new(),
        })
    }

    /// The header being written.
    pub fn header(&self) -> &FieldHeader {
        &self.header
    }

    /// The path the field is written to (once finished).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Appends a chunk; a key may be written once.
    pub fn add_chunk(&mut self, key: ChunkKey, bytes: &[u8]) -> Result<()> {
        if self.chunks.contains_key(&key) {
            return Err(ReflectanceError::Misuse(format!(
                "{}: {key} written twice",
                self.path.display()
            )));
        }
        let out = self
            .out
            .as_mut()
            .ok_or_else(|| ReflectanceError::Misuse("writer finished".into()))?;
        out.write_all(bytes).map_err(|e| io(&self.tmp, e))?;
        self.chunks.insert(
            key,
            ChunkEntry {
                key,
                offset: self.offset,
                length: bytes.len() as u64,
                crc32: crc32fast::hash(bytes),
            },
        );
        self.offset += bytes.len() as u64;
        Ok(())
    }

    /// Writes the index and footer and renames the file into place.
    pub fn finish(mut self) -> Result<()> {
        let index = Index {
            header: self.header.clone(),
            chunks: self.chunks.values().copied().collect(),
        };
        let json = serde_json::to_vec(&index).map_err(|e| ReflectanceError::Codec {
            what: "the field's index as JSON",
            problem: e.to_string(),
        })?;
        let packed = zstd::bulk::compress(&json, ZSTD_LEVEL).map_err(|e| io(&self.tmp, e))?;
        let mut footer = Vec::with_capacity(FOOTER_BYTES as usize);
        footer.extend_from_slice(&self.offset.to_le_bytes());
        footer.extend_from_slice(&(packed.len() as u64).to_le_bytes());
        footer.extend_from_slice(&crc32fast::hash(&packed).to_le_bytes());
        footer.extend_from_slice(&VERSION.to_le_bytes());
        footer.extend_from_slice(END_MAGIC);
        let Some(mut out) = self.out.take() else {
            return Err(ReflectanceError::Misuse("writer finished".into()));
        };
        out.write_all(&packed).map_err(|e| io(&self.tmp, e))?;
        out.write_all(&footer).map_err(|e| io(&self.tmp, e))?;
        let file = out
            .into_inner()
            .map_err(|e| io(&self.tmp, e.into_error()))?;
        file.sync_all().map_err(|e| io(&self.tmp, e))?;
        drop(file);
        std::fs::rename(&self.tmp, &self.path).map_err(|e| io(&self.path, e))
    }
}

impl Drop for FieldWriter {
    fn drop(&mut self) {
        if self.out.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

fn io(path: &Path, source: std::io::Error) -> ReflectanceError {
    ReflectanceError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Poses' visual hulls decoded and still held somewhere, by pose
/// ([`FieldFile::hull_shared`]).
pub(crate) type SharedHulls =
    std::sync::Mutex<std::collections::HashMap<u32, std::sync::Weak<crate::hull::VoxelHull>>>;

/// A field file opened for reading: its header and index are read; chunks on demand.
pub struct FieldFile<R: ReadAt = FileSource> {
    path: PathBuf,
    source: R,
    header: FieldHeader,
    chunks: BTreeMap<ChunkKey, ChunkEntry>,
    /// CRC-32 of the packed index, as the footer holds it.
    index_crc: u32,
    /// Bytes of chunks read so far (what a plan saves is measured on it).
    bytes_read: std::sync::atomic::AtomicU64,
    /// Views' basis images kept decoded ([`FieldFile::keep_decoded`]).
    pub(crate) decoded: crate::decoded::DecodedBasis,
    /// The projector of the field's conditions, made on first use
    /// ([`FieldFile::projector`]).
    pub(crate) projector: std::sync::OnceLock<std::sync::Arc<crate::project::Projector>>,
    /// Poses' visual hulls decoded and still held somewhere ([`FieldFile::hull_shared`]).
    pub(crate) hulls: SharedHulls,
}

impl FieldFile<FileSource> {
    /// Opens a field file.
    pub fn open(path: &Path) -> Result<Self> {
        // Checked before opening: opening a FIFO waits for a writer.
        frf_core::io::regular_file(path)?;
        let file = File::open(path).map_err(|e| io(path, e))?;
        let size = file.metadata().map_err(|e| io(path, e))?.len();
        Self::from_source(
            path,
            FileSource {
                file: Mutex::new(file),
                size,
            },
        )
    }
}

impl<R: ReadAt> FieldFile<R> {
    /// Reads the header and index from `source`; `path` names it in errors.
    pub fn from_source(path: &Path, source: R) -> Result<Self> {
        let bad = |problem: String| ReflectanceError::BadFile {
            path: path.to_path_buf(),
            problem,
        };
        let size = source.size();
        if size < PREAMBLE_BYTES + FOOTER_BYTES {
            return Err(bad(format!(
                "{size} bytes is too short for a field file (truncated?)"
            )));
        }
        let mut preamble = [0u8; PREAMBLE_BYTES as usize];
        source
            .read_exact_at(0, &mut preamble)
            .map_err(|e| io(path, e))?;
        if &preamble[..8] != MAGIC {
            return Err(bad("not a field file (bad magic)".into()));
        }
        let version = u32::from_le_bytes([preamble[8], preamble[9], preamble[10], preamble[11]]);
        if version != VERSION {
            return Err(bad(format!(
                "format version {version}, this build reads {VERSION}"
            )));
        }
        let mut footer = [0u8; FOOTER_BYTES as usize];
        source
            .read_exact_at(size - FOOTER_BYTES, &mut footer)
            .map_err(|e| io(path, e))?;
        if &footer[24..] != END_MAGIC {
            // Bytes after a whole field's end read otherwise as a truncation.
            let tail = size.min(1 << 20);
            let mut last = vec![0u8; tail as usize];
            source
                .read_exact_at(size - tail, &mut last)
                .map_err(|e| io(path, e))?;
            if let Some(at) = last.windows(END_MAGIC.len()).rposition(|w| w == END_MAGIC) {
                let extra = tail - (at + END_MAGIC.len()) as u64;
                return Err(bad(format!(
                    "{extra} bytes follow the field's end (appended to it, or two files joined): \
                     the file is not as it was written"
                )));
            }
            return Err(bad(
                "footer missing: the file is truncated or was not finished".into(),
            ));
        }
        let footer_version = u32::from_le_bytes([footer[20], footer[21], footer[22], footer[23]]);
        if footer_version != version {
            return Err(bad(format!(
                "the footer says format version {footer_version}, the preamble {version} \
                 (damaged file)"
            )));
        }
        let u64_at = |i: usize| u64::from_le_bytes(footer[i..i + 8].try_into().unwrap_or([0; 8]));
        let (index_offset, index_length) = (u64_at(0), u64_at(8));
        let index_crc = u32::from_le_bytes([footer[16], footer[17], footer[18], footer[19]]);
        if index_offset < PREAMBLE_BYTES
            || index_offset.checked_add(index_length) != Some(size - FOOTER_BYTES)
            || index_length as usize > MAX_INDEX_BYTES
        {
            return Err(bad(format!(
                "index at {index_offset}+{index_length} does not end at the footer ({})",
                size - FOOTER_BYTES
            )));
        }
        let mut packed = vec![0u8; index_length as usize];
        source
            .read_exact_at(index_offset, &mut packed)
            .map_err(|e| io(path, e))?;
        if checksums_checked() && crc32fast::hash(&packed) != index_crc {
            return Err(bad("index checksum mismatch (damaged file)".into()));
        }
        // The size the frame declares is checked before anything is reserved.
        let json = crate::unzstd::decompress_at_most(&packed, MAX_INDEX_BYTES, "index")
            .map_err(|e| bad(e.to_string()))?;
        let index: Index = serde_json::from_slice(&json).map_err(|e| bad(format!("index: {e}")))?;
        index
            .header
            .validate()
            .map_err(|e| bad(format!("header: {e}")))?;
        let mut chunks = BTreeMap::new();
        for c in index.chunks {
            if c.offset < PREAMBLE_BYTES
                || c.length > MAX_CHUNK_BYTES
                || c.offset
                    .checked_add(c.length)
                    .is_none_or(|end| end > index_offset)
            {
                return Err(ReflectanceError::BadChunk {
                    path: path.to_path_buf(),
                    chunk: c.key.to_string(),
                    problem: format!("lies outside the data area ({}+{})", c.offset, c.length),
                });
            }
            chunks.insert(c.key, c);
        }
        Ok(Self {
            path: path.to_path_buf(),
            source,
            header: index.header,
            chunks,
            index_crc,
            bytes_read: std::sync::atomic::AtomicU64::new(0),
            decoded: Default::default(),
            projector: Default::default(),
            hulls: Default::default(),
        })
    }

    /// The header.
    pub fn header(&self) -> &FieldHeader {
        &self.header
    }

    /// The byte source the file is read from.
    pub fn source(&self) -> &R {
        &self.source
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// What identifies the file's content: its size in bytes and the CRC-32 of its
    /// index, which holds the header and every chunk's place, length and CRC-32 (two
    /// fields that differ anywhere differ here but with odds of 2⁻³²).
    pub fn identity(&self) -> (u64, u32) {
        (self.source.size(), self.index_crc)
    }

    /// `requested` (an error naming the file and the poses it holds when it lacks it), or
    /// the field's first pose; an error naming the file when it holds none.
    pub fn pose_or_first(&self, requested: Option<u32>) -> Result<u32> {
        let held: Vec<u32> = self.header.poses.iter().map(|p| p.pose).collect();
        match requested {
            Some(p) if held.contains(&p) => Ok(p),
            Some(p) => Err(ReflectanceError::NoSuchPose {
                file: Some(self.path.clone()),
                within: "field",
                pose: p,
                held: crate::field::listed(&held),
            }),
            None => held
                .first()
                .copied()
                .ok_or_else(|| ReflectanceError::Missing {
                    file: self.path.clone(),
                    what: "the field holds no pose".into(),
                }),
        }
    }

    /// All chunk entries, in key order.
    pub fn chunks(&self) -> impl Iterator<Item = &ChunkEntry> {
        self.chunks.values()
    }

    /// Total size of the file, bytes.
    pub fn size(&self) -> u64 {
        self.source.size()
    }

    /// Whether a chunk exists.
    pub fn has(&self, key: &ChunkKey) -> bool {
        self.chunks.contains_key(key)
    }

    /// The checked bytes of a chunk.
    pub fn read_chunk(&self, key: &ChunkKey) -> Result<Vec<u8>> {
        let entry = self
            .chunks
            .get(key)
            .ok_or_else(|| ReflectanceError::Missing {
                file: self.path.clone(),
                what: format!("no {key} in this field"),
            })?;
        let mut bytes = vec![0u8; entry.length as usize];
        self.source
            .read_exact_at(entry.offset, &mut bytes)
            .map_err(|e| self.chunk_error(key, format!("cannot read: {e}")))?;
        if checksums_checked() && crc32fast::hash(&bytes) != entry.crc32 {
            return Err(self.chunk_error(key, "checksum mismatch (damaged file)".into()));
        }
        self.bytes_read
            .fetch_add(entry.length, std::sync::atomic::Ordering::Relaxed);
        Ok(bytes)
    }

    /// Bytes of chunks read from this file so far.
    pub fn bytes_read(&self) -> u64 {
        self.bytes_read.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// An error about chunk `key` of this file.
    pub fn chunk_error(&self, key: &ChunkKey, problem: String) -> ReflectanceError {
        ReflectanceError::BadChunk {
            path: self.path.clone(),
            chunk: key.to_string(),
            problem,
        }
    }

    /// Decodes chunk `key` with `decode`, naming the chunk if it fails.
    pub fn decode_chunk<T>(
        &self,
        key: &ChunkKey,
        decode: impl FnOnce(&[u8]) -> Result<T>,
    ) -> Result<T> {
        let bytes = self.read_chunk(key)?;
        decode(&bytes).map_err(|e| match e {
            ReflectanceError::Corrupt(problem) => self.chunk_error(key, problem),
            other => other,
        })
    }
}

/// Whether the file at `path` begins as a field file does (its magic bytes), for
/// commands that take another kind of file to say what they were given instead.
pub fn is_field_file(path: &Path) -> bool {
    let mut head = [0u8; 8];
    // (Only a regular file is opened: a FIFO would block the read.)
    std::fs::metadata(path).is_ok_and(|m| m.is_file())
        && std::fs::File::open(path)
            .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut head))
            .is_ok_and(|()| &head == MAGIC)
}

/// What differs between two parts' headers (beyond their poses), each with both values.
fn differences(a: &FieldHeader, b: &FieldHeader) -> String {
    let mut out = Vec::new();
    let mut differ = |what: &str, x: String, y: String| {
        if x != y {
            out.push(format!("{what} ({x} against {y})"));
        }
    };
    differ(
        "the grid of views",
        format!("{}x{} wraps {}", a.columns, a.rows, a.wraps),
        format!("{}x{} wraps {}", b.columns, b.rows, b.wraps),
    );
    differ(
        "the image size",
        format!("{}x{}", a.width, a.height),
        format!("{}x{}", b.width, b.height),
    );
    differ(
        "the cycle",
        format!("{} s, {} poses", a.cycle_seconds, a.poses_per_cycle),
        format!("{} s, {} poses", b.cycle_seconds, b.poses_per_cycle),
    );
    let speed = |h: &FieldHeader| match h.gait_speed_mps {
        Some(v) => format!("{v} m/s"),
        None => "not recorded".into(),
    };
    differ("the belt's speed", speed(a), speed(b));
    let basis = |h: &FieldHeader| match h.conditions == a.conditions {
        true => format!("{} conditions", h.conditions.len()),
        false => format!("{} other conditions", h.conditions.len()),
    };
    differ("the lighting basis", basis(a), basis(b));
    differ(
        "the codec",
        format!(
            "JPEG {}, predicted flow {}",
            a.jpeg_quality, a.flow_predicted
        ),
        format!(
            "JPEG {}, predicted flow {}",
            b.jpeg_quality, b.flow_predicted
        ),
    );
    differ(
        "the shadow maps",
        format!("{:?}", a.shadows),
        format!("{:?}", b.shadows),
    );
    differ(
        "the visual hulls",
        format!("{:?}", a.hulls),
        format!("{:?}", b.hulls),
    );
    if out.is_empty() {
        out.push("the headers".into());
    }
    out.join(", ")
}

/// The description of parts merged: theirs when they agree, else each part's with its
/// poses (parts ingested with different flow settings keep the record of each).
fn merged_description(files: &[FieldFile]) -> String {
    let first = &files[0].header().description;
    if files.iter().all(|f| &f.header().description == first) {
        return first.clone();
    }
    let parts: Vec<String> = files
        .iter()
        .map(|f| {
            let poses: Vec<u32> = f.header().poses.iter().map(|p| p.pose).collect();
            format!("poses {poses:?} {}", f.header().description)
        })
        .collect();
    format!("merged from {} parts: {}", files.len(), parts.join("; "))
}

/// Merges field files that hold disjoint poses of the same grid, basis and codec
/// settings into one file at `out`, copying chunks byte for byte (each pose keeps its
/// own flow quantizer). Used to assemble a field ingested pose by pose.
pub fn merge_fields(parts: &[PathBuf], out: &Path) -> Result<()> {
    let files = parts
        .iter()
        .map(|p| FieldFile::open(p))
        .collect::<Result<Vec<_>>>()?;
    let Some(first) = files.first() else {
        return Err(ReflectanceError::Misuse("nothing to merge".into()));
    };
    let shape = |h: &FieldHeader| FieldHeader {
        poses: Vec::new(),
        description: String::new(),
        ..h.clone()
    };
    let mut header = first.header().clone();
    header.poses.clear();
    for f in &files {
        if shape(f.header()) != shape(first.header()) {
            return Err(ReflectanceError::Incompatible {
                part: f.path().to_path_buf(),
                problem: format!(
                    "{} differ from {}'s",
                    differences(f.header(), first.header()),
                    first.path().display()
                ),
            });
        }
        for p in &f.header().poses {
            if header.poses.iter().any(|q| q.pose == p.pose) {
                return Err(ReflectanceError::Incompatible {
                    part: f.path().to_path_buf(),
                    problem: format!("pose {} is in two parts", p.pose),
                });
            }
            header.poses.push(p.clone());
        }
    }
    header.poses.sort_by_key(|p| p.pose);
    header.description = merged_description(&files);
    // Every part with pose-to-pose flows or none: a field with them for some poses only
    // fails three frames into a render between poses.
    let holds = |f: &FieldFile| {
        f.header().poses.iter().any(|p| p.pose_flows_to.is_some())
            || f.chunks()
                .any(|c| matches!(c.key.kind, ChunkKind::PoseFlow(_)))
    };
    if let (Some(with), Some(without)) = (
        files.iter().find(|f| holds(f)),
        files.iter().find(|f| !holds(f)),
    ) {
        return Err(ReflectanceError::Incompatible {
            part: with.path().to_path_buf(),
            problem: format!(
                "holds pose-to-pose flows (ingested with --pose-flow), {} does not: ingest \
                 every part with --pose-flow, or none",
                without.path().display()
            ),
        });
    }
    if let Err((pose, problem)) = header.check_pose_flows() {
        let part = files
            .iter()
            .find(|f| f.header().poses.iter().any(|p| p.pose == pose))
            .map_or(out.to_path_buf(), |f| f.path().to_path_buf());
        return Err(ReflectanceError::Incompatible { part, problem });
    }
    let mut writer = FieldWriter::create(out, header)?;
    for f in &files {
        let keys: Vec<ChunkKey> = f.chunks().map(|c| c.key).collect();
        for key in keys {
            writer.add_chunk(key, &f.read_chunk(&key)?)?;
        }
    }
    writer.finish()
}
