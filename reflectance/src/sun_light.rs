//! A sun relit by a field's fitted normals instead of its basis (docs/design.md section
//! 4.1): the basis integrates a sun over its condition's cell, which blurs and moves its
//! terminator; the sun is taken out of the environment ([`Sun::extract`]), the rest
//! relit by the basis as before, and the sun added per texel by the light fit
//! ([`relight_texel`]): the nearest conditions' images, per unit of their light, times
//! the ratio of the normal's shading under the sun to its shading under them.
//!
//! Each view sees the dome turned by its turntable angle `θ`, so the sun's direction in
//! its dome frame (where its normals were fitted) is `R_y(θ) d`, as the projection turns
//! an environment's texel ([`crate::project`]). The nearest images carry their own
//! directions' cast shadows, not the sun's: a texel the pose's visual hull hides from the
//! sun gets none of it ([`SunLight::sunlit`], by the hull's map seen from the sun,
//! [`SunDepth`]). The CPU reference of the GPU's sun term (`shaders/relight.wgsl`).
//!
//! **Trust.** The normals' sun replaces the basis' only where the field's own evidence
//! says the model holds ([`SunLight::trust`]), and fades to the basis' elsewhere:
//! per view, by how compact the sun is against the cell of the condition it falls in
//! (a source twice as broad as a cell is what the basis already resolves), and per texel, by
//! how well the same relighting, one condition left out, predicts that condition's
//! own image from the others' (leave one out, for each of the sun's nearest
//! conditions). Where it predicts them badly (gloss, light bounced between surfaces, a
//! normal the Lambertian fit got wrong) the texel keeps the basis' sun exactly.

use frf_core::image::{Rgb, luminance};
use frf_core::sun::Sun;
use std::cell::Cell;
use std::sync::Arc;

use glam::{Mat3, Vec3};

use crate::field::ConditionRecord;
use crate::hull::VoxelHull;
use crate::light_fit::{
    RATIO_FLOOR, condition_light_shares, condition_lights, cone_shading, group_cone,
    nearest_weights_by, per_unit, relight_texel,
};
use crate::sun_depth::SunDepth;

