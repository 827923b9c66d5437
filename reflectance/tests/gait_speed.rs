//! The treadmill's speed measured from a field's visual hulls agrees with the speed the
//! capture recorded: a field of the virtual stage's tiny preset (the walk, with its
//! cycle-to-cycle perturbations), its hulls carved from the stage's true mattes as ingest
//! and the oracle carve them (1.2 cm voxels, 6 views allowed to disagree, every 0.1 s of a
//! cycle).

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use frf_core::capture::Capture;
use frf_reflectance::field::HullSpec;
use frf_reflectance::flowcodec::quant::LogQuantizer;
use frf_reflectance::gait_speed;
use frf_reflectance::hull::{Silhouette, VoxelHull, voxel_per_pixel};
use frf_reflectance::{FieldFile, FieldHeader, FieldWriter};
use frf_stage::{Preset, Stage, StageConfig};
use rayon::prelude::*;

/// Ingest's hull: half a pixel's footprint within 5 mm-2 cm (`frf_ingest::shadows`), 6
/// views allowed to disagree, carved in a band under 2 cm parents.
const VOXEL_PER_PIXEL: f32 = 0.5;
const VOXEL_RANGE_M: (f32, f32) = (0.005, 0.02);
const MISSES: usize = 6;
const BAND_PARENT_M: f32 = 0.02;

/// Writes a field of `stage`'s poses holding only their hulls; the header as
/// `FieldHeader::from_capture` makes it from the stage's manifest.
fn hull_field(stage: &Stage, path: &std::path::Path) -> FieldHeader {
    let capture = Capture::from_manifest(path.parent().unwrap(), stage.manifest()).unwrap();
    let poses = stage.config().poses.clone();
    let quantizer = LogQuantizer::new(0.2, 12.0).unwrap();
    let mut header = FieldHeader::from_capture(&capture, &poses, quantizer, 90).unwrap();
    let voxel_m = voxel_per_pixel(stage.cameras(), VOXEL_PER_PIXEL, VOXEL_RANGE_M);
    header.hulls = Some(HullSpec {
        voxel_m,
        misses: MISSES,
    });
    let mut writer = FieldWriter::create(path, header.clone()).unwrap();
    for &pose in &poses {
        let views: Vec<(usize, usize)> = (0..stage.cycles())
            .flat_map(|u| (0..stage.cameras().len()).map(move |v| (u, v)))
            .collect();
        let mattes: Vec<_> = views
            .par_iter()
            .map(|&(u, v)| {
                let camera = stage.subject_camera(pose, u, v).unwrap();
                (camera, stage.reference_surface(pose, u, v).unwrap().1)
            })
            .collect();
        let silhouettes: Vec<Silhouette> = mattes
            .iter()
            .map(|(camera, alpha)| Silhouette { camera, alpha })
            .collect();
        let coarse = (BAND_PARENT_M / voxel_m).floor() as u32;
        let hull = VoxelHull::carve_banded(&silhouettes, voxel_m, coarse, MISSES).unwrap();
        writer.add_hull(pose, &hull).unwrap();
    }
    writer.finish().unwrap();
    header
}

#[test]
fn the_hulls_tell_the_belts_speed() {
    let mut config = StageConfig::preset(Preset::Tiny);
    // Every third pose of the walk's 30: 0.1 s apart.
    config.poses = (0..30).step_by(3).collect();
    let stage = Stage::new(config).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("hulls.frf");
    let header = hull_field(&stage, &path);
    let stored = stage.config().gait.speed_mps();
    assert_eq!(header.gait_speed_mps, Some(stored));

    let field = FieldFile::open(&path).unwrap();
    assert_eq!(field.header().gait_speed_mps, Some(stored));
    assert_eq!(gait_speed::gait_speed_mps(&field).unwrap(), Some(stored));
    let measured = gait_speed::measure(&field).unwrap().unwrap();
    eprintln!("belt speed measured from the hulls {measured:.3} m/s, stored {stored} m/s");
    // Measured: 1.053 m/s against 1.05.
    assert!(
        (measured - stored).abs() < 0.15 * stored,
        "measured {measured} m/s, stored {stored} m/s"
    );

    // Too few poses: no guess.
    let few = gait_speed::from_hulls(
        &[
            (0.0, &field.hull(0).unwrap().unwrap()),
            (0.1, &field.hull(3).unwrap().unwrap()),
        ],
        1.0,
    );
    assert_eq!(few, None);
}
