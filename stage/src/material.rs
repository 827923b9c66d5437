//! What the walker is made of: procedural solid textures in each part's own frame (so
//! the texture moves with the body) on skin, hair, a striped shirt, patterned trousers
//! and shoes, with the specular parameters of the Torrance–Sparrow lobe in
//! [`crate::brdf`].
//!
//! The textures are built from 3D value noise at several scales. Their features span
//! 1.5–8 cm, i.e. 1–4 pixels at the tiny preset and 7–35 pixels at paper size, so that
//! optical flow has texture to lock onto at every resolution (docs/design.md section 5.3).

use frf_core::image::Rgb;
use glam::Vec3;

use crate::rng::mix64;

/// The materials of the walker.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Material {
    /// Bare skin (neck, forearms, hands).
    Skin,
    /// The head: face skin with eyes and mouth, hair on top and at the back.
    Head,
    /// Striped cotton shirt.
    Shirt,
    /// Patterned trousers.
    Trousers,
    /// Leather shoes with white soles.
    Shoe,
}

/// Reflectance parameters at one surface point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    /// Diffuse albedo (linear RGB).
    pub albedo: Rgb,
    /// Specular reflectance at normal incidence (Schlick's F0).
    pub f0: f32,
    /// Beckmann roughness (RMS slope) of the microfacets.
    pub roughness: f32,
}

/// 3D value noise in `[0, 1]`: hashed lattice values, smoothstep-interpolated.
fn value_noise(p: Vec3, salt: u64) -> f32 {
    let base = p.floor();
    let f = p - base;
    let s = f * f * (Vec3::splat(3.0) - 2.0 * f);
    let (ix, iy, iz) = (base.x as i64, base.y as i64, base.z as i64);
    let lattice = |dx: i64, dy: i64, dz: i64| {
        let h = mix64(
            salt ^ mix64((ix + dx) as u64 ^ mix64((iy + dy) as u64 ^ mix64((iz + dz) as u64))),
        );
        (h >> 40) as f32 / (1u64 << 24) as f32
    };
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = lerp(lattice(0, 0, 0), lattice(1, 0, 0), s.x);
    let x10 = lerp(lattice(0, 1, 0), lattice(1, 1, 0), s.x);
    let x01 = lerp(lattice(0, 0, 1), lattice(1, 0, 1), s.x);
    let x11 = lerp(lattice(0, 1, 1), lattice(1, 1, 1), s.x);
    lerp(lerp(x00, x10, s.y), lerp(x01, x11, s.y), s.z)
}

/// How much of a pattern of `frequency` (cycles per metre) survives on a pixel that
/// covers `footprint` metres: all of it below a quarter cycle per pixel, none from half a
/// cycle (the Nyquist limit) on. This is the stage's anti-aliasing prefilter, the role a
/// camera's lens and sensor play: without it, texture above the pixel rate aliases and
/// no resampling (nor any optical flow) can reproduce it.
fn detail(frequency: f32, footprint: f32) -> f32 {
    1.0 - smoothstep(0.25, 0.5, frequency * footprint)
}

/// Fractal sum of `octaves` noise layers starting at `frequency` (cycles per metre),
/// band-limited for a pixel footprint of `footprint` metres; result roughly in `[-1, 1]`.
fn fbm(p: Vec3, frequency: f32, octaves: u32, salt: u64, footprint: f32) -> f32 {
    let (mut sum, mut amp, mut norm, mut f) = (0.0, 1.0, 0.0, frequency);
    for o in 0..octaves {
        let keep = detail(f, footprint);
        if keep > 0.0 {
            sum += keep * amp * (value_noise(p * f, salt.wrapping_add(o as u64)) * 2.0 - 1.0);
        }
        norm += amp;
        amp *= 0.55;
        f *= 2.03;
    }
    sum / norm
}

fn scale(c: Rgb, k: f32) -> Rgb {
    c.map(|v| (v * k).clamp(0.0, 0.95))
}