/// Conditions whose images a texel's sun is carried by, weighted by the inverse of their
/// angle to the sun to the power [`WEIGHT_POWER`]. Measured at the captured views of the
/// stage's small oracle field (subject PSNR; a sun alone at 40° / the built-in sky):
/// 3 conditions by inverse angle 30.50 / 32.30 dB, 3 by its square 31.08 / 32.97, 2 by
/// inverse angle 31.25 / 33.02, 2 by its square 31.41 / 33.23. Fewer images blur the
/// cast shadows and texture they carry less.
pub const NEAREST: usize = 2;
/// See [`NEAREST`].
pub const WEIGHT_POWER: f32 = 2.0;
/// The most conditions a sun's trust reads at a view ([`SunView::involved`]): its
/// [`NEAREST`], and the [`NEAREST`] that predict each.
const INVOLVED: usize = NEAREST * (1 + NEAREST);
/// A texel's leave-one-out error ([`SunLight::trust`]: the error of its nearest
/// conditions' images predicted by the normals from the others', over the plain
/// interpolation's of them) at which it starts to fall back to the basis' sun, and at
/// which it has wholly, smoothly between. Chosen at the captured views of the small
/// oracle field of pose 0 on eight maps (`lobe_zenith_s4`, `overcast_hot_a`, `sun_2_30`,
/// `sun_5_50`, `window_20`, `bright_ground_a`, `forest_slope_1k`,
/// `st_fagans_interior_1k`; summed gain over the basis, subject PSNR): no trust test
/// 14.12 dB, these bounds 1-2 13.93, 1.5-3 14.20, 2-5 14.40; bounds on the error itself
/// (over the photographs', not the interpolation's) 0.25-0.75 12.93, 0.5-1.5 13.97.
/// Reported on the other maps in docs/results/hard_light.md.
pub const TRUST_ERROR: [f32; 2] = [2.0, 5.0];
/// Suns a relighting takes out of an environment and relights by the normals, brightest
/// first ([`Sun::extract`] again on what the last left): a map may hold several sharp
/// lights (a cathedral's windows). Measured at the captured views of the small oracle
/// field (subject PSNR; `grace`, whose two brightest windows carry 29 % and 20 % of its
/// light / `studio_small_03`): 1 sun 31.16 / 31.46 dB, 2 31.76 / -, 3 31.96 / -,
/// 4 32.73 / 32.34, 6 32.85 / -; the basis 29.27 / 25.93. Maps with one sun (the
/// built-in sky) or a soft one (`forest_slope`, `st_fagans_interior`) score the same
/// with 1 or 4. Each sun costs a shadow ray where it would light a texel.
pub const MAX_SUNS: usize = 4;
/// How far from the visual hull's surface a shadow ray toward the sun starts, as a
/// fraction of the height of the hull's grid (the subject's height and a margin; 1.88 m
/// for the stage's walker), so that it scales with the subject.
/// The hull is wider than the body and its surface point lies ahead of the true one, so
/// occluders near the texel are the hull's own error; far ones (a leg over the other, an
/// arm over the torso) are cast shadows. Chosen at the captured views of the small
/// oracle field of pose 0, as metres (2 cm voxels; subject PSNR, a sun alone at 20°,
/// 40°, 70° / the built-in sky): no shadow 31.97, 31.41, 29.00 / 33.23 dB; 0.04 m 31.09,
/// 30.24, - / 31.64; 0.16 m 32.00, -, - / 32.80; 0.32 m 32.40, 31.93, 30.58 / 33.64;
/// 0.48 m 31.97, 31.80, - / 33.51. With the hull at 5 mm voxels (a sun at 20°, 70° / the
/// sky): 0.16 m 32.65, 31.92 / 34.01; 0.24 m 32.74, 31.79 / 34.14; 0.32 m 32.45, 30.86 /
/// 34.35; 0.40 m 32.02, 30.47 / 34.40. Reported on pose 1 and checked at the tiny and
/// paper sizes in docs/results/hard_light.md.
/// Leaving the hull's voxels around the point before looking for an occluder, instead
/// of a fixed offset, scored 0.5-1.2 dB under no shadow.
pub const SHADOW_OFFSET_PER_HEIGHT: f32 = 0.17;

/// One view's sun: its direction in the view's dome frame, and the nearest conditions'
/// inverse-angle weights.
#[derive(Debug, Clone, PartialEq)]
pub struct SunView {
    /// Unit, toward the sun, dome frame of the view.
    pub direction: Vec3,
    /// `(condition, weight)`, [`NEAREST`] of them, weights summing to 1.
    pub nearest: Vec<(usize, f32)>,
    /// Per condition of `nearest`: the conditions that predict its image when it is left
    /// out, weighted as `nearest` is (the [`NEAREST`] others nearest to its direction).
    pub held_out: Vec<Vec<(usize, f32)>>,
    /// The conditions the trust reads, each once: `nearest`'s first, in order, then those
    /// of `held_out` not among them.
    pub involved: Vec<usize>,
    /// `held_out` with each condition as its place in `involved`.
    pub held_at: Vec<Vec<(usize, f32)>>,
    /// How compact the sun is against the cell of its nearest condition, 1 (a point) to
    /// 0 (twice as broad as the cell: the basis resolves it, [`compactness`]).
    pub compactness: f32,
}

/// A sun relit by a pose's normals (see the module text).
#[derive(Debug, Clone)]
pub struct SunLight {
    /// Per condition: the direction of the light standing for it ([`condition_lights`]).
    pub directions: Vec<Vec3>,
    /// Per condition: its lights' directions and shares of its light (luminance).
    pub lights: Vec<Vec<(Vec3, f32)>>,
    /// Per condition: the cone its lights lie in ([`group_cone`]).
    pub cones: Vec<(Vec3, f32)>,
    /// Per condition: the sun's illuminance per unit of the condition's, per channel
    /// (0 where the condition delivers none).
    pub unit: Vec<Rgb>,
    /// Per view.
    pub views: Vec<SunView>,
    /// Unit, toward the sun, subject frame (where the visual hull is).
    pub subject: Vec3,
    /// The pose's visual hull seen from the sun, which casts its shadows (`None`: no
    /// hull, no cast shadows).
    pub depth: Option<SunDepth>,
    /// How far from a texel's point its shadow ray starts, metres ([`shadow_offset_m`]).
    pub shadow_offset_m: f32,
    /// The sun's illuminance, luminance: its weight among the suns' trusts ([`suns_texel`]).
    pub luminance: f32,
}

