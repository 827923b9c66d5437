//! The GPU renderer against its CPU twin on the virtual stage's tiny oracle field, relit
//! by the built-in sky (its sun by the views' fitted normals): the relighting pass
//! (per-view scales and pre-lit codes) and every
//! variant of the morph from cameras between grid views, above the grid and inside the
//! cylinder; and a request the GPU refuses comes back as a typed error.
//!
//! Tolerances (measured on lavapipe: scales equal to 1e-7, codes differ by at most 1 on
//! rounding ties, frames by at most 1e-4): scales 1e-5 relative, codes 1, frames 2e-3
//! absolute in linear radiance (peak about 1) and alpha, pixel classes within 0.5 %.
//!
//! Needs a wgpu adapter (lavapipe on machines without a GPU); with `FRF_SKIP_GPU=1` and
//! no adapter it says so and passes, otherwise a missing adapter fails.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use frf_core::camera::Camera;
use frf_core::env::EnvMap;
use frf_core::image::Image;
use frf_reflectance::FieldFile;
use frf_render::RenderError;
use frf_render::composite::{Backdrop, GroundLook};
use frf_render::cpu::render_cpu;
use frf_render::gpu::Gpu;
use frf_render::morph::Variant;
use frf_render::renderer::{Renderer, SceneShadow};
use frf_render::resident::{PoseSource, ResidentPose};
use frf_render::shadow::ShadowMaps;
use glam::Vec3;

fn gpu() -> Option<Gpu> {
    match Gpu::new() {
        Ok(g) => Some(g),
        Err(e) if std::env::var("FRF_SKIP_GPU").is_ok_and(|v| v == "1") => {
            eprintln!("skipped (FRF_SKIP_GPU=1): {e}");
            None
        }
        Err(e) => panic!("no GPU adapter ({e}); install mesa-vulkan-drivers or set FRF_SKIP_GPU=1"),
    }
}

/// The scales the relighting pass wrote into `pose`'s view table (never read back by the
/// renderer itself) within 1e-5 of the CPU twin's, and its pre-lit codes within 1.
fn assert_relit_as_the_cpu(
    gpu: &Gpu,
    pose: &frf_render::gpu::GpuPose,
    cpu: &ResidentPose,
    what: &str,
) {
    assert_relit_within(gpu, pose, cpu, (what, 1e-5));
}

/// [`assert_relit_as_the_cpu`] with the scales within `tolerance` (relative).
fn assert_relit_within(
    gpu: &Gpu,
    pose: &frf_render::gpu::GpuPose,
    cpu: &ResidentPose,
    (what, tolerance): (&str, f32),
) {
    let scales = gpu.read_scales(pose).unwrap();
    for (i, (a, b)) in cpu.scales.iter().zip(&scales).enumerate() {
        assert!(
            (a - b).abs() <= tolerance * a.abs().max(1e-6),
            "{what}, view {i}: scale {a} vs {b}"
        );
    }
    let texels = gpu.read_prelit(pose).unwrap();
    assert_eq!(texels.len(), cpu.prelit.len());
    for (i, (a, b)) in cpu.prelit.iter().zip(&texels).enumerate() {
        for (x, y) in a.iter().zip(b) {
            for k in 0..4 {
                let d = (x[k] as i32 - y[k] as i32).abs();
                assert!(d <= 1, "{what}, view {i}: pre-lit code {x:?} vs {y:?}");
            }
        }
    }
}

/// A camera between the tiny field's 0° and 17° rows and between two of its columns.
fn between_views() -> Camera {
    Camera::look_at(
        Vec3::new(2.2, 1.4, 3.0),
        Vec3::new(0.0, 0.9, 0.0),
        Vec3::Y,
        0.55,
        64,
        90,
    )
    .unwrap()
}

fn tiny_source() -> PoseSource {
    tiny_field_source(&EnvMap::sky())
}

fn tiny_field_source(env: &EnvMap) -> PoseSource {
    frf_testkit::tiny_field().source(env)
}

/// Copies of one pose (walkers under lights of their own, read by plans of their own)
/// share the frame pass's tables, and with them one bind group and one dispatch, while
/// each keeps its own light, views and flows: the copy that read every other view is
/// relit and drawn as its CPU twin. The pose at a coarser level of detail (other cameras)
/// is drawn apart.
#[test]
fn copies_of_one_pose_read_by_other_plans_are_drawn_together_each_its_own() {
    use frf_reflectance::project::FloorModel;
    use frf_render::resident::Lighting;
    let Some(gpu) = gpu() else { return };
    let fixture = frf_testkit::tiny_field();
    let field = FieldFile::open(&fixture.field).unwrap();
    let sky = EnvMap::sky();
    let lit = |yaw: f32| Lighting::Environment {
        env: sky.rotated(yaw),
        floor: FloorModel::Environment,
    };
    let full = PoseSource::load_at(&field, 0, &lit(0.0), None, 0, None).unwrap();
    let views = full.geometry.views();
    let plan = frf_render::pose_plan::PosePlan {
        pose: 0,
        views: (0..views).map(|i| i % 2 == 0).collect(),
        flows: vec![[true; 4]; views],
        conditions: vec![true; field.header().conditions.len()],
        shadow_maps: false,
        hull: true,
        pose_flows: [false; 2],
        level: 0,
        shadow_level: 0,
        bounds: frf_render::footprint::SubjectBounds::DESIGN,
    };
    let half = PoseSource::load_at(&field, 0, &lit(2.0), Some(&plan), 0, None).unwrap();
    assert!(half.geometry.prelit_layer_count < full.geometry.prelit_layer_count);
    let a = gpu.upload_pose(&full).unwrap();
    let b = gpu.upload_pose(&half).unwrap();
    assert!(a.draws_with(&b));
    let cpu = ResidentPose::relight_cpu(&half);
    assert_relit_as_the_cpu(&gpu, &a, &ResidentPose::relight_cpu(&full), "every view");
    assert_relit_as_the_cpu(&gpu, &b, &cpu, "every other view");
    let cam = between_views();
    let (g, _) = gpu.render(&b, &cam, Variant::FourWay).unwrap();
    let (c, _) = render_cpu(&cpu, &cam, Variant::FourWay);
    let worst = (g.pixels().iter().zip(c.pixels()))
        .flat_map(|(x, y)| (0..4).map(move |k| (x[k] - y[k]).abs()))
        .fold(0.0f32, f32::max);
    assert!(
        worst <= 2e-3,
        "every other view: largest difference {worst}"
    );
    let coarse = PoseSource::load_at(&field, 0, &lit(0.0), None, 1, None).unwrap();
    assert!(!a.draws_with(&gpu.upload_pose(&coarse).unwrap()));
}

