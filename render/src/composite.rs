//! Putting the relit subject into a scene (docs/design.md section 4.4): a backdrop seen by
//! the virtual camera, its ground (the plane `y = 0` of the subject frame) darkened by the
//! subject's relative irradiance ([`crate::shadow`]), and the premultiplied subject over
//! it with the Porter–Duff *over* operator:
//!
//! `composite = subject + (1 − α_subject) · (backdrop ⊙ S)`
//!
//! Backdrops ([`Backdrop`]):
//! - **environment**: the HDR environment itself; rays that meet the ground show either
//!   the environment's lower hemisphere in their direction (a probe's own ground, seen
//!   from afar) or a Lambertian ground of given albedo lit by the upper hemisphere;
//! - **plate**: a photograph taken by the virtual camera (same size), its ground at
//!   `y = 0`;
//! - **none**: nothing; the shadow becomes a black layer of alpha `1 − lum(S)`, so that
//!   the composite, a transparent image, darkens whatever it is later put over.
//!
//! Layers for compositing tools ([`Layers`]): the composite, the relative irradiance `S`
//! per pixel (1 where the ray misses the ground), and the backdrop without shadow. This
//! is the CPU reference; `shaders/composite.wgsl` computes the same on the GPU.

use frf_core::camera::Camera;
use frf_core::env::EnvMap;
use frf_core::image::{Image, Rgb, RgbImage, Rgba, luminance};
use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::error::{RenderError, Result};
use crate::shadow::ground_hit;

/// What the ground of an environment backdrop looks like.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GroundLook {
    /// The environment's lower hemisphere in the ray's direction.
    Environment,
    /// A Lambertian ground of this albedo lit by the environment's upper hemisphere.
    Albedo(Rgb),
}

/// What the subject is put over.
#[derive(Debug, Clone)]
pub enum Backdrop {
    /// Nothing (transparent); the shadow as a black layer.
    None,
    /// The environment (subject frame, its yaw applied) and its ground.
    Environment {
        /// The environment.
        env: EnvMap,
        /// The ground's look.
        ground: GroundLook,
        /// Radiance of the Lambertian ground (for [`GroundLook::Albedo`]).
        ground_radiance: Rgb,
    },
    /// A photograph taken by the virtual camera, linear RGB.
    Plate(RgbImage),
}

impl Backdrop {
    /// The environment backdrop.
    pub fn environment(env: EnvMap, ground: GroundLook) -> Self {
        let ground_radiance = match ground {
            GroundLook::Albedo(a) => env.lambertian_ground(a),
            GroundLook::Environment => [0.0; 3],
        };
        Backdrop::Environment {
            env,
            ground,
            ground_radiance,
        }
    }

    /// Checks that the backdrop suits frames of `camera`'s size.
    pub fn check(&self, camera: &Camera) -> Result<()> {
        if let Backdrop::Plate(p) = self
            && (p.width() as u32, p.height() as u32) != (camera.width, camera.height)
        {
            return Err(RenderError::Mismatch {
                what: "the plate (a plate is seen by its own camera)".into(),
                expected: format!("the camera's {}x{}", camera.width, camera.height),
                got: format!("{}x{}", p.width(), p.height()),
            });
        }
        Ok(())
    }

    /// The backdrop seen through pixel `(x, y)` along `dir`, and whether the ray meets
    /// the ground there; premultiplied RGBA.
    pub fn at(&self, x: usize, y: usize, dir: Vec3, hits_ground: bool) -> Rgba {
        match self {
            Backdrop::None => [0.0; 4],
            Backdrop::Environment {
                env,
                ground,
                ground_radiance,
            } => {
                let c = match (hits_ground, ground) {
                    (true, GroundLook::Albedo(_)) => *ground_radiance,
                    _ => env.radiance(dir),
                };
                [c[0], c[1], c[2], 1.0]
            }
            Backdrop::Plate(img) => {
                let c = img.get(x, y);
                [c[0], c[1], c[2], 1.0]
            }
        }
    }
}