/// [`SHADOW_OFFSET_PER_HEIGHT`] of the height of `hull`'s grid, metres.
pub fn shadow_offset_m(hull: &VoxelHull) -> f32 {
    let g = hull.grid();
    SHADOW_OFFSET_PER_HEIGHT * g.dims[1] as f32 * g.voxel_m
}

impl SunLight {
    /// `sun` (subject frame) over a basis of `conditions`, for views at turntable angles
    /// `turntables` (radians) read at level of detail `level`, its shadows cast by `hull`
    /// where there is one (its map's texel as wide as theirs, [`SunDepth::new`]).
    pub fn new(
        sun: &Sun,
        conditions: &[ConditionRecord],
        turntables: &[f32],
        hull: Option<&Arc<VoxelHull>>,
        level: u8,
    ) -> Self {
        let lights = condition_lights(conditions);
        let directions: Vec<Vec3> = lights.iter().map(|l| l.0).collect();
        let e = sun.illuminance();
        let unit = lights
            .iter()
            .map(|(_, delivered)| per_unit(e, *delivered))
            .collect();
        let lights = condition_light_shares(conditions);
        let cones = lights.iter().map(|l| group_cone(l)).collect();
        // Views of one turntable angle (a column's cameras, the views not read) see the
        // sun alike: each angle is worked out once.
        let (angles, at) = distinct(turntables);
        let distinct_views: Vec<SunView> = angles
            .iter()
            .map(|&theta| {
                let direction = (Mat3::from_rotation_y(theta) * sun.direction()).normalize();
                let nearest = nearest_weights_by(&directions, direction, NEAREST, WEIGHT_POWER);
                let held_out: Vec<Vec<(usize, f32)>> = nearest
                    .iter()
                    .map(|&(k, _)| held_out_weights(&directions, k))
                    .collect();
                let mut involved: Vec<usize> = nearest.iter().map(|&(k, _)| k).collect();
                for &(k, _) in held_out.iter().flatten() {
                    if !involved.contains(&k) {
                        involved.push(k);
                    }
                }
                let place = |k: usize| involved.iter().position(|&j| j == k).unwrap_or(0);
                let held_at = (held_out.iter())
                    .map(|held| held.iter().map(|&(k, w)| (place(k), w)).collect())
                    .collect();
                SunView {
                    direction,
                    compactness: compactness(sun, &directions, nearest[0].0),
                    nearest,
                    held_out,
                    involved,
                    held_at,
                }
            })
            .collect();
        let views = at.iter().map(|&k| distinct_views[k].clone()).collect();
        Self {
            directions,
            lights,
            cones,
            unit,
            views,
            subject: sun.direction(),
            depth: hull.map(|h| SunDepth::new(h, sun.direction(), level)),
            shadow_offset_m: hull.map_or(0.0, |h| shadow_offset_m(h)),
            luminance: luminance(e),
        }
    }

    /// The same sun with other walkers' hulls in the way of its shadows too
    /// ([`SunDepth::with_occluders`]; nothing changes without a hull of its own).
    pub fn with_occluders(mut self, occluders: &[crate::sun_depth::Occluder]) -> Self {
        if !occluders.is_empty() {
            self.depth = self.depth.map(|d| d.with_occluders(occluders));
        }
        self
    }

    /// Condition `k`'s shading of a normal `n`, per unit of its light: its lights'
    /// `max(n · l, 0)` weighted by their shares ([`cone_shading`]).
    #[inline]
    pub fn shading(&self, k: usize, n: Vec3) -> f32 {
        cone_shading(&self.lights[k], self.cones[k], n)
    }