#[test]
fn gpu_and_cpu_agree_on_the_tiny_stage_field() {
    let Some(gpu) = gpu() else { return };
    let source = tiny_source();
    // The sky's sun is relit by the views' fitted normals, its cast shadows traced
    // through the visual hull, on both.
    assert!(source.suns.len() == 1 && source.holds_normals());
    assert!(source.geometry.proxy.hull().is_some());
    let cpu = ResidentPose::relight_cpu(&source);
    let pose = gpu.upload_pose(&source).unwrap();
    // The frames below find their quads through the cylinder's column index.
    assert!(pose.geometry.cylinder.has_column_index());

    assert_relit_as_the_cpu(&gpu, &pose, &cpu, "upload");

    let target = Vec3::new(0.0, 0.9, 0.0);
    let cameras = [
        // Between the 0 and 17 degree rows, between two columns.
        ("between views", Vec3::new(2.2, 1.4, 3.0), 0.55),
        ("above the grid", Vec3::new(0.8, 6.0, 1.5), 0.7),
        ("inside the cylinder", Vec3::new(0.9, 1.1, 1.2), 1.0),
    ];
    for (name, eye, fov) in cameras {
        let cam = Camera::look_at(eye, target, Vec3::Y, fov, 64, 90).unwrap();
        for v in Variant::ALL.into_iter().chain(Variant::ABLATIONS) {
            let (g, gs) = gpu.render(&pose, &cam, v).unwrap();
            let (c, cs) = render_cpu(&cpu, &cam, v);
            let mut worst = 0.0f32;
            for (a, b) in g.pixels().iter().zip(c.pixels()) {
                for k in 0..4 {
                    worst = worst.max((a[k] - b[k]).abs());
                }
            }
            assert!(worst <= 2e-3, "{name}, {v:?}: largest difference {worst}");
            let slack = (64 * 90) / 200;
            for (what, a, b) in [
                ("inside", gs.inside, cs.inside),
                ("above", gs.clamped_above, cs.clamped_above),
                ("below", gs.clamped_below, cs.clamped_below),
                ("missed", gs.missed, cs.missed),
            ] {
                assert!(a.abs_diff(b) <= slack, "{name}, {v:?}: {what} {a} vs {b}");
            }
            if name == "above the grid" {
                assert!(gs.clamped_above > 0, "{name}: {gs:?}");
            }
        }
    }
}

/// A ground of its own shape (bright toward one side) relights the floor conditions by
/// the normals (`frf_reflectance::floor_light`) on both, and changes what they show.
#[test]
fn a_ground_of_its_own_shape_relights_the_floor_conditions_as_on_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let img = Image::from_fn(64, 32, |x, y| {
        if y < 16 {
            [1.0; 3]
        } else {
            let b = 0.2 + 3.0 * x as f32 / 64.0;
            [b, 0.8 * b, 0.6 * b]
        }
    });
    let source = tiny_field_source(&EnvMap::from_image(img).unwrap());
    assert!(
        source
            .floor_shares
            .iter()
            .any(|v| v.iter().any(|e| !e.is_empty()))
    );
    let cpu = ResidentPose::relight_cpu(&source);
    let pose = gpu.upload_pose(&source).unwrap();
    assert_relit_as_the_cpu(&gpu, &pose, &cpu, "a ground of its own shape");
    let flat = ResidentPose::relight_cpu(&PoseSource {
        floor_shares: Vec::new(),
        ..source.clone()
    });
    let changed = (cpu.prelit.iter().flatten())
        .zip(flat.prelit.iter().flatten())
        .filter(|(a, b)| a != b)
        .count();
    assert!(changed > 100, "{changed} texels changed");
}

#[test]
fn an_l2_light_with_negative_lobes_relights_as_on_the_cpu() {
    let Some(gpu) = gpu() else { return };
    // The sky's L2 light rings below zero opposite its sun: some texels relight negative,
    // which the per-view peak of the relit codes must not take for the brightest.
    let light = EnvMap::sky().to_sh();
    let env = EnvMap::from_sh(&light, frf_core::env::SH_MAP_HEIGHT).unwrap();
    assert!(env.image().pixels().iter().any(|p| p[0] < 0.0));
    let source = frf_testkit::tiny_field().source(&env);
    let cpu = ResidentPose::relight_cpu(&source);
    let pose = gpu.upload_pose(&source).unwrap();
    assert_relit_as_the_cpu(&gpu, &pose, &cpu, "an L2 sky");
}

