//! The shadow step of ingest (docs/design.md section 2.4): carve the pose's visual hull
//! from the mattes of all its views ([`frf_reflectance::hull`]), at half a pixel's
//! footprint by default ([`hull_voxel_m`]), then trace the attenuation map of every upper
//! basis condition over the ground patch past it ([`frf_reflectance::shadow`]).

use std::time::Instant;

use frf_core::camera::Camera;
use frf_core::image::GrayImage;
use frf_core::volume::GroundGrid;
use frf_reflectance::field::{ConditionRecord, HullSpec, ShadowSpec};
use frf_reflectance::hull::{Silhouette, VoxelHull, voxel_per_pixel};
use frf_reflectance::shadow::{attenuation_maps, shadow_spec};

use crate::error::Result;

/// The hull's voxel side by default is this fraction of a pixel's footprint on the
/// turntable axis ([`hull_voxel_m`]): the sun's cast shadows are traced through the hull
/// from its surface on (docs/design.md section 4.1), and the novel views' rays meet it
/// there, so a hull as sharp as the mattes pays. Measured at the captured views of the
/// small preset's oracle field (footprint 9.8 mm; subject PSNR under the built-in sky,
/// 8 views) and at its quad centres (the four-way morph): 2 cm voxels 33.63 / 31.86 dB,
/// 1 cm 34.04 / 32.22, 5 mm 34.35 / 32.5.
pub const HULL_VOXEL_PER_PIXEL: f32 = 0.5;
/// Bounds of the default voxel side, metres: below 5 mm a walker's hull holds tens of
/// millions of voxels a pose and the renderer's rays step through hundreds; 2 cm is
/// finer than the ground texels of the original's shadow maps (3 m / 128 = 2.3 cm).
pub const HULL_VOXEL_RANGE_M: (f32, f32) = (0.005, 0.02);
/// A hull finer than this is carved in a band around a carve at about this side
/// ([`VoxelHull::carve_banded`]): the walker's thinnest part, a hand, spans 2.5 of them.
const BAND_PARENT_M: f32 = 0.02;
/// Directions traced per light by default ([`frf_reflectance::shadow`]). Measured on the
/// tiny preset's oracle field, shadow error against the truth with 1 / 8 / 32 samples:
/// Pisa 0.0164 / 0.0085 / 0.0077, Grace 0.0186 / 0.0183 / 0.0181, the built-in sky
/// 0.0435 / 0.0421 / 0.0425 (its small sun is a basis limit).
pub const DEFAULT_LIGHT_SAMPLES: usize = 8;
/// Views allowed to disagree when carving, by default (the views of a pose come from 36
/// different walk cycles: see [`VoxelHull::carve`]). Measured hull IoU against the true
/// body on ingested captures (pose 0), with 2 / 5 / 6 / 8 misses: small preset 0.788 /
/// 0.835 / 0.842 / 0.844, tiny 0.741 / 0.778 / 0.777 / 0.774.
pub const DEFAULT_MISSES: usize = 6;

/// The views allowed to disagree when only `present` of a grid's `total` views were
/// ingested (`frf ingest --for SCENE`): `misses` in proportion, rounded up, so that a
/// full grid keeps `misses` and a few views do not carve with the tolerance of many.
pub fn misses_for(misses: usize, present: usize, total: usize) -> usize {
    if present >= total || total == 0 {
        return misses;
    }
    (misses * present).div_ceil(total)
}

/// The default voxel side of the hull of views seen by `cameras`: [`HULL_VOXEL_PER_PIXEL`]
/// of their smallest pixel footprint on the turntable axis, within [`HULL_VOXEL_RANGE_M`]
/// (5 mm at 160x224, 1.2 cm at 64x90).
pub fn hull_voxel_m(cameras: &[Camera]) -> f32 {
    voxel_per_pixel(cameras, HULL_VOXEL_PER_PIXEL, HULL_VOXEL_RANGE_M)
}

/// How the hull and the shadow maps are made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowOptions {
    /// The hull's voxel side, metres (`None`: [`hull_voxel_m`] of the views' cameras).
    pub hull_voxel_m: Option<f32>,
    /// Views allowed to disagree when carving the hull of a full grid.
    pub hull_misses: usize,
    /// The ground patch of the maps.
    pub ground: GroundGrid,
    /// Directions traced per light ([`frf_reflectance::shadow::attenuation_maps`]).
    pub light_samples: usize,
}

impl Default for ShadowOptions {
    fn default() -> Self {
        Self {
            hull_voxel_m: None,
            hull_misses: DEFAULT_MISSES,
            ground: GroundGrid::ORIGINAL,
            light_samples: DEFAULT_LIGHT_SAMPLES,
        }
    }
}

