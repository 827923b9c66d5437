//! The stage's ray tracer: one image of the actor and (optionally) the studio from a
//! pinhole camera under an [`Illumination`], with `n x n` supersampling per pixel (a box
//! filter over the pixel, like a sensor's fill factor of 1) followed by the lens's
//! point-spread function ([`crate::optics`]), direct lighting with shadow
//! rays (self-shadowing, and the actor's shadow on floor and backdrop), and, per pixel,
//! the subject's coverage (the true alpha) and the surface point seen through the pixel
//! centre (from which true optical flow is computed). [`render_crowd`] does the same for
//! several actors without the studio, each under its own light, the nearest seen and
//! each shadowing the others, with each one's coverage.

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

/// One actor of a crowd, placed in the world frame, and the light that shades it
/// ([`render_crowd`]).
#[derive(Debug, Clone, Copy)]
pub struct Lit<'a> {
    /// The actor, world frame.
    pub actor: &'a Actor,
    /// The lights that shade this actor (every actor shadows every other).
    pub illumination: &'a Illumination,
}

/// What [`render_crowd`] produces.
#[derive(Debug, Clone)]
pub struct CrowdRendered {
    /// Linear radiance, premultiplied on black, averaged over the pixel.
    pub color: RgbImage,
    /// Fraction of the pixel covered by any actor.
    pub alpha: GrayImage,
    /// Per actor, in the order given, the fraction of the pixel's sub-samples whose
    /// nearest hit is that actor; they sum to `alpha` (to rounding; each went through the
    /// same lens blur).
    pub coverage: Vec<GrayImage>,
}

/// The actors and studio one image shows, and how each is lit.
struct World<'a> {
    /// Each actor (world frame) with the light that shades it.
    actors: Vec<Lit<'a>>,
    /// The light of floor and backdrop, when they are present.
    studio: Option<&'a Illumination>,
}

impl<'a> World<'a> {
    fn of_scene(scene: &Scene<'a>) -> Self {
        Self {
            actors: scene
                .actor
                .map(|actor| Lit {
                    actor,
                    illumination: scene.illumination,
                })
                .into_iter()
                .collect(),
            studio: scene.studio.then_some(scene.illumination),
        }
    }
}

/// Offset of shadow-ray origins along the normal, metres: far above f32 rounding at
/// stage scale (~1e-7 m), far below any feature (~1 cm).
const SHADOW_BIAS_M: f32 = 2e-4;

fn add_scaled(acc: &mut Rgb, c: Rgb, k: f32) {
    for i in 0..3 {
        acc[i] += c[i] * k;
    }
}

