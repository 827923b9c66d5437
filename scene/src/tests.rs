//! Scene files: what they accept, what they refuse (naming the field and line), and the
//! frame times, cameras, lighting and poses they ask for.

use std::path::Path;

use super::*;
use glam::Vec3;

const MINIMAL: &str = r#"
field = "walker.frf"

[time]
end = 1.0
fps = 10

[lighting]
env = "sky"

[camera]
orbit = { radius = 3.0, height = 1.4 }
"#;

fn scene(text: &str) -> Result<Scene> {
    Scene::parse(Path::new("/shots/a/scene.toml"), text)
}

fn error(text: &str) -> String {
    scene(text).unwrap_err().to_string()
}

#[test]
fn a_minimal_scene_gets_its_defaults() {
    let s = scene(MINIMAL).unwrap();
    assert_eq!(
        s.field,
        Some(Path::new("/shots/a/walker.frf").to_path_buf())
    );
    assert_eq!(s.frame_times().len(), 10);
    assert_eq!(s.instances.len(), 1);
    assert_eq!(s.variant, Variant::FourWay);
    assert_eq!(s.preview, Preview::Apng);
    assert_eq!(s.backdrop, BackdropSpec::None);
    assert_eq!(s.shadow, ShadowSpec::Maps);
    assert_eq!(s.lighting.len(), 1);
    // The orbit sweeps the time range and loops.
    let c0 = s.camera_at(0.0, (32, 18)).unwrap().centre();
    let c_end = s.camera_at(1.0, (32, 18)).unwrap().centre();
    assert!((c0 - c_end).length() < 1e-4);
}

/// Times near 10^6 s (issue 35): held in 32 bits they resolved 1/16 s, so that `start =
/// 1e6, end = 1e6 + 0.1` at 30 fps gave 4 frames, two at one instant and the last at the
/// exclusive end, and a walker 10^6 s ahead froze every other frame. In 64 bits: 3
/// distinct frames `start + i / fps`, every one before `end`, and a walk that moves.
#[test]
fn times_far_from_zero_keep_their_frames_apart_and_the_walk_moving() {
    let late = MINIMAL.replace(
        "end = 1.0\nfps = 10",
        "start = 1e6\nend = 1000000.1\nfps = 30",
    );
    let s = scene(&late).unwrap();
    let t = s.frame_times();
    assert_eq!(t.len(), 3, "{t:?}");
    for (i, &ti) in t.iter().enumerate() {
        assert_eq!(ti, 1e6 + i as f64 / 30.0);
        assert!(ti < s.end);
    }
    // Beyond 10^9 s f64 no longer keeps microseconds: refused, naming the key.
    let e = error(&MINIMAL.replace("end = 1.0", "start = 1e12\nend = 1e12"));
    assert!(e.contains("time.start") && e.contains("within"), "{e}");
    // Whole frame counts stay whole: 0 to 1 s at 10 fps is 10 frames, the last at 0.9 s.
    let ten = scene(MINIMAL).unwrap().frame_times();
    assert_eq!((ten.len(), ten[9]), (10, 0.9));

    let ahead = format!("{MINIMAL}\n[[instance]]\ntime_offset = 1e6\n")
        .replace("end = 1.0\nfps = 10", "end = 0.2\nfps = 60");
    let s = scene(&ahead).unwrap();
    let poses: Vec<u32> = s
        .frame_times()
        .iter()
        .map(|&t| s.pose_at(0, t, &Gait::new(1.0, None), 300))
        .collect();
    // 300 poses a second at 60 fps: five poses a frame, every frame another.
    assert!(poses.windows(2).all(|w| w[0] != w[1]), "{poses:?}");
}