    /// Whether the sun reaches `surface`, a texel's point on the visual hull (subject
    /// frame), as far as the hull can tell: from [`SunLight::shadow_offset_m`] toward the sun on,
    /// the hull does not lie between it and the sun ([`SunDepth::shades`]). Without a
    /// hull, always. (`shaders/relight.wgsl` is its twin.)
    pub fn sunlit(&self, surface: Vec3) -> bool {
        (self.depth.as_ref())
            .is_none_or(|m| !m.shades(surface + self.subject * self.shadow_offset_m))
    }

    /// The sun's light at a texel of view `view` whose normal is `normal` (`None`: none
    /// fitted), its basis images' linear values being `photo(k)`.
    pub fn texel(&self, view: usize, normal: Option<Vec3>, photo: impl Fn(usize) -> Rgb) -> Rgb {
        self.texel_by(view, normal, photo, |k, n| self.shading(k, n))
    }

    /// [`SunLight::texel`], condition `k`'s shading of a normal `n` being `shade(k, n)`
    /// (the same as [`SunLight::shading`], found once per texel: [`TexelCache`]).
    #[inline]
    fn texel_by(
        &self,
        view: usize,
        normal: Option<Vec3>,
        photo: impl Fn(usize) -> Rgb,
        shade: impl Fn(usize, Vec3) -> f32,
    ) -> Rgb {
        let v = &self.views[view];
        relight_texel(
            normal,
            |k| self.sunned(k, &photo),
            (shade, self.lights.len()),
            v.direction,
            &v.nearest,
        )
    }

    /// Image `k` per unit of its condition's light, times the sun's light.
    fn sunned(&self, k: usize, photo: impl Fn(usize) -> Rgb) -> Rgb {
        let (p, u) = (photo(k), self.unit[k]);
        [p[0] * u[0], p[1] * u[1], p[2] * u[2]]
    }

    /// How far the normals' sun is trusted at a texel of view `view` (see the module
    /// text), 0 (the basis' sun) to 1: the view's [`SunView::compactness`] times a
    /// smooth step down from 1 to 0 as the texel's leave-one-out error goes from
    /// [`TRUST_ERROR`]'s first to its second. The error: each nearest condition's image
    /// (luminance) predicted, as the sun is, from the others' ([`SunView::held_out`]),
    /// its absolute error weighted as the sun weighs them, over the same of the plain
    /// interpolation of the others' images (what the basis does without the normals).
    /// A texel with no normal has no model: 0.
    pub fn trust(&self, view: usize, normal: Option<Vec3>, photo: impl Fn(usize) -> Rgb) -> f32 {
        self.trust_by(view, normal, photo, |k, n| self.shading(k, n))
    }

    /// [`SunLight::trust`], shading as [`SunLight::texel_by`] does.
    #[inline]
    fn trust_by(
        &self,
        view: usize,
        normal: Option<Vec3>,
        photo: impl Fn(usize) -> Rgb,
        shade: impl Fn(usize, Vec3) -> f32,
    ) -> f32 {
        let v = &self.views[view];
        let Some(n) = normal else {
            return 0.0;
        };
        if v.compactness <= 0.0 {
            return 0.0;
        }
        // Each condition's luminance and shading once, the nearest first.
        let (mut lum, mut shading) = ([0.0f32; INVOLVED], [0.0f32; INVOLVED]);
        for (j, &k) in v.involved.iter().enumerate().take(INVOLVED) {
            lum[j] = luminance(self.sunned(k, &photo));
            shading[j] = shade(k, n);
        }
        let (mut error, mut plain) = (0.0f32, 0.0f32);
        for (j, (&(_, w), held)) in v.nearest.iter().zip(&v.held_at).enumerate() {
            let (actual, wanted) = (lum[j], shading[j]);
            let (mut shaded, mut interpolated) = (0.0f32, 0.0f32);
            for &(m, wm) in held {
                shaded += wm * shading[m];
                interpolated += wm * lum[m];
            }
            // As the sun is relit: dark where the normal faces away.
            let predicted = if wanted <= 0.0 {
                0.0
            } else if shaded >= RATIO_FLOOR * wanted {
                interpolated * wanted / shaded
            } else {
                interpolated
            };
            error += w * (predicted - actual).abs();
            plain += w * (interpolated - actual).abs();
        }
        // The model's error against the plain interpolation's (what the basis does).
        let e = if plain > 0.0 {
            error / plain
        } else if error > 0.0 {
            f32::INFINITY
        } else {
            0.0
        };
        v.compactness * (1.0 - smoothstep(TRUST_ERROR[0], TRUST_ERROR[1], e))
    }
}