/// The layers of a composited frame, for compositing tools.
#[derive(Debug, Clone)]
pub struct Layers {
    /// The subject alone (premultiplied linear RGBA).
    pub subject: Image<Rgba>,
    /// Relative irradiance of the ground seen through each pixel (1 off the ground).
    pub shadow: RgbImage,
    /// The backdrop without shadow (premultiplied RGBA).
    pub backdrop: Image<Rgba>,
}

/// One pixel of the composite from the subject, the backdrop and the relative irradiance
/// `s` of the ground seen there (`[1; 3]` off the ground).
pub fn over(subject: Rgba, backdrop: Rgba, s: Rgb, transparent: bool) -> Rgba {
    let under = if transparent {
        // A black layer whose alpha is the light the shadow takes away.
        [0.0, 0.0, 0.0, (1.0 - luminance(s)).clamp(0.0, 1.0)]
    } else {
        [
            backdrop[0] * s[0],
            backdrop[1] * s[1],
            backdrop[2] * s[2],
            backdrop[3],
        ]
    };
    let k = 1.0 - subject[3].clamp(0.0, 1.0);
    [0, 1, 2, 3].map(|c| subject[c] + k * under[c])
}

/// The order to draw walkers standing at `positions` (world frame) in, back to front:
/// farthest from the camera first, so that each goes over the ones behind it.
pub fn back_to_front(camera: &Camera, positions: &[Vec3]) -> Vec<usize> {
    let c = camera.centre();
    let mut order: Vec<usize> = (0..positions.len()).collect();
    order.sort_by(|&a, &b| {
        (positions[b] - c)
            .length_squared()
            .total_cmp(&(positions[a] - c).length_squared())
            .then(a.cmp(&b))
    });
    order
}

/// Walkers rendered one by one (back to front), each put over the ones before it.
pub fn stack(layers: Vec<Image<Rgba>>) -> Result<Image<Rgba>> {
    let mut layers = layers.into_iter();
    let Some(mut out) = layers.next() else {
        return Err(RenderError::Misuse("no walker to stack".into()));
    };
    for layer in layers {
        if layer.size() != out.size() {
            return Err(RenderError::Misuse(
                "walker layers of different sizes".into(),
            ));
        }
        for (o, l) in out.pixels_mut().iter_mut().zip(layer.pixels()) {
            *o = over(*l, *o, [1.0; 3], false);
        }
    }
    Ok(out)
}

/// The most walkers a pixel orders by depth ([`stack_by_depth`]; `MAX_OVERLAP` in
/// `shaders/composite.wgsl`): a pixel where more overlap puts the farthest in the
/// frame's back-to-front order first, under the rest. A crowd of 400 at 640x360 met at
/// most 9 at a pixel.
pub const MAX_OVERLAP: usize = 16;

/// Walkers rendered one by one, each with its depth at every pixel, listed back to front
/// by their positions ([`back_to_front`]): at each pixel, those that cover it
/// (alpha above 0) put over each other farthest first by their depth there, ties in the
/// listed order, so that walkers that pass each other cross where their bodies do. At
/// most [`MAX_OVERLAP`] are ordered at a pixel; those listed before them go under, in
/// the listed order.
pub fn stack_by_depth(layers: Vec<(Image<Rgba>, Image<f32>)>) -> Result<Image<Rgba>> {
    let Some((first, _)) = layers.first() else {
        return Err(RenderError::Misuse("no walker to stack".into()));
    };
    let size = first.size();
    if layers
        .iter()
        .any(|(c, d)| c.size() != size || d.size() != size)
    {
        return Err(RenderError::Misuse(
            "walker layers of different sizes".into(),
        ));
    }
    let (w, h) = size;
    let pixels: Vec<Rgba> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let covering: Vec<(f32, usize)> = layers
                .iter()
                .enumerate()
                .filter(|(_, (c, _))| c.get(x, y)[3] > 0.0)
                .map(|(k, (_, d))| (d.get(x, y), k))
                .collect();
            let cut = covering.len().saturating_sub(MAX_OVERLAP);
            let (under, sorted) = covering.split_at(cut);
            let mut sorted = sorted.to_vec();
            sorted.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
            under.iter().chain(&sorted).fold([0.0; 4], |acc, &(_, k)| {
                over(layers[k].0.get(x, y), acc, [1.0; 3], false)
            })
        })
        .collect();
    Ok(Image::from_vec(w, h, pixels)?)
}

