//! Walkers that walk through a scene and are lit where they are, drawn by the shot on the
//! tiny oracle field (one pose: what changes from frame to frame is where a walker stands,
//! which way it faces and its light): a walker on a path draws at each frame what a
//! walker standing there draws; a path of no length is a standing walker frame for
//! frame; one probe is the scene's map, and a walker between two probes is lit by the
//! map that mixes them. On the tiny stage's two poses with the flow between them: a
//! walker drawn at reduced detail moves as at full detail.
//!
//! Renders on the GPU (lavapipe on machines without one), or on the CPU reference where
//! `FRF_SKIP_GPU=1` says there is no adapter.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use std::path::Path;

use frf_core::image::{Image, Rgba};
use frf_reflectance::FieldFile;
use frf_render::renderer::Device;
use frf_scene::Scene;
use frf_scene::shot::{Shot, ShotOptions};

fn device() -> Device {
    Device::open(frf_testkit::cpu_flag().is_some()).unwrap()
}

/// A scene of the tiny field seen from a fixed camera, 48x64, at 10 fps from 0 to `end`
/// seconds, lit as `lighting` says, with `walkers`.
fn scene(lighting: &str, walkers: &str, end: f64) -> Scene {
    let text = format!(
        r#"
[time]
end = {end}
fps = 10

[output]
size = [64, 48]

{lighting}

[camera]
[[camera.key]]
time = 0.0
position = [0.5, 1.6, 4.5]
look_at = [0.5, 0.8, 0.0]
fov_deg = 40.0

[composite]
backdrop = "env"
shadow = "maps"

{walkers}
"#
    );
    Scene::parse(Path::new("/walkers/scene.toml"), &text).unwrap()
}

/// A planned shot's options, a budget of 1 GiB.
fn planned_options() -> ShotOptions {
    ShotOptions {
        memory_budget: 1 << 30,
        planned: true,
        traced_lights: 64,
        detail: None,
        light_tolerance: frf_scene::shot::LightTolerance::DEFAULT,
        walker_shadows: true,
    }
}

/// The frames of `scene` on the tiny field: composites and walker layers.
fn frames(scene: &Scene) -> Vec<(Image<Rgba>, Image<Rgba>)> {
    let fixture = frf_testkit::tiny_field();
    let field = FieldFile::open(&fixture.field).unwrap();
    let all = scene
        .shot_frames(0..scene.frame_times().len(), (64, 48))
        .unwrap();
    let options = planned_options();
    let mut shot = Shot::new(scene, &field, device(), &all, options).unwrap();
    all.iter()
        .map(|f| {
            let r = shot.render(f, true).unwrap();
            (r.frame.composite, r.frame.layers.unwrap().subject)
        })
        .collect()
}

fn largest_difference(a: &Image<Rgba>, b: &Image<Rgba>) -> f32 {
    a.pixels()
        .iter()
        .zip(b.pixels())
        .flat_map(|(x, y)| (0..4).map(move |k| (x[k] - y[k]).abs()))
        .fold(0.0, f32::max)
}

const SKY: &str = "[lighting]\nenv = \"sky\"";

#[test]
fn a_walker_on_a_path_draws_what_a_walker_standing_there_draws() {
    // A bend: from (-0.6, 0, 0.4) round to (1.2, 0, -0.4) in 0.4 s.
    let path = "[[instance]]\n\
        [[instance.key]]\ntime = 0.0\nposition = [-0.6, 0.0, 0.4]\n\
        [[instance.key]]\ntime = 0.2\nposition = [0.3, 0.0, 0.3]\n\
        [[instance.key]]\ntime = 0.4\nposition = [1.2, 0.0, -0.4]\n";
    let walking = scene(SKY, path, 0.4);
    assert!(walking.instances[0].turns());
    let drawn = frames(&walking);
    for (k, t) in walking.frame_times().into_iter().enumerate() {
        let at = walking.placement(0, t);
        let standing = format!(
            "[[instance]]\nposition = [{}, 0.0, {}]\nheading_deg = {}\n",
            at.position.x,
            at.position.z,
            f64::from(at.heading).to_degrees()
        );
        let still = frames(&scene(SKY, &standing, 0.0));
        let d = largest_difference(&drawn[k].0, &still[0].0);
        // The heading goes through degrees in the file: a few 1e-6 radians of turn.
        assert!(d < 2e-3, "frame {k} at {t} s: {d}");
    }
    // It moved: the first and last frames differ.
    assert!(largest_difference(&drawn[0].1, &drawn[3].1) > 0.1);
}