#[test]
fn a_zero_length_range_is_a_still_and_a_reversed_one_is_refused() {
    let still = MINIMAL.replace("end = 1.0", "start = 2.0\nend = 2.0");
    assert_eq!(scene(&still).unwrap().frame_times(), vec![2.0]);
    let e = error(&MINIMAL.replace("end = 1.0", "start = 2.0\nend = 1.0"));
    assert!(
        e.contains("time.end") && e.contains("line 6") && e.contains("scene.toml"),
        "{e}"
    );
}

#[test]
fn errors_name_the_field_and_its_line() {
    let e = error(&MINIMAL.replace("fps = 10", "fps = -3"));
    assert!(e.contains("time.fps") && e.contains("line 6"), "{e}");
    let e = error(&MINIMAL.replace("fps = 10", "fps = \"ten\""));
    assert!(e.contains("line 6"), "{e}");
    let e = error(&format!("{MINIMAL}\n[composite]\nbackdrop = \"wall\"\n"));
    assert!(
        e.contains("composite.backdrop") && e.contains("wall") && e.contains("line 15"),
        "{e}"
    );
    let e = error(&format!("{MINIMAL}\n[output]\nsize = [0, 10]\n"));
    assert!(e.contains("output.size"), "{e}");
    let e = error(&MINIMAL.replace("[time]", "[time]\nspeed = 2"));
    assert!(e.contains("speed") && e.contains("line 5"), "{e}");
    let e = error(&MINIMAL.replace("orbit = { radius = 3.0, height = 1.4 }", ""));
    assert!(e.contains("camera") && e.contains("orbit or keys"), "{e}");
    let e = error(&format!(
        "{MINIMAL}\n[composite]\nground = 2.0\nbackdrop = \"env\"\n"
    ));
    assert!(e.contains("composite.ground"), "{e}");
    let e = error(&format!(
        "{MINIMAL}\n[[instance]]\nposition = [0.0, 1.0, 0.0]\n"
    ));
    assert!(e.contains("instance[0]") && e.contains("ground"), "{e}");
}

/// A light's yaw of any size is the turn it names mod 360, reduced in double precision
/// (1e9° is -80°: the f32 radians it was turned by missed it by degrees), while keys more
/// than half a turn apart still turn the light that far between them (0° to 720°: two
/// turns); a yaw or a sun's azimuth beyond the stated range is refused naming the field.
#[test]
fn a_yaw_is_the_turn_it_names_and_keys_turn_as_far_as_they_say() {
    let at = |yaw: &str| {
        let text = MINIMAL.replace("env = \"sky\"", &format!("env = \"sky\"\nyaw_deg = {yaw}"));
        scene(&text).unwrap().lighting_at(0.0).yaw
    };
    assert_eq!(at("1e9"), (-80f32).to_radians());
    assert_eq!(at("1e15"), at("-80.0"));
    assert_eq!(at("30.0"), 30f32.to_radians());
    let text = MINIMAL.replace(
        "env = \"sky\"",
        "env = \"sky\"\n[[lighting.key]]\ntime = 0.0\nyaw_deg = 0.0\n[[lighting.key]]\ntime = 1.0\nyaw_deg = 720.0",
    );
    let s = scene(&text).unwrap();
    for (t, deg) in [
        (0.125f64, 90.0f32),
        (0.375, -90.0),
        (0.625, 90.0),
        (0.875, -90.0),
    ] {
        let yaw = s.lighting_at(t).yaw;
        assert!((yaw - deg.to_radians()).abs() < 1e-5, "t {t}: {yaw}");
    }
    for (field, text) in [
        (
            "yaw_deg",
            MINIMAL.replace("env = \"sky\"", "env = \"sky\"\nyaw_deg = 1e16"),
        ),
        (
            "azimuth_deg",
            MINIMAL.replace(
                "env = \"sky\"",
                "env = \"sky\"\nsun = { azimuth_deg = 1e20, elevation_deg = 30.0 }",
            ),
        ),
    ] {
        let e = error(&text);
        assert!(e.contains(field) && e.contains("beyond"), "{e}");
    }
}

