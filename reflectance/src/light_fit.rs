//! What a texel's photographs under single lights tell beyond a linear basis of them, and
//! relighting by it under a light between the captured ones.
//!
//! **The fit.** Per texel, a Lambertian model by photometric stereo: the scaled normal
//! `b` that best explains the texel's brightness under the lights that reach it,
//! `g_k ≈ b · m_k` (`m_k` the light's direction; for a group of lights, a basis
//! condition, their directions weighted by their shares of its light), solved by least
//! squares over the lights that neither leave it dark (a shadow) nor flare far above the
//! fit (a highlight, dropped once when four or more lights remain); then the normal
//! `b / |b|` and per channel the albedo that best explains the colour under those lights.
//!
//! **Relighting** under a light `l`: the photographs of the nearest captured lights,
//! weighted by inverse angle ([`nearest_weights`]), times the ratio of the fit's shading
//! under `l` to its shading under those lights:
//! `I(l) = Σ w_k I_k · S(l) / Σ w_k S_k`, `S(l) = max(n · l, 0)` and `S_k` the same
//! summed over group `k`'s lights by their shares (the albedo cancels, so the normal
//! alone relights: [`relight_texel`]). The fit carries how shading moves between
//! the lights (the terminator, which interpolating photographs smears into two soft
//! ones); the photographs carry what the fit does not model (texture, gloss, cast
//! shadows, light bounced between surfaces). Where the nearest lights barely reach the
//! texel by the fit, the fit's shading is scaled by the texel's own least-squares ratio of
//! photographs to fit over every light.

use glam::{DMat3, DVec3, Vec3};
use rayon::prelude::*;

use frf_core::image::{GrayImage, Image, Rgb, RgbImage, luminance};

use crate::field::ConditionRecord;
use crate::gloss::Gloss;

/// Below this share of its brightest light a texel counts as dark under a light.
const DARK: f32 = 0.03;
/// A light whose brightness exceeds the fit's by this share of its own is a highlight.
const HIGHLIGHT: f32 = 0.25;
/// The nearest lights' fitted shading below this share of the new light's is too little
/// to carry a ratio (a texel they barely reach, whose photographs are mostly noise and
/// shadow there). Chosen on the UW sets `gray`, `owl` and `cat` and reported on `buddha`
/// (6 of 12 lights kept; `scripts/sweep-ratio-floor.sh`, mean PSNR of the held-out
/// lights): 0.05 / 0.3 / 0.8 sum to 98.631 / 98.759 / 98.745 dB over the three (cat
/// 30.307 / 30.431 / 30.421, the others within 0.004 dB); on `buddha` 0.3 scores 29.668
/// dB, 1.59 above the interpolation of the three nearest (0.05: 28.895, 0.8: 29.603).
/// (It was first chosen on `buddha` itself, at c0d3436.)
pub const RATIO_FLOOR: f32 = 0.3;

/// The Lambertian fit of every texel of a set of photographs under single lights.
pub struct LightFit {
    width: usize,
    height: usize,
    /// Per texel, its unit normal (camera frame) and RGB albedo; `None` where too few
    /// lights reach it to fit one.
    texels: Vec<Option<(Vec3, [f32; 3])>>,
    /// A glossy lobe beside the diffuse fit ([`LightFit::fit_glossy`]).
    gloss: Option<Gloss>,
}

impl LightFit {
    /// Fits every texel of `mask` from `images` (linear, one per light, all one size)
    /// lit from `directions` (unit, toward the light).
    pub fn fit(images: &[&RgbImage], directions: &[Vec3], mask: &[bool]) -> Self {
        let lights: Vec<Vec<(Vec3, f32)>> = directions.iter().map(|&d| vec![(d, 1.0)]).collect();
        Self::fit_lights(images, &lights, mask)
    }