#[test]
fn a_path_of_no_length_is_a_standing_walker_frame_for_frame() {
    let still_path = "[[instance]]\ntime_offset = 0.3\n\
        [[instance.key]]\ntime = 0.0\nposition = [0.4, 0.0, 0.2]\nheading_deg = 30.0\n\
        [[instance.key]]\ntime = 1.0\nposition = [0.4, 0.0, 0.2]\nheading_deg = 30.0\n";
    let standing =
        "[[instance]]\ntime_offset = 0.3\nposition = [0.4, 0.0, 0.2]\nheading_deg = 30.0\n";
    let a = frames(&scene(SKY, still_path, 0.3));
    let b = frames(&scene(SKY, standing, 0.3));
    for (k, (x, y)) in a.iter().zip(&b).enumerate() {
        assert!(x.0.pixels() == y.0.pixels(), "frame {k} differs");
    }
}

#[test]
fn one_probe_is_the_scenes_map_and_two_mix_linearly() {
    let walker = "[[instance]]\nposition = [0.5, 0.0, 0.0]\nheading_deg = 20.0\n";
    let plain = frames(&scene(SKY, walker, 0.0));
    let one = "[lighting]\nenv = \"sky\"\n[[lighting.probe]]\nposition = [7.0, 1.2, -3.0]\nenv = \"sky\"\n";
    let probed = frames(&scene(one, walker, 0.0));
    assert!(
        plain[0].0.pixels() == probed[0].0.pixels(),
        "one probe differs from the map"
    );

    // Two probes 4 m apart, the walker a quarter of the way from the uniform one to the
    // sky's: lit by 0.75 uniform + 0.25 sky. A cross-fade of the two maps a quarter of the
    // way (0.1 s of 0.4) lights the walker so too (its backdrop differs: compare the
    // walkers).
    let two = "[lighting]\nenv = \"sky\"\n\
        [[lighting.probe]]\nposition = [-0.5, 1.2, 0.0]\nenv = \"uniform\"\n\
        [[lighting.probe]]\nposition = [3.5, 1.2, 0.0]\nenv = \"sky\"\n";
    let mixed = frames(&scene(two, walker, 0.0));
    let fade = "[lighting]\nenv = \"uniform\"\n\
        [[lighting.key]]\ntime = 0.0\n\
        [[lighting.key]]\ntime = 0.4\nenv = \"sky\"\n";
    let faded = frames(&scene(fade, walker, 0.2));
    let d = largest_difference(&mixed[0].1, &faded[1].1);
    assert!(d < 1e-4, "the probes' mix differs from the maps' by {d}");
    // And it is not the sky's light alone.
    assert!(largest_difference(&mixed[0].1, &plain[0].1) > 0.01);
}

/// The tiny stage's poses 0 and 1 with the flow between them, written into `dir`.
fn two_pose_field(dir: &Path) -> std::path::PathBuf {
    let mut config = frf_testkit::tiny_config();
    config.poses = vec![0, 1];
    let stage = frf_stage::Stage::new(config).unwrap();
    let path = dir.join("two.frf");
    let options = frf_eval::oracle::OracleOptions {
        poses: vec![0, 1],
        jpeg_quality: 95,
        predict_flow: true,
        shadows: None,
        pose_flows: true,
    };
    frf_eval::oracle::write_oracle_field(&stage, &path, &options, &|_, _| {}).unwrap();
    path
}