#[test]
fn a_request_the_gpu_refuses_is_returned_as_a_typed_error() {
    let Some(gpu) = gpu() else { return };
    let pose = gpu.upload_pose(&tiny_source()).unwrap();
    // A frame one pixel wider than the largest texture the device takes.
    let too_wide = gpu.max_texture_side() + 1;
    let cam = Camera::look_at(
        Vec3::new(2.2, 1.4, 3.0),
        Vec3::new(0.0, 0.9, 0.0),
        Vec3::Y,
        0.6,
        too_wide,
        2,
    )
    .unwrap();
    match gpu.render(&pose, &cam, Variant::FourWay) {
        Err(RenderError::GpuValidation { operation, message }) => {
            assert_eq!(operation, "rendering a frame");
            assert!(!message.is_empty());
        }
        other => panic!("expected a validation error, got {:?}", other.map(|_| ())),
    }
    // The device is still usable, and the error was not left for the next request.
    let cam = Camera::look_at(
        Vec3::new(2.2, 1.4, 3.0),
        Vec3::new(0.0, 0.9, 0.0),
        Vec3::Y,
        0.6,
        64,
        90,
    )
    .unwrap();
    let (frame, stats) = gpu.render(&pose, &cam, Variant::FourWay).unwrap();
    assert!(stats.inside > 0 && frame.pixels().iter().any(|p| p[3] > 0.5));
}

#[test]
fn the_relit_shadow_and_the_composite_agree_with_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let field = FieldFile::open(&frf_testkit::tiny_field().field).unwrap();
    let maps = std::sync::Arc::new(
        ShadowMaps::load(&field, 0)
            .unwrap()
            .expect("the fixture has shadow maps"),
    );
    let source = tiny_source();
    let coefficients = source.ground_coefficients.clone().unwrap();
    let cpu_shadow = maps.relight(&coefficients);
    let mut gpu_renderer = Renderer::new(&source, Some(gpu)).unwrap();
    let mut cpu_renderer = Renderer::new(&source, None).unwrap();
    let cam = Camera::look_at(
        Vec3::new(2.4, 1.6, 2.6),
        Vec3::new(0.0, 0.7, 0.0),
        Vec3::Y,
        0.8,
        64,
        48,
    )
    .unwrap();
    let plate = Image::from_fn(64, 48, |x, y| [x as f32 / 64.0, y as f32 / 48.0, 0.3]);
    for (what, backdrop) in [
        (
            "environment",
            Backdrop::environment(EnvMap::sky().rotated(0.7), GroundLook::Environment),
        ),
        (
            "environment with a grey ground",
            Backdrop::environment(EnvMap::sky(), GroundLook::Albedo([0.4, 0.3, 0.2])),
        ),
        ("plate", Backdrop::Plate(plate)),
        ("none", Backdrop::None),
    ] {
        gpu_renderer
            .set_scene(backdrop.clone(), SceneShadow::Maps(maps.clone()))
            .unwrap();
        cpu_renderer
            .set_scene(backdrop, SceneShadow::Maps(maps.clone()))
            .unwrap();
        // The relit shadow: the same sums in the same order (measured: equal).
        let g = gpu_renderer.relit_shadow().unwrap().unwrap();
        for (a, b) in g.image.pixels().iter().zip(cpu_shadow.image.pixels()) {
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() <= 1e-5, "{what}: shadow {a:?} vs {b:?}");
            }
        }
        assert!(
            cpu_shadow.image.pixels().iter().any(|p| p[1] < 0.5),
            "the sky's sun casts a shadow"
        );
        let gf = gpu_renderer
            .render_frame(&cam, Variant::FourWay, true)
            .unwrap();
        let cf = cpu_renderer
            .render_frame(&cam, Variant::FourWay, true)
            .unwrap();
        let (gl, cl) = (gf.layers.unwrap(), cf.layers.unwrap());
        // Measured on lavapipe: composites and backdrops differ by at most 4.2e-5 with
        // a peak of 2.5 (environment lookups go through atan2 and acos in the shader),
        // the relit shadow not at all; bounds with tenfold headroom.
        let peak = cf
            .composite
            .pixels()
            .iter()
            .map(|p| p[0])
            .fold(1.0f32, f32::max);
        let worst = |a: &[[f32; 4]], b: &[[f32; 4]]| {
            a.iter()
                .zip(b)
                .flat_map(|(x, y)| (0..4).map(move |k| (x[k] - y[k]).abs()))
                .fold(0.0f32, f32::max)
        };
        let d = worst(gf.composite.pixels(), cf.composite.pixels());
        let shadow_max = g
            .image
            .pixels()
            .iter()
            .zip(cpu_shadow.image.pixels())
            .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()))
            .fold(0.0f32, f32::max);
        eprintln!(
            "{what}: relit shadow {shadow_max:e}, composite {d:e} of peak {peak}, backdrop {:e}",
            worst(gl.backdrop.pixels(), cl.backdrop.pixels())
        );
        assert!(
            d <= 2e-4 * peak,
            "{what}: composite differs by {d} (peak {peak})"
        );
        let d = worst(gl.backdrop.pixels(), cl.backdrop.pixels());
        assert!(d <= 2e-4 * peak, "{what}: backdrop differs by {d}");
        let ds = gl
            .shadow
            .pixels()
            .iter()
            .zip(cl.shadow.pixels())
            .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()))
            .fold(0.0f32, f32::max);
        assert!(ds <= 1e-3, "{what}: shadow layer differs by {ds}");
        assert!(worst(gl.subject.pixels(), cl.subject.pixels()) <= 2e-3);
    }
}