/// A lone sun (`env = "none"` and a sun: a black sky it lights) is turned by yaw keys like
/// any light (it was refused as "`none` cannot be keyframed"); `none` without a sun, the
/// field shown unlit, still cannot be keyed.
#[test]
fn a_lone_sun_is_turned_by_yaw_keys() {
    let keys = "\n[[lighting.key]]\ntime = 0.0\nyaw_deg = 0.0\n[[lighting.key]]\ntime = 1.0\nyaw_deg = 90.0";
    let sun = "\nsun = { azimuth_deg = 0.0, elevation_deg = 30.0, illuminance = 10.0 }";
    let text = MINIMAL.replace("env = \"sky\"", &format!("env = \"none\"{sun}{keys}"));
    let s = scene(&text).unwrap();
    let at = |t: f64| s.lighting_at(t).sun.unwrap().direction();
    let (start, half) = (at(0.0), at(0.5));
    // Azimuth 0 is +z; a yaw of 45° turns it toward +x.
    assert!(start.x.abs() < 1e-5 && start.z > 0.8, "{start}");
    assert!((half.x - half.z).abs() < 1e-4 && half.x > 0.5, "{half}");
    let e = error(&MINIMAL.replace("env = \"sky\"", &format!("env = \"none\"{keys}")));
    assert!(
        e.contains("cannot be keyframed") && e.contains("give a sun"),
        "{e}"
    );
}

#[test]
fn lighting_keys_interpolate_and_cross_fade_maps() {
    let text = MINIMAL.replace(
        "env = \"sky\"",
        "env = \"sky\"\nyaw_deg = 0.0\n[[lighting.key]]\ntime = 0.0\n[[lighting.key]]\ntime = 1.0\nenv = \"uniform\"\nyaw_deg = 90.0\nintensity = 3.0",
    );
    let s = scene(&text).unwrap();
    let mid = s.lighting_at(0.25);
    assert_eq!(mid.maps.len(), 2);
    assert!((mid.maps[1].1 - 0.25).abs() < 1e-6);
    assert!((mid.yaw - 22.5f32.to_radians()).abs() < 1e-5);
    assert!((mid.intensity - 1.5).abs() < 1e-5);
    let end = s.lighting_at(5.0);
    assert_eq!(end.maps, vec![(EnvSource::Uniform, 1.0)]);
    let before = s.lighting_at(-1.0);
    assert_eq!(before.maps, vec![(EnvSource::Sky, 1.0)]);
    // Keys out of order are refused.
    let bad = text.replace("time = 1.0", "time = 0.0");
    assert!(error(&bad).contains("lighting.key[1].time"));
}