/// A walker drawn at reduced detail between two poses (issue 58): its motion views,
/// made from the pose-to-pose flows of the captured images, hold at each reduced texel
/// the motion full detail holds at the middle of its block, in metres; read at the
/// texel's own coordinates (as the captured image's, the mistake this guards against)
/// they would not.
#[test]
fn motion_at_reduced_detail_is_full_detail_s_at_each_block() {
    use frf_core::grid::PoseStep;
    use frf_render::motion::{decode_motion, pose_motion};
    use frf_render::reduced_views::ReducedViews;
    use frf_render::resident::{Lighting, PoseSource};
    use glam::Vec2;

    let dir = tempfile::tempdir().unwrap();
    let field = FieldFile::open(&two_pose_field(dir.path())).unwrap();
    let kept = ReducedViews::default();
    let motion = |level: u8| {
        let source =
            PoseSource::load_at(&field, 0, &Lighting::Unlit, None, level, Some(&kept)).unwrap();
        pose_motion(&field, &source, PoseStep::Next)
            .unwrap()
            .unwrap()
    };
    let (full, half) = (motion(0), motion(1));
    assert_eq!(half.geometry.level, 1);
    let at = |pose: &frf_render::resident::ResidentPose, view: usize, x: usize, y: usize| {
        decode_motion(pose.sample_prelit(view, Vec2::new(x as f32, y as f32)))
    };
    // Per opaque texel whose block's middle full detail holds: how far its motion is
    // from that pixel's, and from the pixel of its own coordinates.
    let (mut right, mut wrong, mut size) = (Vec::new(), Vec::new(), Vec::new());
    let (c0, c1) = (full.geometry.crop, half.geometry.crop);
    let inside = |c: frf_render::geometry::Crop, x: usize, y: usize| {
        (c.x0 as usize..(c.x0 + c.width) as usize).contains(&x)
            && (c.y0 as usize..(c.y0 + c.height) as usize).contains(&y)
    };
    for view in (0..half.prelit.len()).filter(|&v| !half.prelit[v].is_empty()) {
        for k in 0..c1.texels() {
            let (x, y) = c1.pixel(k);
            if half.prelit[view][k][3] == 0 || !inside(c0, 2 * x + 1, 2 * y + 1) {
                continue;
            }
            let m = at(&half, view, x, y);
            let block = at(&full, view, 2 * x + 1, 2 * y + 1);
            right.push((m - block).length());
            wrong.push((m - at(&full, view, x, y)).length());
            size.push(block.length());
        }
    }
    let median = |mut v: Vec<f32>| {
        v.sort_by(f32::total_cmp);
        v[v.len() / 2]
    };
    let n = right.len();
    let (right, wrong, size) = (median(right), median(wrong), median(size));
    // The subject moves between the poses: centimetres a texel. Measured: 0.56 mm off
    // (the motion views' 8-bit codes) of 21 mm; the edges, where a block's texel is
    // opaque and its middle pixel is not, are farther off (90th percentile 1 cm).
    assert!(n > 100 && size > 0.005, "{n} texels, {size} m");
    assert!(right < 0.1 * size, "{right} m off, of {size} m");
    assert!(
        wrong > 0.5 * size,
        "{wrong} m at the wrong pixel, {right} m at the right"
    );
}

/// The walkers of a crowd drawing one pose share its visual hull (one decode, one upload
/// to the GPU, which keys uploads by the copy): every reader gets the copy that is held,
/// equal to the hull decoded afresh; once none is held, the next reader decodes anew.
#[test]
fn readers_of_one_pose_share_its_hull_while_it_is_held() {
    use std::sync::Arc;

    use frf_render::resident::{Lighting, PoseSource};

    let fixture = frf_testkit::tiny_field();
    let field = FieldFile::open(&fixture.field).unwrap();
    let load = || PoseSource::load(&field, 0, &Lighting::Unlit).unwrap();
    let hull_of = |s: &PoseSource| s.geometry.proxy.hull_shared().unwrap().clone();
    let (a, b) = (load(), load());
    let held = hull_of(&a);
    assert!(Arc::ptr_eq(&held, &hull_of(&b)));
    assert!(Arc::ptr_eq(&held, &field.hull_shared(0).unwrap().unwrap()));
    assert_eq!(*held, field.hull(0).unwrap().unwrap());
    // Dropped by every holder, it is decoded again: a copy of its own.
    let weak = Arc::downgrade(&held);
    drop((a, b, held));
    assert!(weak.upgrade().is_none());
    let again = field.hull_shared(0).unwrap().unwrap();
    assert_eq!(Arc::strong_count(&again), 1);
}