/// Relit in place under a light that turns every frame, from the codes it keeps resident:
/// each frame's pre-lit codes and scales equal the CPU twin's (as a fresh upload's do),
/// and a frame rendered from the pose relit in place equals one rendered from the pose
/// made resident afresh under that light, bit for bit.
#[test]
fn a_pose_relit_in_place_each_frame_equals_the_cpu_twin_and_a_fresh_upload() {
    use frf_reflectance::project::FloorModel;
    use frf_render::renderer::Device;
    use frf_render::resident::Lighting;
    let Some(gpu) = gpu() else { return };
    let fixture = frf_testkit::tiny_field();
    let field = FieldFile::open(&fixture.field).unwrap();
    let sky = EnvMap::sky();
    let first = fixture.source(&sky);
    let mut pose = gpu.upload_pose(&first).unwrap();
    let shared = pose.basis().unwrap().clone();
    let cam = between_views();
    for (frame, yaw) in [0.4f32, 1.3, 2.9, 4.4].into_iter().enumerate() {
        let lighting = Lighting::Environment {
            env: sky.rotated(yaw),
            floor: FloorModel::Environment,
        };
        let source = first.relit(&field, &lighting, None).unwrap();
        gpu.relight_pose(&mut pose, &source).unwrap();
        let cpu = ResidentPose::relight_cpu(&source);
        assert_relit_as_the_cpu(&gpu, &pose, &cpu, &format!("frame {frame}"));
        // A copy made afresh, sharing the codes, draws the same frame.
        let fresh = gpu.upload_pose_sharing(&source, Some(&shared)).unwrap();
        assert!(std::sync::Arc::ptr_eq(fresh.basis().unwrap(), &shared));
        let (a, _) = gpu.render(&pose, &cam, Variant::FourWay).unwrap();
        let (b, _) = gpu.render(&fresh, &cam, Variant::FourWay).unwrap();
        assert!(
            a.pixels() == b.pixels(),
            "frame {frame}: relit in place differs"
        );
    }
    // Its codes let go of (a light that will not change), then relit after all: they
    // are uploaded again, and it still relights as the CPU does.
    pose.release_basis();
    assert!(pose.basis().is_none());
    let lighting = Lighting::Environment {
        env: sky.rotated(5.1),
        floor: FloorModel::Environment,
    };
    let source = first.relit(&field, &lighting, None).unwrap();
    gpu.relight_pose(&mut pose, &source).unwrap();
    assert_relit_as_the_cpu(
        &gpu,
        &pose,
        &ResidentPose::relight_cpu(&source),
        "re-uploaded",
    );
    // Relit with another pose's views: refused, not drawn wrong.
    let other = fixture.source(&sky);
    match gpu.relight_pose(&mut pose, &other) {
        Err(RenderError::Misuse(m)) => assert!(m.contains("another pose's views"), "{m}"),
        r => panic!("expected a misuse, got {:?}", r.map(|_| ())),
    }
    // The same through the device front, on the CPU twin too.
    for device in [Device::Gpu(Box::new(gpu)), Device::Cpu] {
        let mut resident = device.make_resident(&first).unwrap();
        let lighting = Lighting::Environment {
            env: sky.rotated(2.0),
            floor: FloorModel::Environment,
        };
        let source = resident.source().relit(&field, &lighting, None).unwrap();
        device.relight(&mut resident, &source).unwrap();
        let fresh = device.make_resident(&source).unwrap();
        let (a, _) = device
            .render_subject(&resident, &cam, Variant::FourWay)
            .unwrap();
        let (b, _) = device
            .render_subject(&fresh, &cam, Variant::FourWay)
            .unwrap();
        assert!(
            a.pixels() == b.pixels(),
            "{}: relit in place differs",
            device.name()
        );
    }
}

#[test]
fn the_light_fit_relights_on_the_gpu_as_on_the_cpu() {
    use frf_reflectance::light_fit::{LightFit, farthest_lights};
    let Some(gpu) = gpu() else { return };
    // A sphere whose albedo varies, with a highlight and a dark band (a texel the fit
    // skips), under 12 lights; 6 kept.
    const SIDE: usize = 48;
    let photo = |l: Vec3| {
        Image::from_fn(SIDE, SIDE, |x, y| {
            let u = (x as f32 + 0.5) / SIDE as f32 * 2.0 - 1.0;
            let v = 1.0 - (y as f32 + 0.5) / SIDE as f32 * 2.0;
            let r2 = u * u + v * v;
            if r2 >= 0.9 || (0.2..0.25).contains(&u) {
                return [0.0; 3];
            }
            let n = Vec3::new(u, v, (1.0 - r2).sqrt());
            let d = n.dot(l).max(0.0);
            let s = if d > 0.0 {
                0.2 * n.dot((l + Vec3::Z).normalize()).powf(20.0)
            } else {
                0.0
            };
            [
                (0.5 + 0.3 * u) * d + s,
                0.4 * d + s,
                (0.3 - 0.2 * v) * d + s,
            ]
        })
    };
    let all: Vec<Vec3> = (0..12)
        .map(|k| {
            let polar = if k < 4 { 25f32 } else { 55.0 }.to_radians();
            let az = k as f32 * 2.4;
            Vec3::new(polar.sin() * az.cos(), polar.sin() * az.sin(), polar.cos())
        })
        .collect();
    let kept = farthest_lights(&all, 6, Vec3::Z);
    let dirs: Vec<Vec3> = kept.iter().map(|&k| all[k]).collect();
    let images: Vec<_> = dirs.iter().map(|&l| photo(l)).collect();
    let refs: Vec<_> = images.iter().collect();
    let mask = vec![true; SIDE * SIDE];
    // The diffuse fit alone, and with its glossy lobe (the highlight above is one).
    let diffuse = LightFit::fit(&refs, &dirs, &mask);
    let glossy = LightFit::fit_glossy(&refs, &dirs, &mask, Vec3::Z);
    assert!(diffuse.gloss().is_none());
    assert!(
        glossy
            .gloss()
            .is_some_and(|g| g.strength.iter().any(|&k| k > 0.0))
    );
    for (name, fit) in [("diffuse", &diffuse), ("glossy", &glossy)] {
        let resident = gpu.upload_light_fit(fit, &refs, &dirs).unwrap();
        for (k, &l) in all.iter().enumerate().filter(|(k, _)| !kept.contains(k)) {
            let cpu = fit.relight(&refs, &dirs, l, 3);
            let on_gpu = gpu.relight_fit(&resident, l, 3).unwrap();
            let worst = cpu
                .pixels()
                .iter()
                .zip(on_gpu.pixels())
                .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs() / a[c].abs().max(1.0)))
                .fold(0.0f32, f32::max);
            assert!(
                worst < 1e-4,
                "{name}, light {k}: GPU differs from the CPU by {worst}"
            );
        }
    }
    let fit = diffuse;
    // A photograph of another size is refused, not drawn wrong.
    let small = Image::from_vec(2, 2, vec![[0.0; 3]; 4]).unwrap();
    let mut wrong = refs.clone();
    wrong[0] = &small;
    assert!(matches!(
        gpu.upload_light_fit(&fit, &wrong, &dirs),
        Err(RenderError::Misuse(_))
    ));
}

