//! The subject in a scene on the tiny stage's oracle field, against the stage's truth:
//! the visual hull's overlap with the true body, the shadow (relit maps, and traced
//! against the hull) against the true relative irradiance, the contact shadow under the
//! feet, and composites over the environment against true composites.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use frf_core::env::EnvMap;
use frf_eval::scene::{composite_psnr, shadow_error, true_composite};
use frf_eval::views::{between_view_cameras, truth_frame};
use frf_reflectance::FieldFile;
use frf_render::composite::{Backdrop, GroundLook};
use frf_render::morph::Variant;
use frf_render::renderer::{Renderer, SceneShadow};
use frf_render::shadow::{ShadowMaps, traced_shadow};

#[test]
fn hull_shadow_and_composite_meet_their_bounds_against_the_truth() {
    let tiny = frf_testkit::tiny_field();
    let field = FieldFile::open(&tiny.field).unwrap();
    let hull = field.hull(0).unwrap().unwrap();
    let iou = hull
        .iou(&tiny.stage.true_occupancy(0, hull.grid()))
        .unwrap();
    let env = EnvMap::sky();
    let lights = env.median_cut(512);
    let maps = std::sync::Arc::new(ShadowMaps::load(&field, 0).unwrap().unwrap());
    let source = tiny.source(&env);
    let relit = maps.relight(source.ground_coefficients.as_ref().unwrap());
    let maps_error = shadow_error(&relit, &tiny.stage, 0, &lights);
    let traced = traced_shadow(&hull, &env.median_cut(256), maps.spec.ground);
    let traced_error = shadow_error(&traced, &tiny.stage, 0, &lights);
    eprintln!("hull IoU {iou:.3}, shadow error: maps {maps_error:.4}, traced {traced_error:.4}");
    // Measured on this fixture: IoU 0.877 (true mattes, no perturbation, 6 misses),
    // shadow error 0.0430 (maps: the built-in sky's small sun spreads over a condition's
    // four lights) and 0.0060 (traced). 0.05 is the target set for the maps.
    assert!(iou > 0.85, "hull IoU {iou}");
    assert!(maps_error < 0.05, "maps: {maps_error}");
    assert!(
        traced_error < 0.01 && traced_error < maps_error,
        "traced: {traced_error}"
    );

    // Contact: under the lowest occupied voxel both the truth and the relit maps are dark.
    let g = hull.grid();
    let lowest = (0..g.len())
        .filter(|&i| hull.occupied(i))
        .map(|i| {
            let [a, b, c] = g.cell(i);
            g.centre(a, b, c)
        })
        .min_by(|a, b| a.y.total_cmp(&b.y))
        .unwrap();
    let truth = tiny.stage.true_ground_shadow(0, &lights, &maps.spec.ground);
    let t = maps.spec.ground.texel_of(lowest.x, lowest.z);
    let (i, j) = (t.x.round() as usize, t.y.round() as usize);
    let (true_s, relit_s) = (truth.get(i, j)[1], relit.image.get(i, j)[1]);
    assert!(
        true_s < 0.6 && relit_s < 0.6,
        "contact: truth {true_s}, relit {relit_s}"
    );

    // Composites over the environment at a camera between views.
    let camera = between_view_cameras(&source.geometry, 1)
        .unwrap()
        .remove(0)
        .camera;
    let mut renderer = Renderer::new(&source, None).unwrap();
    let backdrop = Backdrop::environment(env, GroundLook::Environment);
    renderer
        .set_scene(backdrop.clone(), SceneShadow::Maps(maps.clone()))
        .unwrap();
    let frame = renderer
        .render_frame(&camera, Variant::FourWay, false)
        .unwrap();
    let subject = truth_frame(&tiny.stage, 0, &camera, &lights).unwrap();
    let true_frame = true_composite(&tiny.stage, 0, &camera, subject, &lights, &backdrop).unwrap();
    let psnr = composite_psnr(&true_frame, &frame.composite);
    eprintln!("composite PSNR {psnr:.2} dB");
    // Measured: 28.9 dB (the backdrop is exact; the subject and its shadow are not).
    assert!(psnr > 26.0 && psnr.is_finite(), "{psnr}");
}