/// Whether `light` reaches `point` past every actor of `world`.
fn lit(world: &World, point: Vec3, normal: Vec3, light: &DirLight) -> bool {
    if world.actors.is_empty() {
        return true;
    }
    let ray = Ray {
        origin: point + normal * SHADOW_BIAS_M,
        dir: light.direction,
    };
    !world
        .actors
        .iter()
        .any(|a| a.actor.occludes(&ray, 0.0, f32::INFINITY))
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
    world: &World,
    which: usize,
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
    match world.actors[which].illumination {
        Illumination::Lights(lights) => {
            for light in lights {
                if n.dot(light.direction) > 0.0 && lit(world, p, n, light) {
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

fn shade_studio(world: &World, ray: &Ray, hit: &StudioHit) -> Rgb {
    let view = -ray.dir;
    let Some(illumination) = world.studio else {
        return [0.0; 3];
    };
    match illumination {
        Illumination::Lights(lights) => {
            let mut out = [0.0; 3];
            let normal = match hit {
                StudioHit::Floor(_) => Vec3::Y,
                StudioHit::Backdrop(_) => Vec3::Z,
            };
            for light in lights {
                if normal.dot(light.direction) <= 0.0 || !lit(world, hit.point(), normal, light) {
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
    /// Actor `.0` of the world.
    Actor(usize, ActorHit),
    Studio(StudioHit),
    Nothing,
}

impl Visible {
    /// Whether two rays see the same smooth surface (one body part of one actor, the
    /// floor, the backdrop or nothing), so that shading one stands for both.
    fn same_surface(&self, other: &Visible) -> bool {
        match (self, other) {
            (Visible::Actor(i, a), Visible::Actor(j, b)) => i == j && a.part == b.part,
            (Visible::Studio(StudioHit::Floor(_)), Visible::Studio(StudioHit::Floor(_)))
            | (Visible::Studio(StudioHit::Backdrop(_)), Visible::Studio(StudioHit::Backdrop(_)))
            | (Visible::Nothing, Visible::Nothing) => true,
            _ => false,
        }
    }

    fn surface_point(&self) -> Option<SurfacePoint> {
        match self {
            Visible::Actor(_, hit) => Some(SurfacePoint {
                part: hit.part,
                local: hit.local,
            }),
            _ => None,
        }
    }
}

/// The nearest actor hit along `ray`, else the studio, else nothing.
fn visibility(world: &World, ray: &Ray) -> Visible {
    let mut nearest: Option<(usize, ActorHit)> = None;
    for (i, a) in world.actors.iter().enumerate() {
        let limit = nearest.map_or(f32::INFINITY, |(_, h)| h.t);
        if let Some(hit) = a.actor.intersect(ray, 0.0, limit) {
            nearest = Some((i, hit));
        }
    }
    if let Some((i, hit)) = nearest {
        return Visible::Actor(i, hit);
    }
    if world.studio.is_some()
        && let Some((_, hit)) = studio::intersect(ray)
    {
        return Visible::Studio(hit);
    }
    Visible::Nothing
}

fn shade(world: &World, ray: &Ray, visible: &Visible, pixel_angle: f32) -> Rgb {
    match visible {
        Visible::Actor(which, hit) => combine(
            actor_albedo(hit, pixel_angle),
            &shade_actor(world, *which, ray, hit, pixel_angle),
        ),
        Visible::Studio(hit) => shade_studio(world, ray, hit),
        Visible::Nothing => [0.0; 3],
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
    let traced = trace(camera, &World::of_scene(scene), samples_per_axis);
    let sigma = crate::optics::PSF_SIGMA_PX;
    Rendered {
        color: crate::optics::blur(&traced.color, sigma),
        alpha: crate::optics::blur(&traced.alpha, sigma),
        surface: traced.surface,
    }
}

/// Renders several actors (world frame) through `camera`, without studio, each shaded
/// by its own illumination, with the nearest hit among them seen and every actor
/// shadowing every other; sampled and blurred as [`render`] does. A crowd of one is
/// exactly [`render`] of that actor without studio.
pub fn render_crowd(camera: &Camera, actors: &[Lit], samples_per_axis: u32) -> CrowdRendered {
    let world = World {
        actors: actors.to_vec(),
        studio: None,
    };
    let traced = trace(camera, &world, samples_per_axis);
    let sigma = crate::optics::PSF_SIGMA_PX;
    CrowdRendered {
        color: crate::optics::blur(&traced.color, sigma),
        alpha: crate::optics::blur(&traced.alpha, sigma),
        coverage: traced
            .coverage
            .iter()
            .map(|c| crate::optics::blur(c, sigma))
            .collect(),
    }
}

/// What [`trace`] produces, before the lens's blur.
struct Traced {
    color: RgbImage,
    alpha: GrayImage,
    /// Per actor, the fraction of sub-samples that see it.
    coverage: Vec<GrayImage>,
    surface: Image<Option<SurfacePoint>>,
}

/// One traced row: colour, per pixel and actor the sub-samples that see it (pixel-major),
/// and the surface points.
type Row = (Vec<Rgb>, Vec<u32>, Vec<Option<SurfacePoint>>);

/// The ray tracing of [`render`] and [`render_crowd`] (see [`render`]).
fn trace(camera: &Camera, world: &World, samples_per_axis: u32) -> Traced {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let k = world.actors.len();
    let n = samples_per_axis.max(1);
    let inv = 1.0 / (n * n) as f32;
    let pixel_angle = 1.0 / camera.intrinsics.fx.min(camera.intrinsics.fy);
    let ray_through = |pixel: Vec2| Ray {
        origin: camera.centre(),
        dir: camera.ray_direction(pixel),
    };
    let rows: Vec<Row> = (0..h)
        .into_par_iter()
        .map(|y| {
            let mut samples = Vec::with_capacity((n * n) as usize);
            let mut colors = Vec::with_capacity(w);
            let mut counts = vec![0u32; w * k];
            let mut surfaces = Vec::with_capacity(w);
            for x in 0..w {
                let centre = Vec2::new(x as f32, y as f32);
                let centre_ray = ray_through(centre);
                let centre_visible = visibility(world, &centre_ray);
                samples.clear();
                for sy in 0..n {
                    for sx in 0..n {
                        let offset = Vec2::new(
                            (sx as f32 + 0.5) / n as f32 - 0.5,
                            (sy as f32 + 0.5) / n as f32 - 0.5,
                        );
                        let ray = ray_through(centre + offset);
                        samples.push((offset, ray, visibility(world, &ray)));
                    }
                }
                for s in &samples {
                    if let Visible::Actor(i, _) = s.2 {
                        counts[x * k + i] += 1;
                    }
                }
                let uniform = samples.iter().all(|s| s.2.same_surface(&centre_visible));
                let color = if uniform {
                    match &centre_visible {
                        Visible::Actor(which, hit) => {
                            let mut albedo = [0.0; 3];
                            for (_, _, v) in &samples {
                                if let Visible::Actor(_, h) = v {
                                    add_scaled(&mut albedo, actor_albedo(h, pixel_angle), inv);
                                }
                            }
                            combine(
                                albedo,
                                &shade_actor(world, *which, &centre_ray, hit, pixel_angle),
                            )
                        }
                        _ => shade(world, &centre_ray, &centre_visible, pixel_angle),
                    }
                } else {
                    let mut color = [0.0; 3];
                    for (_, ray, visible) in &samples {
                        add_scaled(&mut color, shade(world, ray, visible, pixel_angle), inv);
                    }
                    color
                };
                // The surface point through the centre, or at the silhouette the
                // covered sub-sample nearest to it.
                let surface = centre_visible.surface_point().or_else(|| {
                    samples
                        .iter()
                        .filter(|s| matches!(s.2, Visible::Actor(..)))
                        .min_by(|a, b| a.0.length_squared().total_cmp(&b.0.length_squared()))
                        .and_then(|s| s.2.surface_point())
                });
                colors.push(color);
                surfaces.push(surface);
            }
            (colors, counts, surfaces)
        })
        .collect();
    let mut color = Vec::with_capacity(w * h);
    let mut alpha = Vec::with_capacity(w * h);
    let mut coverage = vec![Vec::with_capacity(w * h); k];
    let mut surface = Vec::with_capacity(w * h);
    for (colors, counts, surfaces) in rows {
        color.extend(colors);
        surface.extend(surfaces);
        for x in 0..w {
            let pixel = &counts[x * k..(x + 1) * k];
            alpha.push(pixel.iter().sum::<u32>() as f32 * inv);
            for (c, &m) in coverage.iter_mut().zip(pixel) {
                c.push(m as f32 * inv);
            }
        }
    }
    Traced {
        color: image(w, h, color),
        alpha: image(w, h, alpha),
        coverage: coverage.into_iter().map(|c| image(w, h, c)).collect(),
        surface: image(w, h, surface),
    }
}

fn image<P: Copy>(w: usize, h: usize, pixels: Vec<P>) -> Image<P> {
    Image::from_vec(w, h, pixels).expect("w*h pixels by construction")
}