    /// [`LightFit::fit`] of images each lit by a group of distant lights (a basis
    /// condition): per image, its lights' unit directions and shares of its light
    /// ([`condition_light_shares`]). A group counts where the fit sees all its lights:
    /// its shading is then linear in the scaled normal, `b · Σ share l`.
    pub fn fit_lights(images: &[&RgbImage], lights: &[Vec<(Vec3, f32)>], mask: &[bool]) -> Self {
        let (width, height) = images.first().map_or((0, 0), |i| i.size());
        let texels = (0..width * height)
            .into_par_iter()
            .map(|i| {
                if !mask.get(i).copied().unwrap_or(false) {
                    return None;
                }
                let colours: Vec<[f32; 3]> = images.iter().map(|img| img.pixels()[i]).collect();
                fit_texel(&colours, lights)
            })
            .collect();
        Self {
            width,
            height,
            texels,
            gloss: None,
        }
    }

    /// [`LightFit::fit`], and beside it a glossy lobe seen from `view` (unit, toward the
    /// camera) where one explains what the diffuse fit leaves ([`Gloss::fit`]).
    pub fn fit_glossy(
        images: &[&RgbImage],
        directions: &[Vec3],
        mask: &[bool],
        view: Vec3,
    ) -> Self {
        let mut fit = Self::fit(images, directions, mask);
        fit.gloss = Gloss::fit(images, directions, &fit.texels, (fit.width, view));
        fit
    }

    /// Its glossy lobe, where it has one.
    pub fn gloss(&self) -> Option<&Gloss> {
        self.gloss.as_ref()
    }

    /// Width and height, texels.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Texel `i`'s normal and albedo, where one was fitted.
    pub fn texel(&self, i: usize) -> Option<(Vec3, [f32; 3])> {
        self.texels[i]
    }

    /// The photographs `images` (lit from `directions`, those the fit was made from or
    /// any others of the same texels) relit under a unit light from `l`: see the module
    /// text. Texels without a fit take the interpolation of the nearest `nearest`
    /// photographs alone.
    pub fn relight(
        &self,
        images: &[&RgbImage],
        directions: &[Vec3],
        l: Vec3,
        nearest: usize,
    ) -> RgbImage {
        let weights = nearest_weights(directions, l, nearest);
        let pixels = (0..self.width * self.height)
            .into_par_iter()
            .map(|i| {
                let normal = self.texels[i].map(|t| t.0);
                let shading = |k: usize, n: Vec3| n.dot(directions[k]).max(0.0);
                let photo = |k: usize| images[k].pixels()[i];
                let (Some(gloss), Some(n)) = (&self.gloss, normal) else {
                    return relight_texel(normal, photo, (shading, directions.len()), l, &weights);
                };
                // The photographs' highlights out, the new light's in.
                let matte = |k: usize| gloss.without(photo(k), i, n, directions[k]);
                let diffuse =
                    relight_texel(normal, matte, (shading, directions.len()), l, &weights);
                diffuse.map(|c| c + gloss.highlight(i, n, l))
            })
            .collect();
        Image::from_vec(self.width, self.height, pixels).expect("sized by the fit")
    }

    /// The fit of a view's basis images (linear, one per condition of `conditions`, as
    /// stored) inside its matte: each image per unit of its condition's light, each
    /// condition a light from [`condition_lights`]' direction (the dome frame of the
    /// view's turntable angle, in which its normals then are).
    pub fn of_basis(basis: &[RgbImage], conditions: &[ConditionRecord], alpha: &GrayImage) -> Self {
        let lights = condition_lights(conditions);
        let unit: Vec<RgbImage> = basis
            .iter()
            .zip(&lights)
            .map(|(b, (_, e))| b.map(|p| per_unit(p, *e)))
            .collect();
        let refs: Vec<&RgbImage> = unit.iter().collect();
        let mask: Vec<bool> = alpha.pixels().iter().map(|&a| a > 0.0).collect();
        Self::fit_lights(&refs, &condition_light_shares(conditions), &mask)
    }

    /// A fit of these normals (as a field stores them, [`crate::normalcodec`]); its
    /// albedo is unknown (1), which relighting does not need.
    pub fn from_normals(width: usize, height: usize, normals: &[Option<Vec3>]) -> Self {
        Self {
            width,
            height,
            texels: normals.iter().map(|n| n.map(|n| (n, [1.0; 3]))).collect(),
            gloss: None,
        }
    }

