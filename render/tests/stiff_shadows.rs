//! Stiff and extreme cases of the shadow and compositing path, each asserting finite,
//! bounded and correct values: an empty hull, a light exactly at the horizon, a tiny sun
//! 10^5 times brighter than the sky, a body resting on the ground, and a subject partly
//! outside the ground patch of the maps.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use frf_core::camera::Camera;
use frf_core::env::EnvMap;
use frf_core::image::{Image, Rgb};
use frf_core::light::DirLight;
use frf_core::volume::{GroundGrid, VoxelGrid};
use frf_reflectance::field::{ConditionRecord, LightRecord};
use frf_reflectance::hull::VoxelHull;
use frf_reflectance::shadow::{attenuation_maps, ground_irradiance, shadow_spec};
use frf_render::composite::{Backdrop, GroundLook, compose};
use frf_render::shadow::{ShadowMaps, edge_fade, traced_shadow};
use glam::Vec3;

const GROUND: GroundGrid = GroundGrid {
    extent_m: 3.0,
    texels: 60,
};

fn condition(floor: bool, dirs: &[[f32; 3]]) -> ConditionRecord {
    ConditionRecord {
        name: "c".into(),
        floor,
        lights: dirs
            .iter()
            .map(|d| LightRecord {
                direction: Vec3::from(*d).normalize().to_array(),
                intensity: [1.0; 3],
                solid_angle_sr: 0.05,
            })
            .collect(),
    }
}

/// A box of voxels from `lo` to `hi`, every voxel occupied.
fn block(lo: Vec3, hi: Vec3) -> VoxelHull {
    VoxelHull::full(VoxelGrid::covering(lo, hi, 0.05).unwrap())
}

/// The maps of `hull` under `conditions`, relit with coefficients 1, as [`ShadowMaps`].
fn relit(hull: &VoxelHull, conditions: &[ConditionRecord]) -> Image<Rgb> {
    let spec = shadow_spec(conditions, GROUND, 4);
    let maps = attenuation_maps(hull, conditions, &spec);
    let shadow = ShadowMaps {
        irradiance: spec
            .conditions
            .iter()
            .map(|&k| ground_irradiance(&conditions[k]))
            .collect(),
        spec,
        maps,
    };
    shadow.relight(&vec![[1.0; 3]; conditions.len()]).image
}

fn bounded(img: &Image<Rgb>) -> bool {
    img.pixels()
        .iter()
        .flatten()
        .all(|v| v.is_finite() && (0.0..=1.0).contains(v))
}

#[test]
fn an_empty_hull_casts_no_shadow() {
    let empty = VoxelHull::empty(VoxelGrid::covering(Vec3::ZERO, Vec3::ONE, 0.1).unwrap());
    let conditions = [
        condition(false, &[[0.0, 1.0, 0.0], [0.5, 0.8, 0.1]]),
        condition(true, &[[0.0, -1.0, 0.0]]),
    ];
    assert!(
        relit(&empty, &conditions)
            .pixels()
            .iter()
            .all(|p| *p == [1.0; 3])
    );
    let sun = [DirLight {
        direction: Vec3::new(0.3, 0.9, 0.1).normalize(),
        irradiance: [5.0; 3],
    }];
    let traced = traced_shadow(&empty, &sun, GROUND);
    assert!(traced.image.pixels().iter().all(|p| *p == [1.0; 3]));
    // Composited, a shadow of ones leaves the backdrop as it is.
    let cam = Camera::look_at(Vec3::new(0.0, 1.5, 4.0), Vec3::ZERO, Vec3::Y, 0.8, 16, 12).unwrap();
    let env = EnvMap::uniform([0.7; 3], 8);
    let (c, l) = compose(
        Image::new(16, 12, [0.0; 4]),
        &cam,
        &Backdrop::environment(env, GroundLook::Environment),
        &|p| traced.at(p.x, p.z),
    )
    .unwrap();
    assert_eq!(c.pixels(), l.backdrop.pixels());
}