/// A pose at a reduced level of detail (a far walker) keeps its views' normals, averaged
/// over each block: its suns (here two: the sky's and another, lower and behind) are
/// relit by them on both twins, as at full detail.
#[test]
fn a_reduced_pose_relights_its_suns_by_its_normals_on_both() {
    use frf_reflectance::project::FloorModel;
    use frf_render::resident::Lighting;
    let Some(gpu) = gpu() else { return };
    let fixture = frf_testkit::tiny_field();
    let field = FieldFile::open(&fixture.field).unwrap();
    let second =
        frf_core::light::direction_from_azimuth_elevation(200f32.to_radians(), 25f32.to_radians());
    let env = frf_core::sun::Sun::new(second, 2.0, [6.0, 5.0, 4.0])
        .unwrap()
        .lit(&EnvMap::sky())
        .unwrap();
    let lighting = Lighting::Environment {
        env,
        floor: FloorModel::Environment,
    };
    let source = PoseSource::load_at(&field, 0, &lighting, None, 1, None).unwrap();
    assert!(source.suns.len() == 2 && source.holds_normals());
    let cpu = ResidentPose::relight_cpu(&source);
    let pose = gpu.upload_pose(&source).unwrap();
    assert_relit_as_the_cpu(&gpu, &pose, &cpu, "level 1");
    // The suns' maps of the hull: made on the GPU, traced on the host by the CPU twin.
    let maps = gpu.read_sun_maps(&pose, &source.suns).unwrap();
    assert_eq!(maps.len(), 2);
    for (sun, gpu_map) in source.suns.iter().zip(&maps) {
        let cpu_map = sun.depth.as_ref().unwrap().reach();
        assert_eq!(cpu_map.len(), gpu_map.len());
        let hits = cpu_map.iter().filter(|&&r| r > f32::MIN).count();
        assert!(hits > 100, "{hits} texels reach the hull");
        // The same walk in f32 on both: equal but where a line grazes a voxel's edge.
        let differ = cpu_map
            .iter()
            .zip(gpu_map)
            .filter(|(a, b)| (*a - *b).abs() > 1e-4)
            .count();
        assert!(differ * 1000 <= hits, "{differ} of {hits} texels differ");
    }
}

/// Two walkers that overlap in the frame, one a little behind and beside the other, each
/// turned its own way: the GPU puts them over each other by their depths at each pixel
/// as the CPU twin does (`stack_by_depth`), and differs from the two stacked whole in the
/// order of their positions where the one behind by position is nearer by depth (4 pixels
/// here: a hand).
#[test]
fn overlapping_walkers_are_ordered_by_depth_as_on_the_cpu() {
    use frf_core::camera::Rigid;
    use frf_render::renderer::{Device, Walker};
    let Some(gpu) = gpu() else { return };
    let source = tiny_source();
    let cam = Camera::look_at(
        Vec3::new(0.3, 1.3, 3.4),
        Vec3::new(0.1, 0.8, 0.0),
        Vec3::Y,
        0.7,
        96,
        72,
    )
    .unwrap();
    let place = |x: f32, z: f32, heading: f32| Rigid {
        rotation: Rigid::rotation_y(heading).rotation,
        translation: Vec3::new(x, 0.0, z),
    };
    let placements = [place(0.0, 0.0, 0.0), place(0.25, -0.3, 2.6)];
    let frames: Vec<_> = [Device::Gpu(Box::new(gpu)), Device::Cpu]
        .into_iter()
        .map(|device| {
            let residents = [
                device.make_resident(&source).unwrap(),
                device.make_resident(&source).unwrap(),
            ];
            let walkers: Vec<Walker> = residents
                .iter()
                .zip(placements)
                .map(|(resident, world_from_subject)| Walker {
                    resident,
                    world_from_subject,
                    between: None,
                    within: None,
                })
                .collect();
            let backdrop = device.backdrop(Backdrop::None).unwrap();
            device
                .render_frame(&walkers, &backdrop, &cam, Variant::FourWay, true)
                .unwrap()
        })
        .collect();
    let (g, c) = (&frames[0], &frames[1]);
    let worst = g
        .composite
        .pixels()
        .iter()
        .zip(c.composite.pixels())
        .flat_map(|(x, y)| (0..4).map(move |k| (x[k] - y[k]).abs()))
        .fold(0.0f32, f32::max);
    eprintln!("two walkers by depth: GPU vs CPU {worst:e}");
    assert!(worst <= 2e-3, "GPU and CPU differ by {worst}");
    // Both walkers show, and overlap.
    let covered = c.composite.pixels().iter().filter(|p| p[3] > 0.5).count();
    assert!(covered > 200, "{covered} pixels covered");
    // Stacked whole in the order of their positions instead, some pixels differ.
    let device = Device::Cpu;
    let resident = device.make_resident(&source).unwrap();
    let order = frf_render::composite::back_to_front(&cam, &placements.map(|p| p.translation));
    let layers = order
        .iter()
        .map(|&k| {
            let seen = cam.transformed(&placements[k].inverse());
            device
                .render_subject(&resident, &seen, Variant::FourWay)
                .unwrap()
                .0
        })
        .collect();
    let whole = frf_render::composite::stack(layers).unwrap();
    let crossed = whole
        .pixels()
        .iter()
        .zip(c.layers.as_ref().unwrap().subject.pixels())
        .filter(|(a, b)| (0..4).any(|k| (a[k] - b[k]).abs() > 0.05))
        .count();
    eprintln!("pixels where depth reorders the walkers: {crossed}");
    assert!(crossed > 0, "ordered by depth as by position everywhere");
}

