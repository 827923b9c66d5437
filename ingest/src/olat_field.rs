//! A calibrated one-light-at-a-time set ([`crate::olat`]) ingested as a one-view field
//! whose basis is its lights (`frf ingest-olat`), so that it relights like a stage's
//! field and is scored against the photographs of the lights it leaves out
//! (`frf eval-olat F.frf --photos DIR`).
//!
//! - **Frame**: the set's camera frame (x right, y up, z toward the camera) is the
//!   field's subject frame: the camera stands on `+z` looking toward `−z`, as a stage's
//!   azimuth-0 camera does, so light directions carry over unchanged (turntable angle 0).
//!   The set calibrates no intrinsics; the camera is a long lens (focal length four times
//!   the image's larger side), which nothing that relights needs.
//! - **Basis**: with `--use K`, K lights kept by farthest-point sampling on the sphere
//!   from the one nearest the view ([`farthest_lights`]); otherwise every light. Each is a
//!   condition of one light of unit intensity (its photograph was divided by its
//!   intensity), standing for its spherical Voronoi cell among the kept lights (its solid
//!   angle recorded), so environments relight the field as they relight a stage's.
//! - **Matte**: the set's mask. **Normals**: fitted to the basis when it is written
//!   ([`frf_reflectance::store::encode_images`]).

use std::path::Path;
use std::time::Instant;

use frf_core::image::Image;
use frf_reflectance::field::{CameraRecord, ConditionRecord, LightRecord, PoseRecord, ViewRecord};
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_reflectance::light_fit::farthest_lights;
use frf_reflectance::store::encode_images;
use frf_reflectance::{FieldFile, FieldHeader, FieldWriter};
use glam::{Mat3, Vec3};

use crate::error::{IngestError, Result};
use crate::olat::OlatSet;

/// Directions sampled (a Fibonacci lattice) to measure the lights' Voronoi cells.
const CELL_SAMPLES: usize = 200_000;

/// What [`ingest_olat`] wrote.
#[derive(Debug, Clone, serde::Serialize)]
pub struct OlatFieldReport {
    /// Lights in the set.
    pub lights: usize,
    /// The lights kept as the basis (numbers from 1, in the order taken).
    pub kept: Vec<usize>,
    /// Bytes of the field file.
    pub bytes: u64,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Ingests `set` into the field file `out` (see the module text), keeping `keep` of its
/// lights (all when `None`).
pub fn ingest_olat(
    set: &OlatSet,
    out: &Path,
    keep: Option<usize>,
    jpeg_quality: u8,
) -> Result<OlatFieldReport> {
    let start = Instant::now();
    let n = set.directions.len();
    let keep = keep.unwrap_or(n);
    if !(3..=n).contains(&keep) {
        return Err(IngestError::Argument(frf_core::BadArgument::new(
            "--use",
            keep,
            format!("3 to the set's {n} lights (three at least fix a normal)"),
        )));
    }
    let kept = farthest_lights(&set.directions, keep, Vec3::Z);
    let dirs: Vec<Vec3> = kept.iter().map(|&k| set.directions[k]).collect();
    let cells = voronoi_solid_angles(&dirs);
    let (w, h) = set.images[0].size();
    let header = FieldHeader {
        description: format!(
            "one-light-at-a-time set {} ({keep} of {n} lights)",
            set.dir.display()
        ),
        columns: 1,
        rows: 1,
        wraps: false,
        width: w as u32,
        height: h as u32,
        cycle_seconds: 1.0,
        poses_per_cycle: 1,
        conditions: kept
            .iter()
            .zip(&cells)
            .map(|(&k, &solid_angle_sr)| ConditionRecord {
                name: format!("light {:03}", k + 1),
                floor: false,
                lights: vec![LightRecord {
                    direction: set.directions[k].to_array(),
                    intensity: [1.0; 3],
                    solid_angle_sr,
                }],
            })
            .collect(),
        poses: vec![PoseRecord {
            pose: 0,
            time_s: 0.0,
            views: vec![ViewRecord {
                camera: CameraRecord::from_camera(&set_camera(w as u32, h as u32)),
                turntable_deg: 0.0,
            }],
            flow_quantizer: LogQuantizer::fit(std::iter::empty()),
            pose_flows_to: None,
        }],
        flow_predicted: true,
        jpeg_quality,
        shadows: None,
        hulls: None,
        gait_speed_mps: None,
    };
    let basis: Vec<_> = kept.iter().map(|&k| set.images[k].clone()).collect();
    let alpha = Image::from_vec(
        w,
        h,
        set.mask
            .iter()
            .map(|&m| if m { 1.0 } else { 0.0 })
            .collect(),
    )
    .expect("the mask is the images' size");
    let mut writer = FieldWriter::create(out, header.clone())?;
    writer.add_view(0, 0, 0, &encode_images(&header, &basis, &alpha)?)?;
    writer.finish()?;
    let field = FieldFile::open(out)?;
    Ok(OlatFieldReport {
        lights: n,
        kept: kept.iter().map(|k| k + 1).collect(),
        bytes: field.size(),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The set's camera in the field's subject frame: on `+z`, looking toward `−z`, `+y` up
/// (OpenCV's camera axes: x right, y down, z forward).
fn set_camera(width: u32, height: u32) -> frf_core::camera::Camera {
    let f = 4.0 * width.max(height) as f32;
    frf_core::camera::Camera {
        width,
        height,
        intrinsics: frf_core::camera::Intrinsics {
            fx: f,
            fy: f,
            cx: width as f32 / 2.0,
            cy: height as f32 / 2.0,
        },
        world_from_camera: frf_core::camera::Rigid {
            rotation: Mat3::from_diagonal(Vec3::new(1.0, -1.0, -1.0)),
            translation: Vec3::new(0.0, 0.0, 4.0),
        },
    }
}

/// The solid angle of each direction's spherical Voronoi cell among `dirs`, steradians
/// (summing to 4π), measured on a Fibonacci lattice of [`CELL_SAMPLES`] directions.
pub fn voronoi_solid_angles(dirs: &[Vec3]) -> Vec<f32> {
    let mut counts = vec![0usize; dirs.len()];
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    for i in 0..CELL_SAMPLES {
        let y = 1.0 - 2.0 * (i as f32 + 0.5) / CELL_SAMPLES as f32;
        let r = (1.0 - y * y).max(0.0).sqrt();
        let phi = golden * i as f32;
        let d = Vec3::new(r * phi.cos(), y, r * phi.sin());
        let nearest = (0..dirs.len())
            .max_by(|&a, &b| dirs[a].dot(d).total_cmp(&dirs[b].dot(d)))
            .expect("at least one direction");
        counts[nearest] += 1;
    }
    let per = 4.0 * std::f32::consts::PI / CELL_SAMPLES as f32;
    counts.into_iter().map(|c| c as f32 * per).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voronoi_cells_cover_the_sphere_and_split_it_evenly_between_opposite_lights() {
        let cells = voronoi_solid_angles(&[Vec3::Y, -Vec3::Y]);
        let half = 2.0 * std::f32::consts::PI;
        assert!((cells[0] - half).abs() < 1e-3 && (cells[1] - half).abs() < 1e-3);
        let six = voronoi_solid_angles(&[Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z]);
        for c in six {
            assert!((c - 4.0 * std::f32::consts::PI / 6.0).abs() < 5e-3, "{c}");
        }
    }
}