/// What `suns` add at a texel of view `view` (normal `normal`, basis images `photo(k)`)
/// to the relighting of the light less them: their light by the normals where they are
/// trusted, the basis' `basis` (the suns' coefficients' sum of the images) where not,
/// `basis + t (Σ_s sun_s − basis)` with `t` the suns' [`SunLight::trust`] weighted by
/// their luminance. A sun counts where `sunlit(s)` says it reaches the texel (asked only
/// where it would light it). At `t = 0` the texel is the basis' exactly. `cache` holds
/// what the suns share at the texel (a scratch kept between texels).
pub fn suns_texel(
    suns: &[SunLight],
    (view, normal): (usize, Option<Vec3>),
    (photo, cache): (impl Fn(usize) -> Rgb, &mut TexelCache),
    basis: Rgb,
    mut sunlit: impl FnMut(&SunLight) -> bool,
) -> Rgb {
    let Some(first) = suns.first() else {
        return basis;
    };
    cache.start(first.lights.len());
    let cache = &*cache;
    let photo = |k: usize| cache.photo(k, &photo);
    // Every sun's conditions are the same: their shadings are the first's.
    let shade = |k: usize, n: Vec3| cache.shading(k, || first.shading(k, n));
    let (mut trusted, mut total) = (0.0f32, 0.0f32);
    for sun in suns {
        trusted += sun.luminance * sun.trust_by(view, normal, photo, shade);
        total += sun.luminance;
    }
    let t = if total > 0.0 { trusted / total } else { 0.0 };
    if t <= 0.0 {
        return basis;
    }
    let mut lit = [0.0f32; 3];
    for sun in suns {
        let s = sun.texel_by(view, normal, photo, shade);
        if s != [0.0; 3] && sunlit(sun) {
            for c in 0..3 {
                lit[c] += s[c];
            }
        }
    }
    std::array::from_fn(|c| basis[c] + t * (lit[c] - basis[c]))
}

/// A texel's values that its suns ask for again and again, each found once: per
/// condition, its basis image and the shading of the texel's normal ([`suns_texel`]).
/// Kept between texels, so that nothing is allocated or cleared per texel: a value
/// holds for the texel whose count it was stored under.
#[derive(Debug, Default)]
pub struct TexelCache {
    /// Texels begun.
    texel: u32,
    /// Per condition: the texel its image is of, and the image.
    photos: Vec<Cell<(u32, Rgb)>>,
    /// Per condition: the texel its shading is of, and the shading.
    shadings: Vec<Cell<(u32, f32)>>,
}

impl TexelCache {
    /// Begins a texel of `conditions` conditions (the last one's values forgotten).
    fn start(&mut self, conditions: usize) {
        if self.photos.len() != conditions || self.texel == u32::MAX {
            self.texel = 0;
            self.photos = vec![Cell::new((0, [0.0; 3])); conditions];
            self.shadings = vec![Cell::new((0, 0.0)); conditions];
        }
        self.texel += 1;
    }

    /// Condition `k`'s image, `photo(k)` the first time.
    #[inline]
    fn photo(&self, k: usize, photo: impl Fn(usize) -> Rgb) -> Rgb {
        once(&self.photos, self.texel, k, || photo(k))
    }

    /// Condition `k`'s shading of the texel's normal, `shade()` the first time.
    #[inline]
    fn shading(&self, k: usize, shade: impl FnOnce() -> f32) -> f32 {
        once(&self.shadings, self.texel, k, shade)
    }
}