/// A low sun (`[8, 7, 6]`, its direction at `azimuth_deg`, `elevation_deg`) over a dim
/// uniform sky, and its direction.
fn low_sun(azimuth_deg: f32, elevation_deg: f32) -> (EnvMap, Vec3) {
    let toward = frf_core::light::direction_from_azimuth_elevation(
        azimuth_deg.to_radians(),
        elevation_deg.to_radians(),
    );
    let env = frf_core::sun::Sun::new(toward, 1.0, [8.0, 7.0, 6.0])
        .unwrap()
        .lit(&EnvMap::uniform([0.2; 3], 64))
        .unwrap();
    (env, toward)
}

/// Pose 0 of `field` under `env` read from its yaw tables, with `occluders` in the way of
/// its suns.
fn with_occluders(
    field: &FieldFile,
    env: &EnvMap,
    occluders: Vec<frf_reflectance::sun_depth::Occluder>,
) -> PoseSource {
    let light = frf_render::resident::Lighting::Tabled(
        frf_reflectance::yaw_light::YawLight::of_env(
            field.projector_shared().unwrap().clone(),
            env,
            frf_reflectance::project::FloorModel::Environment,
        )
        .with_occluders(occluders),
    );
    PoseSource::load(field, 0, &light).unwrap()
}

/// Pose 0's hull of `field` standing at `translation`, turned by `turn` (radians), in
/// the way of the walker at the origin.
fn occluder_at(
    field: &FieldFile,
    translation: Vec3,
    turn: f32,
) -> frf_reflectance::sun_depth::Occluder {
    frf_reflectance::sun_depth::Occluder {
        hull: std::sync::Arc::new(field.hull(0).unwrap().unwrap()),
        here_from_there: frf_core::camera::Rigid {
            rotation: glam::Mat3::from_rotation_y(turn),
            translation,
        },
    }
}

/// A walker standing between the sun and the tiny field's walker: the suns' maps with its
/// hull in the way are made on the GPU as the CPU twin traces them, the pose relit by
/// them is the CPU's code for code, and the walker it shades is darker than without it.
#[test]
fn another_walker_in_the_way_of_the_sun_shades_on_both() {
    let Some(gpu) = gpu() else { return };
    let fixture = frf_testkit::tiny_field();
    let field = FieldFile::open(&fixture.field).unwrap();
    // A low sun in the sky's place of the sun, and the same walker 1.2 m toward it.
    let (env, toward) = low_sun(90.0, 20.0);
    let beside = Vec3::new(toward.x, 0.0, toward.z).normalize() * 1.2;
    let alone = with_occluders(&field, &env, Vec::new());
    let shaded = with_occluders(&field, &env, vec![occluder_at(&field, beside, 0.0)]);
    assert!(!shaded.suns.is_empty() && shaded.holds_normals());
    assert_eq!(shaded.suns[0].depth.as_ref().unwrap().occluders.len(), 1);
    let cpu = ResidentPose::relight_cpu(&shaded);
    let pose = gpu.upload_pose(&shaded).unwrap();
    assert_relit_as_the_cpu(&gpu, &pose, &cpu, "shaded by another walker");
    let maps = gpu.read_sun_maps(&pose, &shaded.suns).unwrap();
    let cpu_map = shaded.suns[0].depth.as_ref().unwrap().reach();
    let differ = cpu_map
        .iter()
        .zip(&maps[0])
        .filter(|(a, b)| (*a - *b).abs() > 1e-4)
        .count();
    assert!(differ * 1000 <= cpu_map.len(), "{differ} texels differ");
    // The sunlit side of the walker goes dark where the other stands in the way.
    let lum = |p: &ResidentPose| -> f64 {
        p.prelit
            .iter()
            .zip(&p.scales)
            .map(|(view, s)| view.iter().map(|c| c[1] as f64 * *s as f64).sum::<f64>())
            .sum()
    };
    let (a, b) = (lum(&ResidentPose::relight_cpu(&alone)), lum(&cpu));
    eprintln!("pre-lit light: alone {a:.3e}, with the other in the way {b:.3e}");
    assert!(
        b < 0.9 * a,
        "the other walker took {:.1} % of the light",
        100.0 * (1.0 - b / a)
    );
}

