//! A whole field checked without rendering it (`frf info FIELD --check`): every chunk the
//! index lists is read, its CRC-32 compared, and decoded as its kind requires (the basis
//! mosaic, the alpha plane, the Huffman-coded flow maps, the shadow maps, the hull), so
//! that a field damaged anywhere is found before a farm renders from it, not after three
//! frames.

use serde::Serialize;

use crate::container::{ChunkKey, ChunkKind, FieldFile, ReadAt};
use crate::error::{ReflectanceError, Result};

/// What checking a field found.
#[derive(Debug, Serialize)]
pub struct Verification {
    /// Chunks read and decoded.
    pub chunks: usize,
    /// Their bytes.
    pub bytes: u64,
    /// The damaged chunks, in index order, and what is wrong with each.
    pub damaged: Vec<(String, String)>,
}

impl Verification {
    /// The error of a field with damaged chunks (the first named, the rest counted), or
    /// `None` when every chunk is whole.
    pub fn error(&self, path: &std::path::Path) -> Option<ReflectanceError> {
        let ((chunk, problem), rest) = self.damaged.split_first()?;
        let more = match rest.len() {
            0 => String::new(),
            n => format!(
                "; {n} more of the {} chunks are damaged, first {}",
                self.chunks,
                rest.iter()
                    .take(3)
                    .map(|(c, _)| c.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        };
        Some(ReflectanceError::BadChunk {
            path: path.to_path_buf(),
            chunk: chunk.clone(),
            problem: format!("{problem}{more}"),
        })
    }
}

impl<R: ReadAt> FieldFile<R> {
    /// Reads, checks and decodes every chunk of the field; `each` is called after each
    /// (progress). Damage is reported in the result, not as an error; an error is the
    /// operating system's (a file that cannot be read).
    pub fn verify(&self, each: &dyn Fn()) -> Result<Verification> {
        let keys: Vec<(ChunkKey, u64)> = self.chunks().map(|c| (c.key, c.length)).collect();
        let mut v = Verification {
            chunks: keys.len(),
            bytes: keys.iter().map(|k| k.1).sum(),
            damaged: Vec::new(),
        };
        for (key, _) in keys {
            match self.decode_any(&key) {
                Ok(()) => {}
                // The operating system's failure, not the chunk's damage.
                Err(e) if e.fault() == frf_core::Fault::Io => return Err(e),
                Err(e) => v.damaged.push((key.to_string(), problem_of(e))),
            }
            each();
        }
        Ok(v)
    }

    /// Reads chunk `key` and decodes it as its kind requires.
    fn decode_any(&self, key: &ChunkKey) -> Result<()> {
        let (pose, u, v) = (key.pose, key.u as usize, key.v as usize);
        self.read_chunk(key)?;
        match key.kind {
            ChunkKind::Basis => self.basis(pose, u, v).map(drop),
            ChunkKind::Alpha => self.alpha(pose, u, v).map(drop),
            ChunkKind::Flow(n) => self.flow(pose, u, v, n).map(drop),
            ChunkKind::PoseFlow(s) => self.pose_flow(pose, u, v, s).map(drop),
            ChunkKind::Shadows => self.shadows(pose).map(drop),
            ChunkKind::Hull => self.hull(pose).map(drop),
            ChunkKind::Normals => self.normals(pose, u, v).map(drop),
        }
    }
}

/// The problem of a chunk's error, without the file and chunk it names again.
fn problem_of(e: ReflectanceError) -> String {
    match e {
        ReflectanceError::BadChunk { problem, .. } => problem,
        other => other.to_string(),
    }
}