#[test]
fn a_light_exactly_at_the_horizon_adds_nothing() {
    let hull = block(Vec3::new(-0.3, 0.0, -0.3), Vec3::new(0.3, 1.8, 0.3));
    let horizon = condition(false, &[[1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]);
    assert_eq!(ground_irradiance(&horizon), [0.0; 3]);
    // Traced toward the lights themselves: no light from above, nothing to block.
    let spec = shadow_spec(std::slice::from_ref(&horizon), GROUND, 1);
    let maps = attenuation_maps(&hull, std::slice::from_ref(&horizon), &spec);
    assert!(maps[0].pixels().iter().all(|&a| a == 1.0));
    // Spread over their solid angle, the upper half of each cone lights the ground a
    // little and is blocked near the body: finite and bounded.
    let s = relit(&hull, &[horizon]);
    assert!(bounded(&s));
    // Traced: a light at the horizon is ignored, one just above it casts a long shadow.
    let at = [DirLight {
        direction: Vec3::X,
        irradiance: [1.0; 3],
    }];
    assert!(
        traced_shadow(&hull, &at, GROUND)
            .image
            .pixels()
            .iter()
            .all(|p| *p == [1.0; 3])
    );
    let low = [DirLight {
        direction: Vec3::new(1.0, 0.05, 0.0).normalize(),
        irradiance: [1.0; 3],
    }];
    let long = traced_shadow(&hull, &low, GROUND);
    assert!(bounded(&long.image));
    // 1.8 m tall, 0.05 rise per run: the shadow reaches the patch's edge at x = -1.5; the
    // maps fade to 1 over the patch's outer fifth, and the shadow with them.
    assert_eq!(long.at(-1.15, 0.0), [0.0; 3]);
    let t = GROUND.texel_of(-1.45, 0.0);
    assert_eq!(
        long.image.get(t.x.round() as usize, t.y.round() as usize),
        [0.0; 3]
    );
    let w = edge_fade(-1.45, 0.0, GROUND.extent_m);
    assert!(w > 0.5 && w < 1.0 && (long.at(-1.45, 0.0)[0] - w).abs() < 1e-6);
}

#[test]
fn a_tiny_sun_far_brighter_than_the_sky_casts_a_hard_bounded_shadow() {
    // A sky of radiance 1 with one texel 10^5 times brighter, high in the south-west.
    let (w, h) = (128, 64);
    let mut sky = Image::new(w, h, [1.0f32; 3]);
    sky.set(40, 15, [1e5; 3]);
    let env = EnvMap::from_image(sky).unwrap();
    let lights = env.median_cut(64);
    let sun = lights
        .iter()
        .max_by(|a, b| a.irradiance[0].total_cmp(&b.irradiance[0]))
        .unwrap();
    // The sun carries far more light than the rest of the sky together.
    assert!(sun.irradiance[0] > 10.0 * env.total_light()[0] / 2.0 / 64.0);
    let hull = block(Vec3::new(-0.2, 0.0, -0.2), Vec3::new(0.2, 1.6, 0.2));
    let s = traced_shadow(&hull, &lights, GROUND);
    assert!(bounded(&s.image));
    // Under the sun's shadow almost all light is gone; away from the body nothing is.
    let d = sun.direction;
    let shade = -Vec3::new(d.x, 0.0, d.z).normalize() * 0.8 * (d.length() / d.y).min(1.5);
    let under = s.at(shade.x, shade.z);
    assert!(under[0] < 0.2, "in the sun's shadow: {under:?}");
    // A far corner loses only some low sky behind the body (measured 0.9995).
    assert!(s.at(1.4, 1.4)[0] > 0.99);
}

#[test]
fn a_body_resting_on_the_ground_casts_a_contact_shadow() {
    // The lowest voxels touch y = 0: every light from above is blocked right under them.
    let hull = block(Vec3::new(-0.1, 0.0, -0.1), Vec3::new(0.1, 0.1, 0.1));
    let conditions = [condition(
        false,
        &[[0.0, 1.0, 0.0], [0.7, 0.7, 0.0], [-0.4, 0.9, 0.3]],
    )];
    let s = relit(&hull, &conditions);
    let t = GROUND.texel_of(0.0, 0.0);
    assert_eq!(s.get(t.x.round() as usize, t.y.round() as usize), [0.0; 3]);
    // A hand's width beside the box, lights at 45 degrees still reach it partly.
    assert!(s.get(0, 0) == [1.0; 3]);
}

#[test]
fn a_subject_partly_outside_the_ground_patch_is_shadowed_where_the_patch_reaches() {
    // A pillar straddling the patch's edge at x = 1.5 m, a sun overhead.
    let hull = block(Vec3::new(1.3, 0.0, -0.2), Vec3::new(1.8, 1.0, 0.2));
    let conditions = [condition(false, &[[0.0, 1.0, 0.0]])];
    let s = relit(&hull, &conditions);
    assert!(bounded(&s));
    let shadow = frf_render::shadow::RelitShadow {
        ground: GROUND,
        image: s,
    };
    // Inside the patch under the pillar the map is dark, faded toward 1 as the patch's
    // edge nears; beyond the patch: 1, by definition.
    let t = GROUND.texel_of(1.45, 0.0);
    assert_eq!(
        shadow.image.get(t.x.round() as usize, t.y.round() as usize),
        [0.0; 3]
    );
    let w = edge_fade(1.45, 0.0, GROUND.extent_m);
    assert!((shadow.at(1.45, 0.0)[0] - w).abs() < 1e-6);
    assert_eq!(shadow.at(1.6, 0.0), [1.0; 3]);
}