    /// Every texel's albedo (radiance per unit of irradiance at normal incidence), zero
    /// where unfitted.
    pub fn albedo(&self) -> Vec<[f32; 3]> {
        self.texels
            .iter()
            .map(|t| t.map_or([0.0; 3], |t| t.1))
            .collect()
    }

    /// Every texel's normal, `None` where unfitted.
    pub fn normals(&self) -> Vec<Option<Vec3>> {
        self.texels.iter().map(|t| t.map(|t| t.0)).collect()
    }
}

/// Per condition of a basis, one light standing for its lights: their direction
/// weighted by their irradiance (exact for a Lambertian texel that sees all of them),
/// and their irradiance summed, per channel.
pub fn condition_lights(conditions: &[ConditionRecord]) -> Vec<(Vec3, Rgb)> {
    conditions
        .iter()
        .map(|c| {
            let (mut d, mut e) = (Vec3::ZERO, [0.0f32; 3]);
            for l in &c.lights {
                d += Vec3::from(l.direction).normalize_or_zero() * luminance(l.intensity);
                for (sum, i) in e.iter_mut().zip(l.intensity) {
                    *sum += i;
                }
            }
            (d.normalize_or_zero(), e)
        })
        .collect()
}

/// Per condition of a basis, its lights' unit directions and shares of its light (by
/// luminance): what its image is per unit of its light, `Σ share · max(n · l, 0)` for a
/// Lambertian texel of normal `n` and unit albedo.
pub fn condition_light_shares(conditions: &[ConditionRecord]) -> Vec<Vec<(Vec3, f32)>> {
    conditions
        .iter()
        .map(|c| {
            let total: f32 = c.lights.iter().map(|l| luminance(l.intensity)).sum();
            c.lights
                .iter()
                .map(|l| {
                    let share = if total > 0.0 {
                        luminance(l.intensity) / total
                    } else {
                        0.0
                    };
                    (Vec3::from(l.direction).normalize_or_zero(), share)
                })
                .collect()
        })
        .collect()
}

/// A group of lights' shading of a normal `n`: `Σ share · max(n · l, 0)`.
#[inline]
pub fn group_shading(lights: &[(Vec3, f32)], n: Vec3) -> f32 {
    lights
        .iter()
        .map(|&(l, share)| share * n.dot(l).max(0.0))
        .sum()
}

/// The cone a group of lights lies in, which lets [`cone_shading`] skip the lights one
/// by one: their shares' sum of directions `m = Σ share · l`, and the bound `b` on
/// `n · m` above which a unit normal sees every light and below whose negative it sees
/// none. With `δ` the widest angle of a light from `m`'s direction, a normal within
/// `90° − δ` of it sees them all (`n · m ≥ |m| sin δ`), and one beyond `90° + δ` none; a
/// group spread over more than a hemisphere gets an infinite bound (always one by one).
pub fn group_cone(lights: &[(Vec3, f32)]) -> (Vec3, f32) {
    let m: Vec3 = lights.iter().map(|&(l, share)| l * share).sum();
    let Some(axis) = m.try_normalize() else {
        return (m, f32::INFINITY);
    };
    let widest = (lights
        .iter()
        .filter(|&&(l, share)| share != 0.0 && l != Vec3::ZERO))
    .map(|&(l, _)| l.normalize().dot(axis))
    .fold(1.0f32, f32::min);
    if widest <= 0.0 {
        return (m, f32::INFINITY);
    }
    // sin δ, and a margin for the rounding of unit normals.
    let sin = (1.0 - widest * widest).max(0.0).sqrt();
    (m, m.length() * (sin + 1e-4))
}

