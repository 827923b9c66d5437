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

/// The albedo-independent part of the actor's shading at a hit: radiance toward the eye
/// is `albedo ⊙ diffuse + specular`. `pixel_angle` is the angle one pixel subtends
/// (radians), which with the distance gives the pixel's footprint on the surface.
struct ActorShading {
    diffuse: Rgb,
    specular: Rgb,
}

fn actor_footprint(hit: &ActorHit, pixel_angle: f32) -> f32 {
    hit.t * pixel_angle
}

fn actor_albedo(hit: &ActorHit, pixel_angle: f32) -> Rgb {
    let footprint = actor_footprint(hit, pixel_angle);
    hit.part
        .material()
        .surface(hit.local, hit.part as u64 + 1, footprint)
        .albedo
}

fn shade_actor(
    scene: &Scene,
    actor: &Actor,
    ray: &Ray,
    hit: &ActorHit,
    pixel_angle: f32,
) -> ActorShading {
    let view = -ray.dir;
    // Silhouette hits can have the normal barely facing away through rounding.
    let n = if hit.normal.dot(view) < 0.0 {
        (hit.normal - view * 2.0 * hit.normal.dot(view)).normalize()
    } else {
        hit.normal
    };
    let surface = hit.part.material().surface(
        hit.local,
        hit.part as u64 + 1,
        actor_footprint(hit, pixel_angle),
    );
    let p = ray.origin + ray.dir * hit.t;
    let mut out = ActorShading {
        diffuse: [0.0; 3],
        specular: [0.0; 3],
    };
    let mut add = |light: &DirLight, l: Vec3| {
        let (d, s) = brdf::terms(&surface, n, l, view);
        add_scaled(&mut out.diffuse, light.irradiance, d);
        add_scaled(&mut out.specular, light.irradiance, s);
    };
    match scene.illumination {
        Illumination::Lights(lights) => {
            for light in lights {
                if n.dot(light.direction) > 0.0 && lit(Some(actor), p, n, light) {
                    add(light, light.direction);
                }
            }
        }
        // The ring light sits on the lens: light arrives along the view direction.
        Illumination::Matte { ring } => add(ring, view),
        Illumination::Dark => {}
    }
    out
}

fn combine(albedo: Rgb, shading: &ActorShading) -> Rgb {
    [0, 1, 2].map(|c| albedo[c] * shading.diffuse[c] + shading.specular[c])
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

/// What a primary ray sees first.
#[derive(Debug, Clone, Copy)]
enum Visible {
    Actor(ActorHit),
    Studio(StudioHit),
    Nothing,
}

impl Visible {
    /// Whether two rays see the same smooth surface (one body part, the floor, the
    /// backdrop or nothing), so that shading one stands for both.
    fn same_surface(&self, other: &Visible) -> bool {
        match (self, other) {
            (Visible::Actor(a), Visible::Actor(b)) => a.part == b.part,
            (Visible::Studio(StudioHit::Floor(_)), Visible::Studio(StudioHit::Floor(_)))
            | (Visible::Studio(StudioHit::Backdrop(_)), Visible::Studio(StudioHit::Backdrop(_)))
            | (Visible::Nothing, Visible::Nothing) => true,
            _ => false,
        }
    }

    fn surface_point(&self) -> Option<SurfacePoint> {
        match self {
            Visible::Actor(hit) => Some(SurfacePoint {
                part: hit.part,
                local: hit.local,
            }),
            _ => None,
        }
    }
}

fn visibility(scene: &Scene, ray: &Ray) -> Visible {
    if let Some(hit) = scene
        .actor
        .and_then(|a| a.intersect(ray, 0.0, f32::INFINITY))
    {
        return Visible::Actor(hit);
    }
    if scene.studio
        && let Some((_, hit)) = studio::intersect(ray)
    {
        return Visible::Studio(hit);
    }
    Visible::Nothing
}

fn shade(scene: &Scene, ray: &Ray, visible: &Visible, pixel_angle: f32) -> Rgb {
    match (visible, scene.actor) {
        (Visible::Actor(hit), Some(actor)) => combine(
            actor_albedo(hit, pixel_angle),
            &shade_actor(scene, actor, ray, hit, pixel_angle),
        ),
        (Visible::Studio(hit), _) => shade_studio(scene, ray, hit),
        _ => [0.0; 3],
    }
}

/// Renders `scene` through `camera` with `samples_per_axis²` samples per pixel.
///
/// Visibility and texture are sampled at every sub-sample; lighting, the expensive part
/// (a shadow ray per light), is computed once at the pixel centre when every sub-sample
/// sees the same smooth surface as the centre, and applied to the sub-samples' mean
/// albedo, as multisample anti-aliasing does; at silhouettes and between surfaces every
/// sub-sample is lit on its own. Lighting varies slowly within one surface; texture
/// does not, hence its full sampling.
pub fn render(camera: &Camera, scene: &Scene, samples_per_axis: u32) -> Rendered {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let n = samples_per_axis.max(1);
    let inv = 1.0 / (n * n) as f32;
    let pixel_angle = 1.0 / camera.intrinsics.fx.min(camera.intrinsics.fy);
    let ray_through = |pixel: Vec2| Ray {
        origin: camera.centre(),
        dir: camera.ray_direction(pixel),
    };
    let rows: Vec<Vec<(Rgb, f32, Option<SurfacePoint>)>> = (0..h)
        .into_par_iter()
        .map(|y| {
            let mut samples = Vec::with_capacity((n * n) as usize);
            (0..w)
                .map(|x| {
                    let centre = Vec2::new(x as f32, y as f32);
                    let centre_ray = ray_through(centre);
                    let centre_visible = visibility(scene, &centre_ray);
                    samples.clear();
                    for sy in 0..n {
                        for sx in 0..n {
                            let offset = Vec2::new(
                                (sx as f32 + 0.5) / n as f32 - 0.5,
                                (sy as f32 + 0.5) / n as f32 - 0.5,
                            );
                            let ray = ray_through(centre + offset);
                            samples.push((offset, ray, visibility(scene, &ray)));
                        }
                    }
                    let covered = samples
                        .iter()
                        .filter(|s| matches!(s.2, Visible::Actor(_)))
                        .count();
                    let uniform = samples.iter().all(|s| s.2.same_surface(&centre_visible));
                    let color = if uniform {
                        match (&centre_visible, scene.actor) {
                            (Visible::Actor(hit), Some(actor)) => {
                                let mut albedo = [0.0; 3];
                                for (_, _, v) in &samples {
                                    if let Visible::Actor(h) = v {
                                        add_scaled(&mut albedo, actor_albedo(h, pixel_angle), inv);
                                    }
                                }
                                combine(
                                    albedo,
                                    &shade_actor(scene, actor, &centre_ray, hit, pixel_angle),
                                )
                            }
                            _ => shade(scene, &centre_ray, &centre_visible, pixel_angle),
                        }
                    } else {
                        let mut color = [0.0; 3];
                        for (_, ray, visible) in &samples {
                            add_scaled(&mut color, shade(scene, ray, visible, pixel_angle), inv);
                        }
                        color
                    };
                    // The surface point through the centre, or at the silhouette the
                    // covered sub-sample nearest to it.
                    let surface = centre_visible.surface_point().or_else(|| {
                        samples
                            .iter()
                            .filter(|s| matches!(s.2, Visible::Actor(_)))
                            .min_by(|a, b| a.0.length_squared().total_cmp(&b.0.length_squared()))
                            .and_then(|s| s.2.surface_point())
                    });
                    (color, covered as f32 * inv, surface)
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
