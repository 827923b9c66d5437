//! A glossy lobe beside a Lambertian light fit, so that a light between the captured
//! ones places its highlight where the surface's normal puts it (docs/design.md section
//! 4.1): the diffuse fit carries how shading moves, the photographs what it does not
//! model, and neither can move a highlight to a light no photograph was taken under.
//!
//! **The lobe** is Torrance–Sparrow's, as the stage renders skin and cloth ([`lobe`]):
//! the Beckmann distribution of microfacet slopes of RMS `m`, the V-cavity
//! shadowing–masking, Fresnel folded into the strength:
//! `s(l) = D(n·h; m) G / (4 n·v)` per unit irradiance at normal incidence, `h` halfway
//! between the light `l` and the view `v`.
//!
//! **The fit.** What the diffuse fit leaves of a texel's photographs, `r_k = g_k − ρ S_k`
//! (grey), is taken for `k_s s(l_k)`: a white highlight (a dielectric's) of per-texel
//! strength `k_s`, fitted by least squares pooled over a Gaussian neighbourhood
//! ([`POOL_SIGMA`]): few photographs light one texel's highlight, its neighbours'
//! highlights fix how strong the material's is. The roughness is one for the whole
//! set (spatially smooth, as a material's is), the one of [`ROUGHNESS`] whose pooled
//! strengths explain the most of the residuals; none when none explains any.
//!
//! **Relighting** takes each photograph's highlight out, relights the rest by the
//! diffuse fit and adds the new light's highlight:
//! `I(l) = relight(I_k − k_s s(l_k)) + k_s s(l)`.

use frf_core::filter::gaussian_blur;
use frf_core::image::{Image, Rgb, RgbImage};
use glam::Vec3;
use rayon::prelude::*;

/// The roughnesses (Beckmann RMS slope) a set's gloss is chosen among: from a polished
/// surface's to a matte one's; the stage's skin is 0.3-0.35.
pub const ROUGHNESS: [f32; 6] = [0.08, 0.12, 0.18, 0.25, 0.35, 0.5];
/// The standard deviation, texels, of the neighbourhood a texel's strength is pooled
/// over.
pub const POOL_SIGMA: f32 = 3.0;

/// The lobe's reflected radiance per unit irradiance at normal incidence, per unit of
/// strength (see the module text); 0 where the light or the view is behind the surface.
pub fn lobe(n: Vec3, l: Vec3, v: Vec3, roughness: f32) -> f32 {
    let (nl, nv) = (n.dot(l), n.dot(v));
    if nl <= 0.0 || nv <= 0.0 {
        return 0.0;
    }
    let h = (l + v).normalize();
    let nh = n.dot(h).max(1e-4);
    let vh = v.dot(h).max(1e-4);
    let (m2, nh2) = (roughness * roughness, nh * nh);
    let d = (-(1.0 - nh2) / (nh2 * m2)).exp() / (std::f32::consts::PI * m2 * nh2 * nh2);
    let g = (2.0 * nh * nv / vh).min(2.0 * nh * nl / vh).min(1.0);
    d * g / (4.0 * nv)
}

/// A set's fitted gloss: its roughness, the view direction, and per texel the lobe's
/// strength (see the module text).
#[derive(Debug, Clone)]
pub struct Gloss {
    /// Beckmann RMS slope.
    pub roughness: f32,
    /// Unit, toward the camera, the frame of the normals and lights.
    pub view: Vec3,
    /// Per texel, `k_s` (0 where there is no fit).
    pub strength: Vec<f32>,
}

impl Gloss {
    /// The gloss of `images` (linear, one per light of `directions`, `width` wide) seen
    /// from `view`, beside their diffuse fit `texels` (per texel its normal and albedo,
    /// `None` where unfitted); `None` when no roughness explains any of what the diffuse
    /// fit leaves.
    pub fn fit(
        images: &[&RgbImage],
        directions: &[Vec3],
        texels: &[Option<(Vec3, Rgb)>],
        (width, view): (usize, Vec3),
    ) -> Option<Self> {
        let height = texels.len().checked_div(width)?;
        let grey = |k: usize, i: usize| images[k].pixels()[i].iter().sum::<f32>() / 3.0;
        let best = ROUGHNESS
            .par_iter()
            .map(|&m| {
                // Per texel: Σ r s and Σ s², then pooled.
                let sums: Vec<(f32, f32)> = texels
                    .iter()
                    .enumerate()
                    .map(|(i, t)| {
                        let Some((n, albedo)) = *t else {
                            return (0.0, 0.0);
                        };
                        let rho = albedo.iter().sum::<f32>() / 3.0;
                        let (mut rs, mut ss) = (0.0f32, 0.0f32);
                        for (k, &l) in directions.iter().enumerate() {
                            let s = lobe(n, l, view, m);
                            if s > 0.0 {
                                rs += (grey(k, i) - rho * n.dot(l).max(0.0)) * s;
                                ss += s * s;
                            }
                        }
                        (rs, ss)
                    })
                    .collect();
                let pool = |f: fn(&(f32, f32)) -> f32| {
                    let img = Image::from_vec(width, height, sums.iter().map(f).collect());
                    gaussian_blur(&img.expect("sized by the texels"), POOL_SIGMA).into_pixels()
                };
                let (rs, ss) = (pool(|s| s.0), pool(|s| s.1));
                let strength: Vec<f32> = (0..texels.len())
                    .map(|i| {
                        if texels[i].is_some() && ss[i] > 0.0 {
                            (rs[i] / ss[i]).max(0.0)
                        } else {
                            0.0
                        }
                    })
                    .collect();
                // How much of the residuals the lobe explains, texel by texel.
                let explained: f64 = sums
                    .iter()
                    .zip(&strength)
                    .map(|(&(r, s), &k)| (2.0 * k * r - k * k * s) as f64)
                    .sum();
                (m, strength, explained)
            })
            .max_by(|a, b| a.2.total_cmp(&b.2))?;
        (best.2 > 0.0).then_some(Self {
            roughness: best.0,
            view,
            strength: best.1,
        })
    }

    /// Texel `i`'s highlight under a unit light from `l`, its normal `n`.
    pub fn highlight(&self, i: usize, n: Vec3, l: Vec3) -> f32 {
        let k = self.strength.get(i).copied().unwrap_or(0.0);
        if k <= 0.0 {
            return 0.0;
        }
        k * lobe(n, l, self.view, self.roughness)
    }

    /// `photo` with texel `i`'s highlight under `l` taken out (no channel below zero).
    pub fn without(&self, photo: Rgb, i: usize, n: Vec3, l: Vec3) -> Rgb {
        let s = self.highlight(i, n, l);
        photo.map(|c| (c - s).max(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lobe_peaks_at_the_mirror_direction_and_narrows_with_smoothness() {
        let (n, v) = (Vec3::Z, Vec3::new(0.3, 0.0, 1.0).normalize());
        let mirror = 2.0 * n.dot(v) * n - v;
        let off = Vec3::new(-0.1, 0.25, 1.0).normalize();
        for m in ROUGHNESS {
            assert!(lobe(n, mirror, v, m) > lobe(n, off, v, m), "{m}");
        }
        let ratio = |m: f32| lobe(n, off, v, m) / lobe(n, mirror, v, m);
        assert!(ratio(0.12) < ratio(0.35));
        assert_eq!(lobe(n, -Vec3::Z, v, 0.3), 0.0);
    }
}
