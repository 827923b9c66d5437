//! Camera paths and scenes at their limits (no GPU needed): keys a float step apart in
//! time, keys at one position, a single key, a single frame, a zero-length time range.
//! Every camera is finite and passes through the keys.

#![allow(clippy::unwrap_used)] // tests: a failed unwrap is a failed test

use frf_core::camera::Camera;
use frf_scene::Scene;
use frf_scene::path::{CameraPath, Key, Orbit, Trajectory};
use glam::Vec3;

fn key(time: f64, position: [f32; 3], look_at: [f32; 3]) -> Key {
    Key {
        time,
        position,
        look_at,
        fov_deg: 40.0,
    }
}

/// Every camera finite (centre, rotation, intrinsics).
fn assert_finite(cams: &[Camera]) {
    for c in cams {
        let r = c.world_from_camera.rotation;
        let k = c.intrinsics;
        assert!(
            c.centre().is_finite()
                && r.is_finite()
                && [k.fx, k.fy, k.cx, k.cy].iter().all(|v| v.is_finite()),
            "{c:?}"
        );
    }
}

#[test]
fn keys_a_float_step_apart_in_time_give_finite_cameras_through_both_keys() {
    // Keys 1 ulp apart at t = 1, and a subnormal 1.4e-45 s apart at t = 0: valid
    // (strictly increasing) paths. The Hermite segment between them must still start at
    // the first key and end at the second, and stay finite everywhere (before the fix
    // the subnormal span gave an infinite tangent, times a zero Hermite weight: NaN).
    let (p0, p1, p2) = ([1.0, 1.2, 3.0], [-1.0, 1.4, 3.0], [0.0, 1.3, -3.0]);
    let target = [0.0, 0.9, 0.0];
    for (t0, t1) in [(1.0f64, 1.0f64.next_up()), (0.0, f64::from_bits(1))] {
        let path = CameraPath::new(vec![
            key(t0, p0, target),
            key(t1, p1, target),
            key(t1 + 2.0, p2, target),
        ])
        .unwrap();
        let cams = path.cameras(9, 16, 12).unwrap();
        assert_finite(&cams);
        assert!((cams[0].centre() - Vec3::from(p0)).length() < 1e-5);
        assert!((cams[8].centre() - Vec3::from(p2)).length() < 1e-5);
        let mid = path.at(t1);
        assert!((Vec3::from(mid.position) - Vec3::from(p1)).length() < 1e-5);
    }
    // The same keys at one and the same time are refused, naming the key.
    let e = CameraPath::new(vec![key(1.0, p0, target), key(1.0, p1, target)]).unwrap_err();
    assert!(e.to_string().contains("key 1"), "{e}");
}

#[test]
fn keys_at_one_position_hold_the_camera_there() {
    // Three keys at the same position (looking at different points): every tangent of
    // the position is 0 and the Hermite weights of the two ends sum to 1, so the
    // centre stays at the key's position (1e-6, a few roundings of values ≤ 3).
    let p = [2.0, 1.5, 3.0];
    let path = CameraPath::new(vec![
        key(0.0, p, [0.0, 0.9, 0.0]),
        key(0.5, p, [0.5, 1.0, 0.0]),
        key(2.0, p, [-0.5, 0.8, 0.2]),
    ])
    .unwrap();
    let cams = path.cameras(41, 16, 12).unwrap();
    assert_finite(&cams);
    for c in &cams {
        assert!(
            (c.centre() - Vec3::from(p)).length() < 1e-6,
            "{}",
            c.centre()
        );
    }
}

#[test]
fn a_single_key_or_a_single_frame_gives_the_keys_camera() {
    // A one-key path spans no time: every time and every frame is that key.
    let k = key(3.0, [1.0, 1.2, 3.0], [0.0, 0.9, 0.0]);
    let still = CameraPath::new(vec![k]).unwrap();
    assert_eq!(still.span(), (3.0, 3.0));
    let want = k.camera(16, 12).unwrap();
    for c in still.cameras(5, 16, 12).unwrap() {
        assert_eq!(c, want);
    }
    for t in [-1e30, 0.0, 3.0, 1e30] {
        assert_eq!(still.at(t), k);
    }
    // One frame of a longer path: its first key.
    let path = CameraPath::new(vec![k, key(4.0, [-1.0, 1.2, 3.0], [0.0, 0.9, 0.0])]).unwrap();
    assert_eq!(path.cameras(1, 16, 12).unwrap(), vec![want]);
    // One frame of an orbit: its start, exactly on its circle.
    let orbit = Orbit {
        radius: 3.0,
        height: 1.4,
        start_deg: 90.0,
        sweep_deg: 360.0,
        look_at: Vec3::new(0.0, 0.9, 0.0),
        fov_deg: 30.0,
    };
    let one = Trajectory::Orbit(orbit).cameras(1, 16, 12).unwrap();
    assert_eq!(one.len(), 1);
    assert!((one[0].centre() - Vec3::new(3.0, 1.4, 0.0)).length() < 1e-5);
}

const SCENE: &str = r#"
field = "walker.frf"

[time]
start = 2.0
end = 2.0
fps = 24

[lighting]
env = "sky"

[camera]
orbit = { radius = 3.0, height = 1.4 }
"#;

#[test]
fn a_scene_of_zero_length_or_of_one_frame_renders_one_finite_camera() {
    // start = end: a still, one frame at the start, the orbit at its first azimuth
    // (0°, on +z: centre (0, 1.4, 3)) rather than a division by the zero span.
    let path = std::path::Path::new("/shots/stiff/scene.toml");
    let still = Scene::parse(path, SCENE).unwrap();
    assert_eq!(still.frame_times(), vec![2.0]);
    for t in [2.0, 2.0f64.next_up(), 1e6] {
        let c = still.camera_at(t, (32, 18)).unwrap();
        assert!(
            (c.centre() - Vec3::new(0.0, 1.4, 3.0)).length() < 1e-5,
            "{t}: {c:?}"
        );
    }
    // Shorter than one frame (0.01 s at 24 fps): one frame, at the start.
    let short = Scene::parse(path, &SCENE.replace("end = 2.0", "end = 2.01")).unwrap();
    assert_eq!(short.frame_times(), vec![2.0]);
    assert_finite(&[short.camera_at(2.0, (32, 18)).unwrap()]);
    // Exactly one frame long: one frame, not two (the end is exclusive).
    let one = Scene::parse(
        path,
        &SCENE
            .replace("fps = 24", "fps = 0.5")
            .replace("end = 2.0", "end = 4.0"),
    )
    .unwrap();
    assert_eq!(one.frame_times(), vec![2.0]);
}