/// Walkers relit between two frames whose suns' maps and hulls outgrow the buffers they
/// share (the batch's scratch, the table of hulls), grown while the maps asked for before
/// wait in the batch: every walker relit as the CPU twin relights it, and the last one's
/// maps (two occluders in the way) as the CPU traces them.
#[test]
fn walkers_whose_maps_outgrow_the_buffers_are_relit_as_on_the_cpu() {
    use frf_core::camera::Rigid;
    use frf_reflectance::project::FloorModel;
    use frf_reflectance::sun_depth::Occluder;
    use frf_reflectance::yaw_light::YawLight;
    use frf_render::resident::Lighting;
    let Some(gpu) = gpu() else { return };
    let fixture = frf_testkit::tiny_field();
    let field = FieldFile::open(&fixture.field).unwrap();
    let toward =
        frf_core::light::direction_from_azimuth_elevation(60f32.to_radians(), 25f32.to_radians());
    let env = frf_core::sun::Sun::new(toward, 1.0, [8.0, 7.0, 6.0])
        .unwrap()
        .lit(&EnvMap::uniform([0.2; 3], 64))
        .unwrap();
    // Occluders with hulls of their own (each its own entry in the table of hulls), one
    // and two metres toward the sun.
    let flat = Vec3::new(toward.x, 0.0, toward.z).normalize();
    let occluder = |metres: f32| Occluder {
        hull: std::sync::Arc::new(field.hull(0).unwrap().unwrap()),
        here_from_there: Rigid {
            rotation: glam::Mat3::from_rotation_y(metres),
            translation: flat * metres,
        },
    };
    let light = |occluders: Vec<Occluder>| {
        Lighting::Tabled(
            YawLight::of_env(
                field.projector_shared().unwrap().clone(),
                &env,
                FloorModel::Environment,
            )
            .with_occluders(occluders),
        )
    };
    let sources: Vec<PoseSource> = [
        vec![],
        vec![occluder(1.0)],
        vec![occluder(1.0), occluder(2.0)],
    ]
    .into_iter()
    .map(|o| PoseSource::load(&field, 0, &light(o)).unwrap())
    .collect();
    // Buffers far too small for one walker's maps and hulls: every request outgrows
    // them, while the maps asked for before it wait in the batch.
    gpu.restart_sun_maps(16, 1, 16);
    let poses: Vec<_> = sources
        .iter()
        .map(|s| gpu.upload_pose(s).unwrap())
        .collect();
    for (k, (pose, source)) in poses.iter().zip(&sources).enumerate() {
        let cpu = ResidentPose::relight_cpu(source);
        assert_relit_as_the_cpu(&gpu, pose, &cpu, &format!("walker {k}"));
    }
    // The last walker's maps, as made (its batch was the last).
    let last = sources.last().unwrap();
    let maps = gpu
        .read_sun_maps(poses.last().unwrap(), &last.suns)
        .unwrap();
    let cpu_map = last.suns[0].depth.as_ref().unwrap().reach();
    assert_eq!(last.suns[0].depth.as_ref().unwrap().occluders.len(), 2);
    let differ = (cpu_map.iter().zip(&maps[0]))
        .filter(|(a, b)| (*a - *b).abs() > 1e-4)
        .count();
    assert!(differ * 1000 <= cpu_map.len(), "{differ} texels differ");
    // The control: the same walker's map without the occluders differs from it (a GPU
    // that dropped them would fail above).
    let alone = sources[0].suns[0].depth.as_ref().unwrap().reach();
    assert_eq!(
        alone.len(),
        cpu_map.len(),
        "one frame of map with and without them"
    );
    let raised = (alone.iter().zip(&maps[0]))
        .filter(|(a, b)| (*a - *b).abs() > 1e-4)
        .count();
    assert!(
        raised * 100 > cpu_map.len(),
        "occluders raise {raised} texels"
    );
}

/// `light` to relight pose 0 of `field` by on the device, the conditions `used` (`None`:
/// all).
fn on_device<'a>(
    light: &'a frf_reflectance::yaw_light::YawLight,
    field: &'a FieldFile,
    used: Option<&'a [bool]>,
) -> frf_render::gpu::turn_light::TurnedLight<'a> {
    frf_render::gpu::turn_light::TurnedLight {
        light,
        conditions: &field.header().conditions,
        pose: field.header().pose(0).unwrap(),
        used,
    }
}

