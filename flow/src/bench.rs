//! The benchmark runner behind `frf flow-bench`: finds image pairs with ground truth in
//! a directory and measures the estimator's error and wall time on each.
//!
//! Two layouts are read:
//! - **Middlebury** (Baker et al., IJCV 2011): `<Seq>/frame10.png`, `<Seq>/frame11.png`,
//!   `<Seq>/flow10.flo`, under the directory or the directory itself.
//! - **MPI-Sintel** (Butler et al., ECCV 2012): `<scene>/{clean,final}/frame_NNNN.png`
//!   with `<scene>/flow/frame_NNNN.flo` from frame `NNNN` to `NNNN + 1`, and
//!   `<scene>/invalid/frame_NNNN.png` (255 = invalid, excluded from the errors), under
//!   the directory or the directory itself. Each pass is its own sequence,
//!   `<scene>/<pass>/NNNN`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use frf_core::flo::read_flo;
use frf_core::image::GrayImage;
use frf_core::io::{read_gray, read_rgb};

use crate::error::{FlowError, Result};
use crate::estimate::estimate_flow;
use crate::metrics::{FlowErrors, flow_errors};
use crate::params::FlowParams;

/// One image pair with ground truth.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchPair {
    /// Sequence name, e.g. `RubberWhale` or `alley_1/clean/0002`.
    pub name: String,
    /// First frame.
    pub frame_a: PathBuf,
    /// Second frame.
    pub frame_b: PathBuf,
    /// Ground-truth flow from the first frame to the second.
    pub truth: PathBuf,
    /// Optional mask of pixels to exclude (non-zero = excluded).
    pub excluded: Option<PathBuf>,
}

/// Result of the estimator on one pair.
#[derive(Debug, Clone, PartialEq)]
pub struct PairResult {
    /// The pair's name.
    pub name: String,
    /// Errors against the ground truth.
    pub errors: FlowErrors,
    /// Wall time of [`estimate_flow`] on the pair, seconds (the median over repeats;
    /// reading the files is not included).
    pub seconds: f64,
}

/// Every pair under `dir`, sorted by name.
pub fn find_pairs(dir: &Path) -> Result<Vec<BenchPair>> {
    if !dir.is_dir() {
        return Err(FlowError::Dataset {
            dir: dir.to_path_buf(),
            problem: "not a directory".into(),
        });
    }
    let mut pairs = Vec::new();
    let mut candidates = vec![dir.to_path_buf()];
    candidates.extend(subdirectories(dir)?);
    for d in candidates {
        if let Some(p) = middlebury_pair(&d) {
            pairs.push(p);
        }
        pairs.extend(sintel_pairs(&d)?);
    }
    pairs.sort_by(|a, b| a.name.cmp(&b.name));
    pairs.dedup_by(|a, b| a.name == b.name);
    if pairs.is_empty() {
        return Err(FlowError::Dataset {
            dir: dir.to_path_buf(),
            problem: "no sequence found: expected <Seq>/frame10.png, frame11.png, flow10.flo \
                      (Middlebury) or <scene>/clean/frame_NNNN.png with <scene>/flow/frame_NNNN.flo \
                      (Sintel)"
                .into(),
        });
    }
    Ok(pairs)
}

fn subdirectories(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir).map_err(|e| frf_core::CoreError::io(dir, e))?;
    let mut dirs: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    Ok(dirs)
}

fn name_of(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

fn middlebury_pair(dir: &Path) -> Option<BenchPair> {
    let (a, b, t) = (
        dir.join("frame10.png"),
        dir.join("frame11.png"),
        dir.join("flow10.flo"),
    );
    (a.is_file() && b.is_file() && t.is_file()).then(|| BenchPair {
        name: name_of(dir),
        frame_a: a,
        frame_b: b,
        truth: t,
        excluded: None,
    })
}

fn sintel_pairs(scene: &Path) -> Result<Vec<BenchPair>> {
    let flow_dir = scene.join("flow");
    if !flow_dir.is_dir() {
        return Ok(Vec::new());
    }
    let mut out = Vec::new();
    let entries =
        std::fs::read_dir(&flow_dir).map_err(|e| frf_core::CoreError::io(&flow_dir, e))?;
    let mut flows: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "flo"))
        .collect();
    flows.sort();
    for truth in flows {
        let stem = truth
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let Some(number) = stem
            .strip_prefix("frame_")
            .and_then(|n| n.parse::<u32>().ok())
        else {
            continue;
        };
        let next = format!("frame_{:04}.png", number + 1);
        for pass in ["clean", "final"] {
            let (a, b) = (
                scene.join(pass).join(format!("{stem}.png")),
                scene.join(pass).join(&next),
            );
            if a.is_file() && b.is_file() {
                let invalid = scene.join("invalid").join(format!("{stem}.png"));
                out.push(BenchPair {
                    name: format!("{}/{pass}/{number:04}", name_of(scene)),
                    frame_a: a,
                    frame_b: b,
                    truth: truth.clone(),
                    excluded: invalid.is_file().then_some(invalid),
                });
            }
        }
    }
    Ok(out)
}

/// Threads the estimator parallelises over (rayon's pool: all cores unless the
/// `RAYON_NUM_THREADS` environment variable says otherwise).
pub fn threads() -> usize {
    rayon::current_num_threads()
}

/// Runs the estimator `repeat` times (at least once) on `pair`, keeping the median time.
pub fn run_pair(pair: &BenchPair, params: &FlowParams, repeat: usize) -> Result<PairResult> {
    let a = read_rgb(&pair.frame_a)?;
    let b = read_rgb(&pair.frame_b)?;
    let truth = read_flo(&pair.truth)?;
    let mask: Option<GrayImage> = match &pair.excluded {
        Some(path) => Some(read_gray(path)?.map(|v| if v > 0.5 { 0.0 } else { 1.0 })),
        None => None,
    };
    let mut times = Vec::new();
    let mut flow = None;
    for _ in 0..repeat.max(1) {
        let start = Instant::now();
        flow = Some(estimate_flow(&a, &b, params)?);
        times.push(start.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    let flow = flow.ok_or(FlowError::NoValidPixels)?;
    let errors = flow_errors(&flow, &truth, mask.as_ref())?;
    Ok(PairResult {
        name: pair.name.clone(),
        errors,
        seconds: times[times.len() / 2],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_layouts_are_found() {
        let dir = tempfile::tempdir().unwrap();
        let seq = dir.path().join("Seq");
        std::fs::create_dir_all(&seq).unwrap();
        for f in ["frame10.png", "frame11.png", "flow10.flo"] {
            std::fs::write(seq.join(f), b"x").unwrap();
        }
        let scene = dir.path().join("alley");
        for sub in ["clean", "final", "flow", "invalid"] {
            std::fs::create_dir_all(scene.join(sub)).unwrap();
        }
        for f in [
            "clean/frame_0002.png",
            "clean/frame_0003.png",
            "final/frame_0002.png",
            "flow/frame_0002.flo",
            "invalid/frame_0002.png",
        ] {
            std::fs::write(scene.join(f), b"x").unwrap();
        }
        let pairs = find_pairs(dir.path()).unwrap();
        let names: Vec<&str> = pairs.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["Seq", "alley/clean/0002"], "final lacks frame 3");
        assert!(pairs[1].excluded.is_some());
        // A sequence directory itself works too.
        assert_eq!(find_pairs(&seq).unwrap().len(), 1);
        let empty = tempfile::tempdir().unwrap();
        assert!(matches!(
            find_pairs(empty.path()),
            Err(FlowError::Dataset { .. })
        ));
    }
}