#[test]
fn a_sun_in_the_lighting_turns_and_scales_with_it_and_bad_suns_are_refused_by_name() {
    let with = |sun: &str| {
        MINIMAL.replace(
            "env = \"sky\"",
            &format!("env = \"sky\"\nyaw_deg = 90.0\nintensity = 2.0\nsun = {{ {sun} }}"),
        )
    };
    let s = scene(&with(
        "azimuth_deg = 0.0, elevation_deg = 30.0, illuminance = 5.0",
    ))
    .unwrap();
    let sun = s.lighting_at(0.0).sun.unwrap();
    // Azimuth 0 is +z; a yaw of 90° turns it to +x; intensity 2 doubles it.
    let d = sun.direction();
    assert!(
        (d.x - 30f32.to_radians().cos()).abs() < 1e-5 && d.z.abs() < 1e-5,
        "{d}"
    );
    assert!((sun.illuminance()[0] - 10.0).abs() < 1e-5);
    assert!((sun.radius().to_degrees() - 0.265).abs() < 1e-4);
    // A radiance is its disc's solid angle times as much illuminance.
    let s = scene(&with(
        "direction = [0.0, 1.0, 0.0], radiance = 1000.0, angular_diameter_deg = 2.0",
    ))
    .unwrap();
    let e = s.sun.unwrap().illuminance()[0];
    assert!(
        (e - 1000.0 * frf_core::sun::Sun::solid_angle(2.0)).abs() < 1e-3,
        "{e}"
    );
    for (sun, field) in [
        (
            "azimuth_deg = 0.0, elevation_deg = 95.0, illuminance = 1.0",
            "lighting.sun.elevation_deg",
        ),
        (
            "elevation_deg = 30.0, illuminance = 1.0",
            "lighting.sun.direction",
        ),
        (
            "direction = [0.0, 0.0, 0.0], illuminance = 1.0",
            "lighting.sun.direction",
        ),
        (
            "direction = [0.0, 1.0, 0.0], angular_diameter_deg = 40.0, illuminance = 1.0",
            "lighting.sun.angular_diameter_deg",
        ),
        (
            "direction = [0.0, 1.0, 0.0], illuminance = -1.0",
            "lighting.sun.illuminance",
        ),
        (
            "direction = [0.0, 1.0, 0.0], illuminance = nan",
            "lighting.sun.illuminance",
        ),
        ("direction = [0.0, 1.0, 0.0]", "lighting.sun.illuminance"),
        (
            "direction = [0.0, 1.0, 0.0], illuminance = 1.0, colour = [1.0, -1.0, 1.0]",
            "lighting.sun.colour",
        ),
    ] {
        let e = error(&with(sun));
        assert!(e.contains(field), "{sun}: {e}");
    }
    assert!(
        error(&with(
            "direction = [0.0, 1.0, 0.0], illuminance = 1.0, size = 2"
        ))
        .contains("size")
    );
}

#[test]
fn poses_follow_the_walk_cycle_with_each_walker_s_offset() {
    let text = format!(
        "{MINIMAL}\n[[instance]]\n[[instance]]\nposition = [1.0, 0.0, 0.0]\ntime_offset = 0.5\n"
    );
    let s = scene(&text).unwrap();
    // A 1 s cycle of 30 poses.
    assert_eq!(s.pose_at(0, 0.0, &Gait::new(1.0, None), 30), 0);
    assert_eq!(s.pose_at(0, 0.1, &Gait::new(1.0, None), 30), 3);
    assert_eq!(s.pose_at(1, 0.0, &Gait::new(1.0, None), 30), 15);
    // Looping, and nearest: 0.99 s rounds to pose 30, which is pose 0.
    assert_eq!(s.pose_at(0, 0.99, &Gait::new(1.0, None), 30), 0);
    assert_eq!(s.pose_at(0, 2.1, &Gait::new(1.0, None), 30), 3);
    // The second walker's frame: a camera at its position sees it from its origin.
    let cam = Camera::look_at(
        Vec3::new(1.0, 1.5, 4.0),
        Vec3::new(1.0, 0.9, 0.0),
        Vec3::Y,
        0.6,
        8,
        8,
    )
    .unwrap();
    let seen = s.placement(1, 0.0).camera_in_subject_frame(&cam);
    assert!((seen.centre() - Vec3::new(0.0, 1.5, 4.0)).length() < 1e-5);
}

#[test]
fn a_plate_needs_one_camera_key() {
    let text = format!("{MINIMAL}\n[composite]\nbackdrop = \"plate\"\nplate = \"p.png\"\n");
    assert!(error(&text).contains("one camera key"));
    let keyed = text.replace(
        "orbit = { radius = 3.0, height = 1.4 }",
        "[[camera.key]]\ntime = 0.0\nposition = [0.0, 1.5, 4.0]\nlook_at = [0.0, 0.9, 0.0]\nfov_deg = 30.0",
    );
    let s = scene(&keyed).unwrap();
    assert_eq!(
        s.backdrop,
        BackdropSpec::Plate(Path::new("/shots/a/p.png").to_path_buf())
    );
}

