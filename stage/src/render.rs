//! The stage's ray tracer: one image of the actor and (optionally) the studio from a
//! pinhole camera under an [`Illumination`], with `n x n` supersampling per pixel (a box
//! filter over the pixel, like a sensor's fill factor of 1) followed by the lens's
//! point-spread function ([`crate::optics`]), direct lighting with shadow
//! rays (self-shadowing, and the actor's shadow on floor and backdrop), and, per pixel,
//! the subject's coverage (the true alpha) and the surface point seen through the pixel
//! centre (from which true optical flow is computed).

use frf_core::camera::Camera;
use frf_core::image::{GrayImage, Image, Rgb, RgbImage};
use frf_core::light::DirLight;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::actor::{Actor, ActorHit, Part};
use crate::brdf;
use crate::geometry::Ray;
use crate::studio::{self, Illumination, StudioHit};

/// A point on the actor's surface, in its part's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// The part.
    pub part: Part,
    /// Coordinates in the part's frame, metres.
    pub local: Vec3,
}

/// What [`render`] produces.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// Linear radiance, averaged over the pixel. Without studio it is premultiplied on black.
    pub color: RgbImage,
    /// Fraction of the pixel covered by the actor.
    pub alpha: GrayImage,
    /// The actor's surface point through the pixel centre (or, at the silhouette, through
    /// the covered sub-sample nearest to it); `None` where the pixel misses the actor.
    pub surface: Image<Option<SurfacePoint>>,
}

/// What to render.
#[derive(Debug, Clone, Copy)]
pub struct Scene<'a> {
    /// The actor (already placed in the world frame), if any.
    pub actor: Option<&'a Actor>,
    /// Whether the floor and backdrop are present.
    pub studio: bool,
    /// The lighting.
    pub illumination: &'a Illumination,
}

/// Offset of shadow-ray origins along the normal, metres: far above f32 rounding at
/// stage scale (~1e-7 m), far below any feature (~1 cm).
const SHADOW_BIAS_M: f32 = 2e-4;

fn add_scaled(acc: &mut Rgb, c: Rgb, k: f32) {
    for i in 0..3 {
        acc[i] += c[i] * k;
    }
}

fn lit(actor: Option<&Actor>, point: Vec3, normal: Vec3, light: &DirLight) -> bool {
    let Some(actor) = actor else { return true };
    let ray = Ray {
        origin: point + normal * SHADOW_BIAS_M,
        dir: light.direction,
    };
    !actor.occludes(&ray, 0.0, f32::INFINITY)
}

/// Radiance of the actor at a hit, toward the eye; `pixel_angle` is the angle one pixel
/// subtends (radians), which with the distance gives the pixel's footprint on the surface.
fn shade_actor(scene: &Scene, actor: &Actor, ray: &Ray, hit: &ActorHit, pixel_angle: f32) -> Rgb {
    let view = -ray.dir;
    // Silhouette hits can have the normal barely facing away through rounding.
    let n = if hit.normal.dot(view) < 0.0 {
        (hit.normal - view * 2.0 * hit.normal.dot(view)).normalize()
    } else {
        hit.normal
    };
    // The pixel's footprint on the surface at that distance.
    let footprint = hit.t * pixel_angle;
    let surface = hit
        .part
        .material()
        .surface(hit.local, hit.part as u64 + 1, footprint);
    let p = ray.origin + ray.dir * hit.t;
    let mut out = [0.0; 3];
    match scene.illumination {
        Illumination::Lights(lights) => {
            for light in lights {
                if n.dot(light.direction) <= 0.0 || !lit(Some(actor), p, n, light) {
                    continue;
                }
                let f = brdf::reflect(&surface, n, light.direction, view);
                for c in 0..3 {
                    out[c] += f[c] * light.irradiance[c];
                }
            }
        }
        Illumination::Matte { ring } => {
            // The ring light sits on the lens: light arrives along the view direction.
            let f = brdf::reflect(&surface, n, view, view);
            for c in 0..3 {
                out[c] += f[c] * ring.irradiance[c];
            }
        }
        Illumination::Dark => {}
    }
    out
}