/// [`group_shading`] of `lights` whose cone is `cone` ([`group_cone`]): `n · m` where `n`
/// sees every light, 0 where it sees none, the lights one by one between. The same
/// shading but for rounding; the GPU's `shading` (`shaders/relight.wgsl`) is its twin.
#[inline]
pub fn cone_shading(lights: &[(Vec3, f32)], (m, bound): (Vec3, f32), n: Vec3) -> f32 {
    let d = n.dot(m);
    if d >= bound {
        d
    } else if d <= -bound {
        0.0
    } else {
        group_shading(lights, n)
    }
}

/// `p` per unit of the light `e` (0 in a channel `e` leaves dark).
pub fn per_unit(p: Rgb, e: Rgb) -> Rgb {
    std::array::from_fn(|c| if e[c] > 0.0 { p[c] / e[c] } else { 0.0 })
}

/// One texel of normal `normal` (`None`: unfitted), seen under unit lights as
/// `photo(k)`, relit under a unit light from `l` by the photographs `weights` names (see
/// the module text). `shading(k, n)` is the shading of a normal `n` by light `k` per unit
/// of its light (`max(n · l_k, 0)` for a single distant light; for a condition of several
/// lights, their sum weighted by their share of its light). The fit's albedo cancels from
/// both of its ratios, so the normal alone is needed: the CPU reference of the GPU's sun
/// term (`shaders/relight.wgsl`).
#[inline]
pub fn relight_texel(
    normal: Option<Vec3>,
    photo: impl Fn(usize) -> Rgb,
    (shading, lights): (impl Fn(usize, Vec3) -> f32, usize),
    l: Vec3,
    weights: &[(usize, f32)],
) -> Rgb {
    let Some(n) = normal else {
        return weighted(weights, &photo);
    };
    let wanted = n.dot(l).max(0.0);
    if wanted <= 0.0 {
        return [0.0; 3];
    }
    let interpolated = weighted(weights, &photo);
    let shaded: f32 = weights.iter().map(|&(k, w)| w * shading(k, n)).sum();
    if shaded >= RATIO_FLOOR * wanted {
        return interpolated.map(|x| x * wanted / shaded);
    }
    // The fit's shading, scaled by the photographs' ratio to it over every light.
    let (mut num, mut den) = ([0.0f32; 3], 0.0f32);
    for k in 0..lights {
        let m = shading(k, n);
        if m > 0.0 {
            let p = photo(k);
            for c in 0..3 {
                num[c] += p[c] * m;
            }
            den += m * m;
        }
    }
    if den <= 0.0 {
        return [0.0; 3];
    }
    num.map(|x| wanted * x / den)
}

/// The `n` directions of `directions` nearest to `l` (by angle), weighted by the inverse
/// of their angle and normalised to sum to 1; a direction equal to `l` takes all.
pub fn nearest_weights(directions: &[Vec3], l: Vec3, n: usize) -> Vec<(usize, f32)> {
    nearest_weights_by(directions, l, n, 1.0)
}

/// [`nearest_weights`] by the inverse of the angle to the power `power`.
pub fn nearest_weights_by(directions: &[Vec3], l: Vec3, n: usize, power: f32) -> Vec<(usize, f32)> {
    let mut by_angle: Vec<(usize, f32)> = directions
        .iter()
        .enumerate()
        .map(|(k, d)| (k, d.dot(l).clamp(-1.0, 1.0).acos()))
        .collect();
    by_angle.sort_by(|a, b| a.1.total_cmp(&b.1));
    by_angle.truncate(n.max(1));
    if by_angle[0].1 < 1e-6 {
        return vec![(by_angle[0].0, 1.0)];
    }
    let total: f32 = by_angle.iter().map(|(_, a)| 1.0 / a.powf(power)).sum();
    by_angle
        .iter()
        .map(|&(k, a)| (k, 1.0 / a.powf(power) / total))
        .collect()
}