#[test]
fn keyed_lighting_may_leave_the_base_environment_to_its_first_key() {
    // Issue 23: the base `env` was demanded even when the keys name the maps.
    let keyed = MINIMAL.replace(
        "env = \"sky\"",
        "[[lighting.key]]\ntime = 0.0\nenv = \"uniform\"\n[[lighting.key]]\ntime = 1.0\nenv = \"sky\"",
    );
    let s = scene(&keyed).unwrap();
    assert_eq!(s.lighting[0].env, EnvSource::Uniform);
    assert_eq!(s.lighting_at(0.0).maps, vec![(EnvSource::Uniform, 1.0)]);
    assert_eq!(s.lighting_at(1.0).maps, vec![(EnvSource::Sky, 1.0)]);
    // Neither a base environment nor one in the first key: said, with the way out.
    let none = MINIMAL.replace("env = \"sky\"", "yaw_deg = 10.0");
    let e = error(&none);
    assert!(
        e.contains("lighting.env") && e.contains("no environment"),
        "{e}"
    );
}

#[test]
fn time_interpolation_is_read_and_a_bad_one_refused() {
    assert_eq!(scene(MINIMAL).unwrap().interpolate, None);
    let with = |v: &str| MINIMAL.replace("fps = 10", &format!("fps = 10\ninterpolate = \"{v}\""));
    assert_eq!(
        scene(&with("flow")).unwrap().interpolate,
        Some(TimeInterpolation::Flow)
    );
    assert_eq!(
        scene(&with("nearest")).unwrap().interpolate,
        Some(TimeInterpolation::Nearest)
    );
    let e = error(&with("blend"));
    assert!(e.contains("time.interpolate") && e.contains("blend"), "{e}");
}

#[test]
fn a_time_between_poses_finds_both_and_the_fraction() {
    use super::plan::poses_around;
    let held = [0, 3, 6, 27];
    assert_eq!(poses_around(0.0, &held, 30), (0, None));
    assert_eq!(poses_around(1.5, &held, 30), (0, Some((3, 0.5))));
    assert_eq!(poses_around(4.0, &held, 30), (3, Some((6, 1.0 / 3.0))));
    // Round the cycle: from the last pose held to the first.
    assert_eq!(poses_around(28.5, &held, 30), (27, Some((0, 0.5))));
    // At a pose, to a thousandth of its step, that pose alone.
    assert_eq!(poses_around(5.9999, &held, 30), (6, None));
    assert_eq!(poses_around(3.0001, &held, 30), (3, None));
    // One pose held: that pose at every instant.
    assert_eq!(poses_around(12.5, &[4], 30), (4, None));
}

#[test]
fn only_rays_near_the_subject_may_see_it() {
    use frf_render::footprint::SubjectBounds;
    let may_see_subject = |o, d| SubjectBounds::DESIGN.may_see(o, d);
    let eye = Vec3::new(0.0, 1.5, 12.0);
    // Straight at the body, over its head, beside it, and down onto its feet.
    assert!(may_see_subject(
        eye,
        (Vec3::new(0.0, 1.0, 0.0) - eye).normalize()
    ));
    assert!(!may_see_subject(
        eye,
        (Vec3::new(0.0, 3.5, 0.0) - eye).normalize()
    ));
    assert!(!may_see_subject(
        eye,
        (Vec3::new(2.0, 1.0, 0.0) - eye).normalize()
    ));
    assert!(may_see_subject(
        eye,
        (Vec3::new(0.5, 0.0, 0.3) - eye).normalize()
    ));
    // Looking away, and from inside the bounds.
    assert!(!may_see_subject(eye, Vec3::Z));
    assert!(may_see_subject(Vec3::new(0.2, 1.0, 0.0), Vec3::Z));
}