/// Most texels per side of a patch sized for a scene without `--shadow-texels` (6 m at the
/// original's density): tracing the maps costs as the square of it, and a long shadow's
/// far end is soft.
pub const MAX_AUTO_TEXELS: u32 = 256;

impl ShadowOptions {
    /// The hulls of a field of a capture whose cameras (world frame, the turntable's axis
    /// vertical through the origin) are `cameras`: their voxel side and tolerance, what
    /// its header records and every pose is carved with. (A pose's own views, in its
    /// subject frame, give slightly different footprints, and the poses ingested apart
    /// must agree to merge.)
    pub fn hull(&self, cameras: &[Camera]) -> HullSpec {
        HullSpec {
            voxel_m: self.hull_voxel_m.unwrap_or_else(|| hull_voxel_m(cameras)),
            misses: self.hull_misses,
        }
    }

    /// The ground patch of the maps: of side `extent_m` where given, else `needed` metres
    /// (a scene's need) but at least the original's; of `texels` a side where given, else
    /// following the side at the original's density (128 per 3 m), at most
    /// [`MAX_AUTO_TEXELS`].
    pub fn ground_for(
        extent_m: Option<f32>,
        texels: Option<u32>,
        needed: Option<f32>,
    ) -> GroundGrid {
        let original = GroundGrid::ORIGINAL;
        let extent_m = extent_m
            .unwrap_or_else(|| needed.map_or(original.extent_m, |n| n.max(original.extent_m)));
        let texels = texels.unwrap_or_else(|| {
            let per_metre = original.texels as f32 / original.extent_m;
            ((extent_m * per_metre).ceil() as u32).clamp(original.texels, MAX_AUTO_TEXELS)
        });
        GroundGrid { extent_m, texels }
    }

    /// Checks the options, naming the bad one.
    pub fn validate(&self) -> Result<()> {
        if let Some(v) = self.hull_voxel_m {
            // Below 2 mm a hull of the search region exceeds the grid limit; above 50 cm
            // it no longer resembles a person.
            frf_core::argument::within("--hull-voxel", v, 0.002, 0.5, "metres")?;
        }
        // Beyond 256 directions per light the maps no longer change visibly and the
        // tracing takes minutes.
        frf_core::argument::within("--shadow-samples", self.light_samples, 1, 256, "")?;
        let g = self.ground;
        if !(g.extent_m.is_finite() && g.extent_m > 0.0) {
            let allowed = "a positive side of the ground patch, metres";
            return Err(frf_core::BadArgument::new("--shadow-extent", g.extent_m, allowed).into());
        }
        let most = frf_core::volume::MAX_GROUND_TEXELS;
        frf_core::argument::within("--shadow-texels", g.texels, 1, most, "")?;
        Ok(())
    }

    /// The shadow spec of a field with these `conditions`.
    pub fn spec(&self, conditions: &[ConditionRecord]) -> ShadowSpec {
        shadow_spec(conditions, self.ground, self.light_samples)
    }
}

/// A pose's hull and maps, with the seconds each took.
pub struct PoseShadows {
    /// The visual hull.
    pub hull: VoxelHull,
    /// One map per condition of the spec.
    pub maps: Vec<GrayImage>,
    /// Seconds carving.
    pub hull_seconds: f64,
    /// Seconds tracing the maps.
    pub map_seconds: f64,
}

/// Carves the hull of one pose from its views (`cameras` in the subject frame, `alphas`
/// the mattes) as `hull` says, in a band when it is finer than [`BAND_PARENT_M`], and
/// traces its maps.
pub fn pose_shadows(
    cameras: &[Camera],
    alphas: &[&GrayImage],
    conditions: &[ConditionRecord],
    hull: HullSpec,
    options: &ShadowOptions,
) -> Result<PoseShadows> {
    let start = Instant::now();
    let views: Vec<Silhouette> = cameras
        .iter()
        .zip(alphas)
        .map(|(camera, alpha)| Silhouette { camera, alpha })
        .collect();
    let coarse = (BAND_PARENT_M / hull.voxel_m).floor() as u32;
    let hull = VoxelHull::carve_banded(&views, hull.voxel_m, coarse, hull.misses)?;
    let hull_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let maps = attenuation_maps(&hull, conditions, &options.spec(conditions));
    Ok(PoseShadows {
        hull,
        maps,
        hull_seconds,
        map_seconds: start.elapsed().as_secs_f64(),
    })
}