/// Farthest-point sampling of `k` of `directions`: first the one nearest `start`, then
/// each time the one farthest (by angle) from those taken. In the order taken.
pub fn farthest_lights(directions: &[Vec3], k: usize, start: Vec3) -> Vec<usize> {
    let k = k.min(directions.len());
    let mut taken: Vec<usize> = Vec::with_capacity(k);
    if k == 0 {
        return taken;
    }
    let first = (0..directions.len())
        .max_by(|&a, &b| {
            directions[a]
                .dot(start)
                .total_cmp(&directions[b].dot(start))
        })
        .expect("not empty");
    taken.push(first);
    // Per direction, the cosine of its angle to the nearest taken.
    let mut nearest: Vec<f32> = directions
        .iter()
        .map(|d| d.dot(directions[first]))
        .collect();
    while taken.len() < k {
        let next = (0..directions.len())
            .filter(|j| !taken.contains(j))
            .min_by(|&a, &b| nearest[a].total_cmp(&nearest[b]))
            .expect("fewer taken than directions");
        taken.push(next);
        for (j, d) in directions.iter().enumerate() {
            nearest[j] = nearest[j].max(d.dot(directions[next]));
        }
    }
    taken
}

/// `Σ w_k images[k]` over `weights` (e.g. [`nearest_weights`]): the interpolation of
/// photographs a relight starts from, and the baseline it is scored against.
pub fn blend(images: &[&RgbImage], weights: &[(usize, f32)]) -> RgbImage {
    let (w, h) = images.first().map_or((0, 0), |i| i.size());
    let pixels = (0..w * h)
        .map(|i| weighted(weights, |k| images[k].pixels()[i]))
        .collect();
    Image::from_vec(w, h, pixels).expect("sized as the photographs")
}

/// `Σ w_k f(k)` over `weights`.
#[inline]
fn weighted(weights: &[(usize, f32)], f: impl Fn(usize) -> [f32; 3]) -> [f32; 3] {
    let mut out = [0.0f32; 3];
    for &(k, w) in weights {
        let v = f(k);
        for c in 0..3 {
            out[c] += w * v[c];
        }
    }
    out
}

fn sum3(v: [f32; 3]) -> f32 {
    v[0] + v[1] + v[2]
}

/// One texel's normal and albedo from its colour under each group of lights (see the
/// module text), or `None` when fewer than three groups reach it or they do not fix a
/// normal.
fn fit_texel(colours: &[[f32; 3]], lights: &[Vec<(Vec3, f32)>]) -> Option<(Vec3, [f32; 3])> {
    let grey: Vec<f32> = colours.iter().map(|c| sum3(*c) / 3.0).collect();
    let brightest = grey.iter().copied().fold(0.0f32, f32::max);
    if brightest <= 0.0 {
        return None;
    }
    // Each group's shading of the scaled normal where it sees all of the group's lights.
    let mean: Vec<Vec3> = lights
        .iter()
        .map(|g| g.iter().map(|&(l, share)| l * share).sum())
        .collect();
    let mut used: Vec<usize> = (0..grey.len())
        .filter(|&k| grey[k] > DARK * brightest)
        .collect();
    let mut b = solve(&grey, &mean, &used)?;
    // Groups the fit says do not wholly reach it, then one highlight, are dropped.
    let before = used.len();
    used.retain(|&k| b.dot(mean[k]) > 0.0);
    if used.len() >= 4 {
        let (worst, excess) = used
            .iter()
            .map(|&k| (k, grey[k] - b.dot(mean[k])))
            .max_by(|a, c| a.1.total_cmp(&c.1))
            .expect("not empty");
        if excess > HIGHLIGHT * grey[worst] {
            used.retain(|&k| k != worst);
        }
    }
    if used.len() != before {
        b = solve(&grey, &mean, &used)?;
    }
    let n = b.try_normalize()?;
    let (mut num, mut den) = ([0.0f32; 3], 0.0f32);
    for &k in &used {
        let s = group_shading(&lights[k], n);
        for c in 0..3 {
            num[c] += colours[k][c] * s;
        }
        den += s * s;
    }
    if den <= 0.0 {
        return None;
    }
    Some((n, num.map(|x| (x / den).max(0.0))))
}