fn shade_studio(scene: &Scene, ray: &Ray, hit: &StudioHit) -> Rgb {
    let view = -ray.dir;
    match scene.illumination {
        Illumination::Lights(lights) => {
            let mut out = [0.0; 3];
            let normal = match hit {
                StudioHit::Floor(_) => Vec3::Y,
                StudioHit::Backdrop(_) => Vec3::Z,
            };
            for light in lights {
                if normal.dot(light.direction) <= 0.0
                    || !lit(scene.actor, hit.point(), normal, light)
                {
                    continue;
                }
                add_scaled(&mut out, studio::reflect(hit, light, view), 1.0);
            }
            out
        }
        Illumination::Matte { ring } => studio::matte_radiance(hit, ring),
        Illumination::Dark => [0.0; 3],
    }
}

/// Traces one ray: radiance and whether it hit the actor (and where).
fn trace(scene: &Scene, ray: &Ray, pixel_angle: f32) -> (Rgb, Option<ActorHit>) {
    let actor_hit = scene
        .actor
        .and_then(|a| a.intersect(ray, 0.0, f32::INFINITY));
    if let (Some(actor), Some(hit)) = (scene.actor, actor_hit) {
        return (shade_actor(scene, actor, ray, &hit, pixel_angle), Some(hit));
    }
    if scene.studio
        && let Some((_, hit)) = studio::intersect(ray)
    {
        return (shade_studio(scene, ray, &hit), None);
    }
    ([0.0; 3], None)
}

/// Renders `scene` through `camera` with `samples_per_axis²` samples per pixel.
pub fn render(camera: &Camera, scene: &Scene, samples_per_axis: u32) -> Rendered {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let n = samples_per_axis.max(1);
    let inv = 1.0 / (n * n) as f32;
    let pixel_angle = 1.0 / camera.intrinsics.fx.min(camera.intrinsics.fy);
    let rows: Vec<Vec<(Rgb, f32, Option<SurfacePoint>)>> = (0..h)
        .into_par_iter()
        .map(|y| {
            (0..w)
                .map(|x| {
                    let mut color = [0.0; 3];
                    let mut covered = 0u32;
                    let mut nearest: Option<(f32, SurfacePoint)> = None;
                    for sy in 0..n {
                        for sx in 0..n {
                            let offset = Vec2::new(
                                (sx as f32 + 0.5) / n as f32 - 0.5,
                                (sy as f32 + 0.5) / n as f32 - 0.5,
                            );
                            let pixel = Vec2::new(x as f32, y as f32) + offset;
                            let ray = Ray {
                                origin: camera.centre(),
                                dir: camera.ray_direction(pixel),
                            };
                            let (c, hit) = trace(scene, &ray, pixel_angle);
                            add_scaled(&mut color, c, inv);
                            if let Some(hit) = hit {
                                covered += 1;
                                let d = offset.length_squared();
                                if nearest.is_none_or(|(best, _)| d < best) {
                                    nearest = Some((
                                        d,
                                        SurfacePoint {
                                            part: hit.part,
                                            local: hit.local,
                                        },
                                    ));
                                }
                            }
                        }
                    }
                    // Samples are symmetric about the centre for even n: trace the
                    // centre itself so the surface point is exactly the pixel's.
                    if covered > 0 && n % 2 == 0 {
                        let ray = Ray {
                            origin: camera.centre(),
                            dir: camera.ray_direction(Vec2::new(x as f32, y as f32)),
                        };
                        if let Some(hit) = scene
                            .actor
                            .and_then(|a| a.intersect(&ray, 0.0, f32::INFINITY))
                        {
                            nearest = Some((
                                0.0,
                                SurfacePoint {
                                    part: hit.part,
                                    local: hit.local,
                                },
                            ));
                        }
                    }
                    (color, covered as f32 * inv, nearest.map(|(_, s)| s))
                })
                .collect()
        })
        .collect();
    let mut color = Vec::with_capacity(w * h);
    let mut alpha = Vec::with_capacity(w * h);
    let mut surface = Vec::with_capacity(w * h);
    for (c, a, s) in rows.into_iter().flatten() {
        color.push(c);
        alpha.push(a);
        surface.push(s);
    }
    let sigma = crate::optics::PSF_SIGMA_PX;
    Rendered {
        color: crate::optics::blur(
            &Image::from_vec(w, h, color).expect("w*h pixels by construction"),
            sigma,
        ),
        alpha: crate::optics::blur(
            &Image::from_vec(w, h, alpha).expect("w*h pixels by construction"),
            sigma,
        ),
        surface: Image::from_vec(w, h, surface).expect("w*h pixels by construction"),
    }
}
