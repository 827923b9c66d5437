//! Parts of a field merged into one (`frf merge`): the parts in the order of their first
//! pose, checked against the poses expected before anything is written.

use std::path::{Path, PathBuf};

use crate::container::{FieldFile, merge_fields};
use crate::error::{ReflectanceError, Result};
use crate::field::listed;

/// Merges `parts` into `out` in the order of their first pose, after checking that they
/// hold every pose of `expected` (the poses, and where the expectation comes from, for
/// the message); the poses held.
pub fn merge_parts(
    parts: &[PathBuf],
    out: &Path,
    expected: Option<(&[u32], &str)>,
) -> Result<Vec<u32>> {
    let mut ordered = Vec::with_capacity(parts.len());
    let mut held: Vec<u32> = Vec::new();
    for p in parts {
        let f = FieldFile::open(p)?;
        held.extend(f.header().poses.iter().map(|r| r.pose));
        let first = f
            .header()
            .poses
            .iter()
            .map(|r| r.pose)
            .min()
            .ok_or_else(|| ReflectanceError::Missing {
                file: p.clone(),
                what: "holds no pose".into(),
            })?;
        ordered.push((first, p.clone()));
    }
    ordered.sort();
    held.sort_unstable();
    if let Some((poses, from)) = expected {
        let missing: Vec<u32> = poses
            .iter()
            .copied()
            .filter(|p| !held.contains(p))
            .collect();
        if !missing.is_empty() {
            return Err(ReflectanceError::Incompatible {
                part: out.to_path_buf(),
                problem: format!(
                    "the parts hold poses {held:?}, {from} expects {poses:?}: poses {missing:?} \
                     are missing (ingest them, e.g. frf ingest CAPTURE --poses {}); nothing \
                     written",
                    listed(&missing).replace(", ", ",")
                ),
            });
        }
    }
    let paths: Vec<PathBuf> = ordered.into_iter().map(|(_, p)| p).collect();
    merge_fields(&paths, out)?;
    Ok(held)
}