/// A light that turns with a sun in the scene (issue 58): the sun's map is one yaw table
/// turned by the lighting keys, as the sky's is, so a turning shot makes two tables
/// whatever its frames (control: keyed by the turned sun, as before, it made one a frame,
/// six here, and the GPU held every one of them), and the light does turn.
#[test]
fn a_turning_light_with_a_sun_reads_one_table_for_the_sun() {
    let lighting = "[lighting]\nenv = \"uniform\"\nintensity = 0.35\n\
        [[lighting.key]]\ntime = 0.0\nyaw_deg = 0.0\n\
        [[lighting.key]]\ntime = 0.5\nyaw_deg = 90.0\n\
        [lighting.sun]\nazimuth_deg = -90.0\nelevation_deg = 25.0\nilluminance = 12.0\n";
    let walker = "[[instance]]\nposition = [0.0, 0.0, 0.0]\n";
    let turning = scene(lighting, walker, 0.5);
    let fixture = frf_testkit::tiny_field();
    let field = FieldFile::open(&fixture.field).unwrap();
    let all = turning
        .shot_frames(0..turning.frame_times().len(), (64, 48))
        .unwrap();
    assert!(all.len() >= 5);
    let options = planned_options();
    let mut shot = Shot::new(&turning, &field, device(), &all, options).unwrap();
    let mut lit = Vec::new();
    for f in &all {
        lit.push(shot.render(f, false).unwrap().frame.composite);
    }
    assert!(
        shot.counters().relights >= all.len() - 1,
        "{:?}",
        shot.counters()
    );
    assert_eq!(shot.counters().yaw_tables, 2, "{:?}", shot.counters());
    // The light does turn: the first and last frames differ.
    assert!(largest_difference(&lit[0], &lit[lit.len() - 1]) > 0.01);
}

/// Walkers of one pose between two poses share its motion (issue 58, the first frame):
/// the motion of views does not depend on their light, so a walker whose views another
/// walker's copy holds takes that copy's motion (one made per pose and direction,
/// whatever the walkers: control, before, one per walker); its shadow maps are read
/// once, not once a walker.
#[test]
fn walkers_of_one_pose_share_its_motion() {
    let dir = tempfile::tempdir().unwrap();
    let field = FieldFile::open(&two_pose_field(dir.path())).unwrap();
    // Three walkers facing three ways, whose frames after the first fall between the
    // field's two poses.
    let walkers = "[[instance]]\nposition = [-0.8, 0.0, 0.0]\nheading_deg = 0.0\n\
        [[instance]]\nposition = [0.0, 0.0, 0.0]\nheading_deg = 120.0\n\
        [[instance]]\nposition = [0.8, 0.0, 0.0]\nheading_deg = 240.0\n";
    let scene = scene(SKY, walkers, 0.3);
    let all = scene
        .shot_frames(0..scene.frame_times().len(), (64, 48))
        .unwrap();
    let drawn = |walkers: usize| {
        let options = ShotOptions {
            planned: false,
            ..planned_options()
        };
        let mut one = scene.clone();
        one.instances.truncate(walkers);
        let mut shot = Shot::new(&one, &field, device(), &all, options).unwrap();
        let between = all
            .iter()
            .map(|f| shot.render(f, false).unwrap().between)
            .filter(|b| b.iter().all(Option::is_some))
            .count();
        (between, shot.counters().clone())
    };
    let (between, one) = drawn(1);
    let (_, three) = drawn(3);
    assert!(between > 0, "no frame between poses");
    assert!(one.motions_made >= 2, "{one:?}");
    assert_eq!(three.poses_made_resident, 3 * one.poses_made_resident);
    assert_eq!(three.motions_made, one.motions_made, "{three:?}");
    // Their shadow maps (none in this field: looked for once a pose) read once a pose.
    assert!(one.shadow_maps_read >= 1, "{one:?}");
    assert_eq!(three.shadow_maps_read, one.shadow_maps_read, "{three:?}");
}