fn mix(a: Rgb, b: Rgb, t: f32) -> Rgb {
    let t = t.clamp(0.0, 1.0);
    [0, 1, 2].map(|i| a[i] + (b[i] - a[i]) * t)
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

// Albedos: skin after measured values for light skin (Krishnaswamy & Baranoski 2004
// give ~0.35–0.6 in the visible); cloth and leather typical of fabrics and shoes.
const SKIN: Rgb = [0.62, 0.42, 0.33];
const HAIR: Rgb = [0.09, 0.06, 0.04];
const SHIRT_BASE: Rgb = [0.12, 0.24, 0.52];
const SHIRT_STRIPE: Rgb = [0.72, 0.70, 0.62];
const TROUSERS: Rgb = [0.16, 0.15, 0.13];
const TROUSERS_PATCH: Rgb = [0.42, 0.33, 0.22];
const SHOE: Rgb = [0.06, 0.045, 0.04];
const SOLE: Rgb = [0.75, 0.74, 0.70];
/// Period of the shirt's stripes, metres.
const STRIPE_PERIOD_M: f32 = 0.06;

impl Material {
    /// The surface at `local` (the part's frame, metres) as seen by a pixel covering
    /// `footprint` metres; `salt` decorrelates parts.
    pub fn surface(self, local: Vec3, salt: u64, footprint: f32) -> Surface {
        match self {
            Material::Skin => skin(local, salt, footprint),
            Material::Head => head(local, salt, footprint),
            Material::Shirt => {
                // Horizontal stripes of 6 cm period, broken up by a weave-scale noise.
                let wobble = 0.012 * fbm(local, 9.0, 2, salt ^ 7, footprint);
                let stripe = smoothstep(
                    -0.25,
                    0.25,
                    ((local.y + wobble) * std::f32::consts::TAU / STRIPE_PERIOD_M).sin(),
                );
                // Unresolved stripes fade to their mean.
                let stripe = 0.5 + (stripe - 0.5) * detail(1.0 / STRIPE_PERIOD_M, footprint);
                let c = mix(SHIRT_BASE, SHIRT_STRIPE, stripe);
                Surface {
                    albedo: scale(c, 1.0 + 0.5 * fbm(local, 22.0, 3, salt, footprint)),
                    f0: 0.04,
                    roughness: 0.6,
                }
            }
            Material::Trousers => {
                let patch = smoothstep(0.05, 0.25, fbm(local, 11.0, 3, salt ^ 3, footprint));
                let c = mix(TROUSERS, TROUSERS_PATCH, patch);
                Surface {
                    albedo: scale(c, 1.0 + 0.5 * fbm(local, 22.0, 3, salt, footprint)),
                    f0: 0.04,
                    roughness: 0.7,
                }
            }
            Material::Shoe => {
                let sole = smoothstep(-0.07, -0.065, -local.y);
                Surface {
                    albedo: scale(
                        mix(SHOE, SOLE, sole),
                        1.0 + 0.3 * fbm(local, 35.0, 2, salt, footprint),
                    ),
                    f0: 0.04,
                    roughness: 0.22,
                }
            }
        }
    }
}

fn skin(local: Vec3, salt: u64, footprint: f32) -> Surface {
    // Blotches and freckles: ±15 % over 2–6 cm, plus darker spots.
    let blotch = fbm(local, 25.0, 3, salt, footprint);
    let freckle =
        smoothstep(0.55, 0.75, fbm(local, 70.0, 1, salt ^ 5, footprint)) * detail(70.0, footprint);
    Surface {
        albedo: scale(mix(SKIN, [0.4, 0.24, 0.17], freckle), 1.0 + 0.35 * blotch),
        f0: 0.028, // skin's refractive index ~1.4 (Weyrich et al., SIGGRAPH 2006)
        roughness: 0.35,
    }
}

fn head(local: Vec3, salt: u64, footprint: f32) -> Surface {
    // Head frame: face toward +x, up +y, centre (0.01, 0.11, 0) with radii 0.10/0.12/0.085.
    let p = local - Vec3::new(0.01, 0.11, 0.0);
    // The hairline rises from the temples (4 cm above the head's centre) to the forehead
    // (7 cm), and the hair reaches down to the nape at the back.
    let hairline = 0.04 + 0.3 * p.x.max(0.0) + 0.01 * fbm(local, 25.0, 2, salt ^ 9, footprint);
    let is_hair = p.y > hairline || (p.x < -0.03 && p.y > -0.06);
    if is_hair {
        // Stretched 5x along y: its finest detail is 5x finer than `frequency` says.
        // Fine strands, and (below) isotropic clumps that survive at low resolution
        // where the strands fade out.
        let strands = fbm(
            local * Vec3::new(1.0, 5.0, 1.0),
            30.0,
            3,
            salt ^ 11,
            footprint * 5.0,
        );
        return Surface {
            albedo: scale(
                HAIR,
                1.0 + 0.6 * fbm(local, 20.0, 3, salt ^ 13, footprint) + 0.4 * strands,
            ),
            f0: 0.046, // keratin, n ≈ 1.55
            roughness: 0.25,
        };
    }
    let mut s = skin(local, salt, footprint);
    // Eyes and eyebrows on the front (+x) of the face, mouth below.
    for side in [-1.0f32, 1.0] {
        let eye = Vec3::new(0.09, 0.025, side * 0.035);
        let d = (p - eye) * Vec3::new(0.5, 1.6, 1.0);
        if d.length() < 0.014 {
            s.albedo = [0.05, 0.04, 0.035];
        }
        let brow = (p - eye - Vec3::new(0.0, 0.022, 0.0)) * Vec3::new(0.5, 3.0, 0.8);
        if brow.length() < 0.016 {
            s.albedo = HAIR;
        }
    }
    let mouth = (p - Vec3::new(0.085, -0.055, 0.0)) * Vec3::new(0.5, 4.0, 0.9);
    if mouth.length() < 0.022 {
        s.albedo = [0.45, 0.18, 0.16];
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn textures_are_varied_and_physical() {
        for m in [
            Material::Skin,
            Material::Head,
            Material::Shirt,
            Material::Trousers,
            Material::Shoe,
        ] {
            let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
            for i in 0..400 {
                let p = Vec3::new(i as f32 * 0.0037, (i % 17) as f32 * 0.011 - 0.09, 0.02);
                let s = m.surface(p, 1, 0.002);
                for c in s.albedo {
                    assert!((0.0..=0.95).contains(&c));
                }
                let l = frf_core::image::luminance(s.albedo);
                lo = lo.min(l);
                hi = hi.max(l);
            }
            assert!(hi > 1.3 * lo, "{m:?} is nearly uniform: {lo}..{hi}");
        }
    }

    #[test]
    fn noise_is_continuous() {
        let a = value_noise(Vec3::new(1.2, 3.4, 5.6), 0);
        let b = value_noise(Vec3::new(1.2001, 3.4, 5.6), 0);
        assert!((a - b).abs() < 1e-3);
    }
}