/// `cells[k]`'s value where it was stored for `texel`, else `find()`, stored for it.
#[inline]
fn once<T: Copy>(cells: &[Cell<(u32, T)>], texel: u32, k: usize, find: impl FnOnce() -> T) -> T {
    match cells.get(k).map(Cell::get) {
        Some((t, v)) if t == texel => v,
        _ => {
            let v = find();
            if let Some(cell) = cells.get(k) {
                cell.set((texel, v));
            }
            v
        }
    }
}

/// The [`NEAREST`] of `directions` other than `k` nearest to `directions[k]`, weighted
/// as a sun's nearest are.
pub fn held_out_weights(directions: &[Vec3], k: usize) -> Vec<(usize, f32)> {
    let others: Vec<usize> = (0..directions.len()).filter(|&j| j != k).collect();
    if others.is_empty() {
        return Vec::new();
    }
    let towards: Vec<Vec3> = others.iter().map(|&j| directions[j]).collect();
    nearest_weights_by(&towards, directions[k], NEAREST, WEIGHT_POWER)
        .into_iter()
        .map(|(j, w)| (others[j], w))
        .collect()
}

/// How compact `sun` is against the cell of condition `k` of `directions`: 1 while its
/// diameter is at most the angle from `k` to its nearest other condition (the cell's
/// width), falling smoothly to 0 at twice that. Falling from half the cell's width to
/// the whole cost `lobe_70_s5` (a Gaussian lobe of σ 5°, taken for a sun of about 17°
/// in cells of about 30°) 0.96 dB at the small oracle field's captured views, and moved
/// the dev maps by at most 0.06 dB: a source the size of a cell is still relit better
/// by the normals than by the basis.
pub fn compactness(sun: &Sun, directions: &[Vec3], k: usize) -> f32 {
    let cell = cell_width(directions, k);
    1.0 - smoothstep(cell, 2.0 * cell, 2.0 * sun.radius())
}

/// The width of condition `k`'s cell among `directions`: the angle to its nearest other
/// (radians, at most π), what [`compactness`] holds a sun against.
pub fn cell_width(directions: &[Vec3], k: usize) -> f32 {
    (directions.iter().enumerate())
        .filter(|&(j, d)| j != k && *d != Vec3::ZERO)
        .map(|(_, d)| d.dot(directions[k]).clamp(-1.0, 1.0).acos())
        .fold(std::f32::consts::PI, f32::min)
}