/// The least-squares `b` of `grey[k] ≈ b · directions[k]` over `used` (at least three
/// lights not in one plane through the texel).
fn solve(grey: &[f32], directions: &[Vec3], used: &[usize]) -> Option<Vec3> {
    if used.len() < 3 {
        return None;
    }
    let mut ata = DMat3::ZERO;
    let mut atb = DVec3::ZERO;
    for &k in used {
        let d = directions[k].as_dvec3();
        ata += DMat3::from_cols(d * d.x, d * d.y, d * d.z);
        atb += d * grey[k] as f64;
    }
    if ata.determinant().abs() < 1e-9 {
        return None;
    }
    Some((ata.inverse() * atb).as_vec3())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn farthest_lights_start_nearest_the_view_and_spread() {
        let dirs = [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.1, 0.0, 1.0).normalize(),
            Vec3::new(1.0, 0.0, 0.2).normalize(),
            Vec3::new(-1.0, 0.0, 0.2).normalize(),
        ];
        let taken = farthest_lights(&dirs, 3, Vec3::Z);
        assert_eq!(taken[0], 0);
        assert!(
            taken[1..].contains(&2) && taken[1..].contains(&3),
            "{taken:?}"
        );
    }

    #[test]
    fn nearest_weights_sum_to_one_and_favour_the_nearest() {
        let dirs = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X];
        let l = Vec3::new(1.0, 0.3, 0.1).normalize();
        let w = nearest_weights(&dirs, l, 3);
        assert_eq!(w.len(), 3);
        assert!((w.iter().map(|x| x.1).sum::<f32>() - 1.0).abs() < 1e-5);
        assert_eq!(w[0].0, 0);
        assert!(w[0].1 > w[1].1);
        assert_eq!(nearest_weights(&dirs, Vec3::Y, 3), vec![(1, 1.0)]);
    }

    /// A cell of lights about `axis` spread `spread` radians, uneven shares.
    fn cell(axis: Vec3, spread: f32) -> Vec<(Vec3, f32)> {
        let (u, v) = axis.any_orthonormal_pair();
        (0..16)
            .map(|j| {
                let (a, r) = (j as f32 * 2.4, spread * ((j % 4) as f32 + 1.0) / 4.0);
                let d = axis * r.cos() + (u * a.cos() + v * a.sin()) * r.sin();
                (d, (1 + j % 3) as f32 / 32.0)
            })
            .collect()
    }

    proptest::proptest! {
        #[test]
        fn the_cone_shades_as_the_lights_one_by_one(
            ax in -1.0f32..1.0, ay in -1.0f32..1.0, az in -1.0f32..1.0,
            nx in -1.0f32..1.0, ny in -1.0f32..1.0, nz in -1.0f32..1.0,
            spread in 0.0f32..2.0,
        ) {
            let (Some(axis), Some(n)) = (Vec3::new(ax, ay, az).try_normalize(),
                Vec3::new(nx, ny, nz).try_normalize()) else { return Ok(()) };
            let lights = cell(axis, spread);
            let cone = group_cone(&lights);
            let (one_by_one, by_cone) = (group_shading(&lights, n), cone_shading(&lights, cone, n));
            proptest::prop_assert!((one_by_one - by_cone).abs() <= 1e-5, "{one_by_one} {by_cone}");
        }
    }

    #[test]
    fn the_cone_skips_the_lights_only_where_a_normal_sees_all_or_none() {
        let lights = cell(Vec3::Y, 0.3);
        let (m, bound) = group_cone(&lights);
        assert!(Vec3::Y.dot(m) >= bound && (-Vec3::Y).dot(m) <= -bound);
        // At the terminator some lights are seen and some not: one by one.
        assert!(Vec3::X.dot(m).abs() < bound);
        // A group over more than a hemisphere is never skipped.
        let wide = [(Vec3::Y, 0.5), (Vec3::new(0.0, -0.2, 1.0).normalize(), 0.5)];
        assert!(group_cone(&wide).1.is_finite());
        let opposed = [(Vec3::Y, 0.5), (-Vec3::Y, 0.5)];
        assert_eq!(group_cone(&opposed).1, f32::INFINITY);
    }
}