/// A light looked up on the device by each view's turn (`Gpu::relight_turned`) writes the
/// coefficients the host works out for it (`PoseSource::relit`) and relights the pose as
/// the CPU twin does: the sky turned (its sun relit by the normals, the floor conditions
/// by the ground's shape), two maps cross-faded (a sun from each), a walker in the way
/// of the sun, and a plan that leaves conditions out. Coefficients within 1e-3 (relative;
/// measured 3.8e-4 at most, the suns' nearest weights through the GPU's `acos`), scales
/// within 5e-4 and codes within 1 of the CPU twin. Every case is looked up in one
/// submission (one dispatch for all, each pose's coefficients a range of a shared page),
/// and one more pose relit under two of the lights before it ends as the later. Control:
/// the coefficients of the light the pose was made under differ.
#[test]
fn a_light_looked_up_on_the_device_relights_as_the_host_works_it_out() {
    use frf_reflectance::project::FloorModel;
    use frf_reflectance::yaw_light::{YawLight, YawTerm};
    use frf_render::resident::Lighting;
    let Some(gpu) = gpu() else { return };
    let fixture = frf_testkit::tiny_field();
    let field = FieldFile::open(&fixture.field).unwrap();
    let h = field.header();
    let views = h.pose(0).unwrap().views.len();
    let projector = field.projector_shared().unwrap().clone();
    let sky = YawLight::of_env(projector.clone(), &EnvMap::sky(), FloorModel::Environment);
    let (low, _) = low_sun(130.0, 25.0);
    let low = YawLight::of_env(projector, &low, FloorModel::Environment);
    let faded = YawLight::new(vec![
        YawTerm {
            weight: 0.6,
            yaw: 0.7,
            ..sky.terms()[0].clone()
        },
        YawTerm {
            weight: 0.4,
            yaw: -1.1,
            ..low.terms()[0].clone()
        },
    ]);
    let shaded =
        low.turned(0.3)
            .with_occluders(vec![occluder_at(&field, Vec3::new(0.9, 0.0, 0.4), 0.5)]);
    let first = fixture.source(&EnvMap::sky());
    let mut unused = vec![true; h.conditions.len()];
    for k in (0..unused.len()).step_by(3) {
        unused[k] = false;
    }
    let cases: Vec<(&str, YawLight, Option<&[bool]>)> = vec![
        ("sky turned", sky.turned(2.3), None),
        ("sky turned back", sky.turned(-0.05), None),
        ("two maps", faded, None),
        ("a walker in the way", shaded, None),
        ("a plan", sky.turned(4.0), Some(&unused)),
    ];
    let plan_of = |used: Option<&[bool]>| {
        used.map(|u| frf_render::pose_plan::PosePlan {
            pose: 0,
            views: vec![true; views],
            flows: vec![[true; 4]; views],
            conditions: u.to_vec(),
            shadow_maps: false,
            hull: true,
            pose_flows: [false; 2],
            level: 0,
            shadow_level: 0,
            bounds: frf_render::footprint::SubjectBounds::DESIGN,
        })
    };
    // Every pose made first, then every light looked up before one submission; the host's
    // coefficients written in the same order in one submission of their own (the suns'
    // maps, whose places the coefficients hold, then lie alike).
    let sources: Vec<_> = (cases.iter())
        .map(|(_, light, used)| {
            let plan = plan_of(*used);
            first
                .relit(&field, &Lighting::Tabled(light.clone()), plan.as_ref())
                .unwrap()
        })
        .collect();
    let order: Vec<usize> = (0..cases.len()).chain([0, 1]).collect();
    let poses = || -> Vec<_> {
        (0..=cases.len())
            .map(|_| gpu.upload_pose(&first).unwrap())
            .collect()
    };
    let (mut devices, mut hosts) = (poses(), poses());
    gpu.flush();
    // The last pose relit under the first light, then the second's: it ends as the second.
    for (n, &k) in order.iter().enumerate() {
        let (_, light, used) = &cases[k];
        let turned = on_device(light, &field, *used);
        let device = &mut devices[n.min(cases.len())];
        assert!(gpu.relight_turned(device, &first, &turned).unwrap());
    }
    gpu.flush();
    for (n, &k) in order.iter().enumerate() {
        gpu.relight_pose(&mut hosts[n.min(cases.len())], &sources[k])
            .unwrap();
    }
    for (n, (device, host)) in devices.iter().zip(&hosts).enumerate() {
        let k = if n < cases.len() { n } else { 1 };
        let (what, source) = (cases[k].0, &sources[k]);
        let looked_up = gpu.read_coefficients(device).unwrap();
        // Every case relights suns by the normals; the cross-fade one from each map.
        let suns = if what == "two maps" { 2 } else { 1 };
        assert_eq!(source.suns.len(), suns, "{what}");
        let worked_out = gpu.read_coefficients(host).unwrap();
        assert_eq!(looked_up.len(), worked_out.len(), "{what}: batches");
        let mut most = 0.0f32;
        for (a, b) in looked_up.iter().flatten().zip(worked_out.iter().flatten()) {
            for (x, y) in a.iter().zip(b) {
                let d = (x - y).abs() / y.abs().max(1e-3);
                most = most.max(d);
                assert!(
                    d < 1e-3,
                    "{what} (pose {n}): coefficient {a:?} looked up, {b:?} worked out"
                );
            }
        }
        eprintln!("{what} (pose {n}): largest relative difference {most:.2e}");
        let cpu = ResidentPose::relight_cpu(source);
        assert_relit_within(&gpu, device, &cpu, (what, 5e-4));
    }
    // Control: the pose as made (the sky unturned) is not what the last light relights.
    let made = gpu.upload_pose(&first).unwrap();
    let as_made = gpu.read_coefficients(&made).unwrap();
    let turned = on_device(&cases[0].1, &field, None);
    let mut device = gpu.upload_pose(&first).unwrap();
    gpu.relight_turned(&mut device, &first, &turned).unwrap();
    let looked_up = gpu.read_coefficients(&device).unwrap();
    let differ = (looked_up.iter().flatten())
        .zip(as_made.iter().flatten())
        .filter(|(a, b)| {
            a.iter()
                .zip(b.iter())
                .any(|(x, y)| (x - y).abs() > 1e-3 * y.abs().max(1e-3))
        })
        .count();
    assert!(
        differ > 100,
        "the turned sky looks up {differ} coefficients unlike the unturned"
    );
}

/// The device holds a bounded number of yaw tables: lights of more maps than it holds,
/// one after the other, let go of those no light holds any more, and the last light
/// still relights as the host works it out.
#[test]
fn the_tables_on_the_device_are_bounded_and_stay_right() {
    use frf_reflectance::project::FloorModel;
    use frf_reflectance::yaw_light::YawLight;
    use frf_render::resident::Lighting;
    let Some(gpu) = gpu() else { return };
    let fixture = frf_testkit::tiny_field();
    let field = FieldFile::open(&fixture.field).unwrap();
    let projector = field.projector_shared().unwrap().clone();
    let first = fixture.source(&EnvMap::sky());
    let mut pose = gpu.upload_pose(&first).unwrap();
    let mut last = None;
    for k in 0..20 {
        // A map of its own each time: the sky brighter by a step.
        let env = EnvMap::sky().scaled(1.0 + 0.05 * k as f32);
        let light = YawLight::of_env(projector.clone(), &env, FloorModel::Environment);
        let turned = on_device(&light, &field, None);
        gpu.flush();
        assert!(gpu.relight_turned(&mut pose, &first, &turned).unwrap());
        assert!(gpu.tables_held() <= 16, "{} tables held", gpu.tables_held());
        last = Some(light);
    }
    let source = first
        .relit(&field, &Lighting::Tabled(last.unwrap()), None)
        .unwrap();
    assert_relit_within(
        &gpu,
        &pose,
        &ResidentPose::relight_cpu(&source),
        ("the last", 5e-4),
    );
}