/// Walkers on paths and light probes in scene files: what they accept, and what they
/// refuse naming the walker's key or the probe and the line.
#[test]
fn paths_and_probes_are_read_and_bad_ones_refused_by_name() {
    let path = format!(
        "{MINIMAL}\n[[instance]]\ntime_offset = 0.2\n\
         [[instance.key]]\ntime = 0.0\nposition = [-1.0, 0.0, 0.0]\n\
         [[instance.key]]\ntime = 1.0\nposition = [0.0, 0.0, 1.0]\n"
    );
    let s = scene(&path).unwrap();
    // Two keys: a straight line, walked without turning.
    assert!(s.instances[0].moves() && !s.instances[0].turns());
    let at = s.placement(0, 1.0).position;
    assert!((at - Vec3::new(0.0, 0.0, 1.0)).length() < 1e-5, "{at}");
    // Phase from the distance walked: 1.2 m a cycle.
    let gait = Gait::new(1.0, Some(1.2));
    let walked = s.instances[0].path.as_ref().unwrap().distance(1.0);
    let want = (0.2 + walked / 1.2).rem_euclid(1.0);
    assert!((s.phase_at(0, 1.0, &gait) - want).abs() < 1e-9);

    let one_key = format!(
        "{MINIMAL}\n[[instance]]\n[[instance.key]]\ntime = 0.0\nposition = [0.0, 0.0, 0.0]\n"
    );
    let e = error(&one_key);
    assert!(
        e.contains("instance[0].key[0]") && e.contains("at least two keys"),
        "{e}"
    );
    let out_of_order = path.replace(
        "time = 1.0\nposition = [0.0",
        "time = -1.0\nposition = [0.0",
    );
    let e = error(&out_of_order);
    assert!(
        e.contains("instance[0].key[1]") && e.contains("does not follow"),
        "{e}"
    );
    assert!(e.contains("line"), "{e}");
    let nan = path.replace("[-1.0, 0.0, 0.0]", "[nan, 0.0, 0.0]");
    let e = error(&nan);
    assert!(
        e.contains("instance[0].key[0]") && e.contains("not finite"),
        "{e}"
    );
    let fast = path.replace(
        "time = 1.0\nposition = [0.0, 0.0, 1.0]",
        "time = 1.0\nposition = [900.0, 0.0, 1.0]",
    );
    let e = error(&fast);
    assert!(e.contains("m/s") && e.contains("instance[0].key[1]"), "{e}");
    let both = path.replace(
        "time_offset = 0.2\n",
        "time_offset = 0.2\nposition = [1.0, 0.0, 0.0]\n",
    );
    let e = error(&both);
    assert!(
        e.contains("instance[0].key") && e.contains("not position"),
        "{e}"
    );

    let probes = format!(
        "{MINIMAL}\n[[lighting.probe]]\nposition = [1.0, 1.2, 0.0]\nenv = \"sky\"\n\
         [[lighting.probe]]\nposition = [-1.0, 1.2, 0.0]\nenv = \"uniform\"\nsuns = false\n"
    );
    let s = scene(&probes).unwrap();
    let p = s.probes.as_ref().unwrap();
    assert_eq!(p.probes.len(), 2);
    assert!(!p.probes[1].suns);
    // The walker at the origin: half of each.
    let w = s.probe_weights(0, 0.0);
    assert!(w.iter().all(|&(_, x)| (x - 0.5).abs() < 1e-6), "{w:?}");
    let no_map = probes.replace("env = \"uniform\"", "env = \"none\"");
    let e = error(&no_map);
    assert!(
        e.contains("lighting.probe[1].env") && e.contains("needs a map"),
        "{e}"
    );
    let missing = probes.replace("env = \"uniform\"\n", "");
    let e = error(&missing);
    assert!(e.contains("env"), "{e}");
    let same = probes.replace("[-1.0, 1.2, 0.0]", "[1.0, 0.5, 0.0]");
    let e = error(&same);
    assert!(
        e.contains("lighting.probe[1]") && e.contains("probe 0"),
        "{e}"
    );
}