/// Composites `subject` (rendered by `camera`) over `backdrop`, its ground darkened by
/// `shadow(ground point)` (see the module docs): the composite and its layers.
pub fn compose(
    subject: Image<Rgba>,
    camera: &Camera,
    backdrop: &Backdrop,
    shadow: &(dyn Fn(Vec3) -> Rgb + Sync),
) -> Result<(Image<Rgba>, Layers)> {
    backdrop.check(camera)?;
    let (w, h) = subject.size();
    if (w as u32, h as u32) != (camera.width, camera.height) {
        return Err(RenderError::Misuse(format!(
            "a {w}x{h} subject for a {}x{} camera",
            camera.width, camera.height
        )));
    }
    let transparent = matches!(backdrop, Backdrop::None);
    let centre = camera.centre();
    let rows: Vec<Vec<(Rgba, Rgb, Rgba)>> = (0..h)
        .into_par_iter()
        .map(|y| {
            (0..w)
                .map(|x| {
                    let dir = camera.ray_direction(Vec2::new(x as f32, y as f32));
                    let hit = ground_hit(centre, dir);
                    let s = hit.map_or([1.0; 3], shadow);
                    let b = backdrop.at(x, y, dir, hit.is_some());
                    (over(subject.get(x, y), b, s, transparent), s, b)
                })
                .collect()
        })
        .collect();
    let mut composite = Vec::with_capacity(w * h);
    let mut shadow_layer = Vec::with_capacity(w * h);
    let mut backdrop_layer = Vec::with_capacity(w * h);
    for (c, s, b) in rows.into_iter().flatten() {
        composite.push(c);
        shadow_layer.push(s);
        backdrop_layer.push(b);
    }
    Ok((
        Image::from_vec(w, h, composite)?,
        Layers {
            subject,
            shadow: Image::from_vec(w, h, shadow_layer)?,
            backdrop: Image::from_vec(w, h, backdrop_layer)?,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera::look_at(
            Vec3::new(0.0, 1.5, 4.0),
            Vec3::new(0.0, 0.8, 0.0),
            Vec3::Y,
            0.8,
            40,
            30,
        )
        .unwrap()
    }

    #[test]
    fn over_is_porter_duff_and_the_shadow_darkens_only_the_backdrop() {
        let subject = [0.2, 0.1, 0.0, 0.5];
        let back = [1.0, 1.0, 1.0, 1.0];
        let c = over(subject, back, [0.5, 0.5, 0.5], false);
        assert_eq!(c, [0.45, 0.35, 0.25, 1.0]);
        // An opaque subject hides the shadow; none at all leaves the backdrop.
        assert_eq!(
            over([0.3, 0.3, 0.3, 1.0], back, [0.0; 3], false),
            [0.3, 0.3, 0.3, 1.0]
        );
        assert_eq!(over([0.0; 4], back, [1.0; 3], false), back);
        // Transparent: the shadow is black of alpha 1 − S.
        let t = over([0.0; 4], [0.0; 4], [0.25; 3], true);
        assert!((t[3] - 0.75).abs() < 1e-6 && t[0] == 0.0);
    }

    #[test]
    fn an_environment_backdrop_shows_sky_above_and_a_shadowed_ground_below() {
        let cam = camera();
        let env = EnvMap::uniform([2.0, 2.0, 2.0], 16);
        let subject = Image::new(40, 30, [0.0f32; 4]);
        // Shadow: relative irradiance 0.25 within 0.5 m of the origin.
        let shadow = |p: Vec3| {
            if p.length() < 0.5 {
                [0.25; 3]
            } else {
                [1.0; 3]
            }
        };
        let (c, l) = compose(
            subject.clone(),
            &cam,
            &Backdrop::environment(env.clone(), GroundLook::Environment),
            &shadow,
        )
        .unwrap();
        // The top row sees sky (radiance 2), the bottom row ground.
        assert_eq!(l.shadow.get(20, 0), [1.0; 3]);
        assert!((c.get(20, 0)[0] - 2.0).abs() < 1e-5);
        // Some pixel sees the shadowed patch: 2 x 0.25.
        assert!(c.pixels().iter().any(|p| (p[0] - 0.5).abs() < 1e-5));
        // A Lambertian ground of albedo 1 under a uniform sky of radiance 2 has radiance 2.
        let (_, l) = compose(
            subject,
            &cam,
            &Backdrop::environment(env, GroundLook::Albedo([1.0; 3])),
            &shadow,
        )
        .unwrap();
        let ground: Vec<&Rgba> = l
            .backdrop
            .pixels()
            .iter()
            .zip(l.shadow.pixels())
            .filter(|(_, s)| **s == [1.0; 3])
            .map(|(b, _)| b)
            .collect();
        assert!(
            ground.iter().all(|b| (b[0] - 2.0).abs() < 0.02),
            "{:?}",
            ground[0]
        );
    }

    #[test]
    fn walkers_cross_where_their_depths_do() {
        // Two opaque walkers over the same 2x1 pixels: red nearer at the left pixel, blue
        // nearer at the right one (two bodies passing each other).
        let red = Image::from_vec(2, 1, vec![[1.0, 0.0, 0.0, 1.0]; 2]).unwrap();
        let blue = Image::from_vec(2, 1, vec![[0.0, 0.0, 1.0, 1.0]; 2]).unwrap();
        let red_depth = Image::from_vec(2, 1, vec![2.0f32, 4.0]).unwrap();
        let blue_depth = Image::from_vec(2, 1, vec![3.0f32, 3.0]).unwrap();
        let out = stack_by_depth(vec![(red, red_depth), (blue, blue_depth)]).unwrap();
        assert_eq!(out.get(0, 0), [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(out.get(1, 0), [0.0, 0.0, 1.0, 1.0]);
        // Half-covering layers keep Porter–Duff over in depth order.
        let a = Image::from_vec(1, 1, vec![[0.5, 0.0, 0.0, 0.5]]).unwrap();
        let b = Image::from_vec(1, 1, vec![[0.0, 0.5, 0.0, 0.5]]).unwrap();
        let near = Image::from_vec(1, 1, vec![1.0f32]).unwrap();
        let far = Image::from_vec(1, 1, vec![5.0f32]).unwrap();
        let out = stack_by_depth(vec![(a, near), (b, far)]).unwrap();
        assert_eq!(out.get(0, 0), [0.5, 0.25, 0.0, 0.75]);
    }

    #[test]
    fn a_plate_must_match_its_camera() {
        let cam = camera();
        let subject = Image::new(40, 30, [0.0f32; 4]);
        let bad = Backdrop::Plate(Image::new(20, 30, [0.5f32; 3]));
        let e = compose(subject.clone(), &cam, &bad, &|_| [1.0; 3])
            .unwrap_err()
            .to_string();
        assert!(e.contains("20x30") && e.contains("40x30"), "{e}");
        let good = Backdrop::Plate(Image::from_fn(40, 30, |x, _| [x as f32 / 40.0; 3]));
        let (c, _) = compose(subject, &cam, &good, &|_| [1.0; 3]).unwrap();
        assert_eq!(c.get(10, 5), [0.25, 0.25, 0.25, 1.0]);
    }
}