/// 0 below `a`, 1 above `b`, `3x² − 2x³` of `x = (v − a) / (b − a)` between (WGSL's
/// `smoothstep`).
#[inline]
pub fn smoothstep(a: f32, b: f32, v: f32) -> f32 {
    let x = ((v - a) / (b - a)).clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// The distinct values of `angles` (bit for bit, in first-seen order) and, per angle, the
/// index of its value among them.
pub(crate) fn distinct(angles: &[f32]) -> (Vec<f32>, Vec<usize>) {
    let mut values: Vec<f32> = Vec::new();
    let at = angles
        .iter()
        .map(
            |a| match values.iter().position(|v| v.to_bits() == a.to_bits()) {
                Some(k) => k,
                None => {
                    values.push(*a);
                    values.len() - 1
                }
            },
        )
        .collect();
    (values, at)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::LightRecord;

    fn condition(direction: Vec3, e: f32) -> ConditionRecord {
        ConditionRecord {
            name: String::new(),
            floor: false,
            lights: vec![LightRecord {
                direction: direction.normalize().to_array(),
                intensity: [e; 3],
                solid_angle_sr: 0.5,
            }],
        }
    }

    #[test]
    fn views_of_one_angle_see_the_sun_as_that_angle_alone() {
        let (values, at) = distinct(&[0.5, 0.0, 0.5, -0.0, 1.0, 0.0]);
        // Bit for bit: -0 and 0 are two angles (each worked out as itself).
        assert_eq!(values, vec![0.5, 0.0, -0.0, 1.0]);
        assert_eq!(at, vec![0, 1, 0, 2, 3, 1]);
        let conditions: Vec<ConditionRecord> = [Vec3::X, Vec3::Z, Vec3::NEG_X, Vec3::Y]
            .into_iter()
            .map(|d| condition(d + 0.3 * Vec3::Y, 1.0))
            .collect();
        let sun = Sun::new(Vec3::new(1.0, 1.0, 0.2), 0.53, [1.0; 3]).unwrap();
        let angles = [0.3, 1.2, 0.3, 2.0, 1.2];
        let together = SunLight::new(&sun, &conditions, &angles, None, 0);
        for (i, &a) in angles.iter().enumerate() {
            let alone = SunLight::new(&sun, &conditions, &[a], None, 0);
            assert_eq!(together.views[i], alone.views[0], "view {i}");
        }
    }

    #[test]
    fn the_shadow_offset_scales_with_the_subject() {
        let hull = |height: f32| {
            let grid = frf_core::volume::VoxelGrid::covering(
                Vec3::new(-0.3, 0.0, -0.3),
                Vec3::new(0.3, height, 0.3),
                0.05,
            );
            Arc::new(VoxelHull::from_fn(grid.unwrap(), |p| p.y < 0.9 * height))
        };
        let sun = Sun::new(Vec3::Y, 0.53, [1.0; 3]).unwrap();
        let conditions = vec![condition(Vec3::Y, 1.0)];
        let offset =
            |h: f32| SunLight::new(&sun, &conditions, &[0.0], Some(&hull(h)), 0).shadow_offset_m;
        let (walker, child) = (offset(1.9), offset(0.95));
        assert!(
            (walker - SHADOW_OFFSET_PER_HEIGHT * 1.9).abs() < 0.03,
            "{walker}"
        );
        assert!((child / walker - 0.5).abs() < 0.03, "{child} {walker}");
        // Without a hull nothing is cast, and nothing is offset.
        assert_eq!(
            SunLight::new(&sun, &conditions, &[0.0], None, 0).shadow_offset_m,
            0.0
        );
    }

    #[test]
    fn a_sun_on_a_condition_light_relights_as_its_image_scaled() {
        let conditions: Vec<ConditionRecord> = [Vec3::Y, Vec3::X, Vec3::Z, -Vec3::X]
            .into_iter()
            .map(|d| condition(d, 2.0))
            .collect();
        // The sun at +X of the subject frame: +X in the dome at θ = 0, −Z at θ = 90°.
        let sun = Sun::new(Vec3::X, 0.53, [4.0, 4.0, 4.0]).unwrap();
        let light = SunLight::new(
            &sun,
            &conditions,
            &[0.0, std::f32::consts::FRAC_PI_2],
            None,
            0,
        );
        assert_eq!(light.views[0].nearest, vec![(1, 1.0)]);
        assert!(light.views[1].direction.distance(-Vec3::Z) < 1e-5);
        let photo = |k: usize| [k as f32 + 1.0, 0.5, 0.0];
        // A texel facing the sun: the condition's image, times 4 / 2.
        let lit = light.texel(0, Some(Vec3::X), photo);
        assert!(
            (lit[0] - 4.0).abs() < 1e-5 && (lit[1] - 1.0).abs() < 1e-5,
            "{lit:?}"
        );
        // A texel facing away is dark; one without a normal takes the interpolation.
        assert_eq!(light.texel(0, Some(-Vec3::X), photo), [0.0; 3]);
        assert_eq!(light.texel(0, None, photo), [4.0, 1.0, 0.0]);
    }

    /// Seven single-light conditions (the zenith and a ring at `elevation` degrees) of
    /// 2 units each.
    fn dome(elevation: f32) -> Vec<ConditionRecord> {
        let ring = (0..6).map(move |j| {
            let a = j as f32 * std::f32::consts::FRAC_PI_3;
            Vec3::new(a.cos(), elevation.to_radians().tan(), a.sin())
        });
        std::iter::once(Vec3::Y)
            .chain(ring)
            .map(|d| condition(d, 2.0))
            .collect()
    }

    #[test]
    fn a_lambertian_texel_is_trusted_and_one_the_fit_misses_keeps_the_basis_sun_exactly() {
        let conditions = dome(40.0);
        let sun = Sun::new(Vec3::new(0.5, 1.0, 0.2).normalize(), 0.53, [3.0; 3]).unwrap();
        let light = SunLight::new(&sun, &conditions, &[0.0], None, 0);
        let n = Vec3::new(0.6, 0.7, 0.1).normalize();
        let dirs = condition_lights(&conditions);
        // Its images under unit light, Lambertian of albedo 0.4 with normal n.
        let lambert = |k: usize| [0.4 * 2.0 * n.dot(dirs[k].0).max(0.0); 3];
        let basis = [0.123, 0.456, 0.789];
        let lit = |_: &SunLight| true;
        // One cache for every texel below, as a view's texels share one.
        let mut cache = TexelCache::default();
        let trusted = suns_texel(
            std::slice::from_ref(&light),
            (0, Some(n)),
            (lambert, &mut cache),
            basis,
            lit,
        );
        assert!((light.trust(0, Some(n), lambert) - 1.0).abs() < 1e-4);
        let want = 0.4 * 3.0 * n.dot(sun.direction());
        assert!(
            trusted.iter().all(|&c| (c - want).abs() < 1e-4),
            "{trusted:?}"
        );
        // A texel whose images follow its normal less and less (lit alike by every
        // condition, as by light bounced from all around): the normals predict them
        // from each other ever worse than their plain interpolation does, and the trust
        // falls from 1 to 0.
        let mixed = |a: f32| move |k: usize| lambert(k).map(|x| a * x + (1.0 - a) * 0.5);
        let trusts: Vec<f32> = [1.0f32, 0.4, 0.35, 0.3, 0.25, 0.2, 0.1, 0.0]
            .map(|a| light.trust(0, Some(n), mixed(a)))
            .to_vec();
        assert!((trusts[0] - 1.0).abs() < 1e-4, "{trusts:?}");
        assert_eq!(*trusts.last().unwrap(), 0.0, "{trusts:?}");
        assert!(trusts.windows(2).all(|w| w[1] <= w[0] + 1e-6), "{trusts:?}");
        assert!(trusts.iter().any(|&t| t > 0.05 && t < 0.95), "{trusts:?}");
        // Where it is not trusted at all, the basis' sun exactly (the last texel's
        // values forgotten).
        assert_eq!(
            suns_texel(
                std::slice::from_ref(&light),
                (0, Some(n)),
                (mixed(0.0), &mut cache),
                basis,
                lit
            ),
            basis
        );
        // No normal, no model: the basis' sun.
        let none = suns_texel(&[light], (0, None), (lambert, &mut cache), basis, lit);
        assert_eq!(none, basis);
    }

    #[test]
    fn a_sun_as_broad_as_its_cell_is_left_to_the_basis() {
        let conditions = dome(82.0);
        let cell = Vec3::Y
            .angle_between(condition_lights(&conditions)[1].0)
            .to_degrees();
        let light = |diameter: f32| {
            let sun = Sun::new(Vec3::Y, diameter, [3.0; 3]).unwrap();
            SunLight::new(&sun, &conditions, &[0.0], None, 0).views[0].compactness
        };
        assert_eq!(light(0.53), 1.0);
        assert_eq!(light(cell), 1.0);
        let between = light(1.5 * cell);
        assert!(between > 0.2 && between < 0.8, "{between}");
        assert_eq!(light(2.0 * cell), 0.0);
        let n = Vec3::Y;
        let photo = |_: usize| [1.0; 3];
        let sun = Sun::new(Vec3::Y, 2.0 * cell, [3.0; 3]).unwrap();
        let broad = SunLight::new(&sun, &conditions, &[0.0], None, 0);
        assert_eq!(
            suns_texel(
                &[broad],
                (0, Some(n)),
                (photo, &mut TexelCache::default()),
                [0.5; 3],
                |_| true
            ),
            [0.5; 3]
        );
    }
}
