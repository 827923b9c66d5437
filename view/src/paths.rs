//! The walkers' paths drawn over the frame: each walker on a path as a line on the ground
//! where it walks (sampled along the path), and a mark where it stands at the viewer's
//! time, seen by the viewer's camera and placed in the window as the frame is
//! (letterboxed, [`frf_render::gpu::present::letterbox`]). The time slider scrubs the
//! walkers along them.

use frf_core::camera::Camera;
use frf_render::gpu::present::letterbox;
use frf_scene::Scene;
use glam::Vec2;

/// Points sampled along each path, every this many seconds of its keys' span.
pub const SAMPLE_S: f64 = 1.0 / 30.0;

/// The most points a path is drawn with (a path hours long is drawn coarser).
const MOST_POINTS: usize = 4096;

/// One walker's path as the window shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct PathOverlay {
    /// The walker.
    pub walker: usize,
    /// Runs of consecutive points in front of the camera, window pixels.
    pub runs: Vec<Vec<Vec2>>,
    /// Where it stands now, window pixels (when in front of the camera).
    pub now: Option<Vec2>,
}

/// The paths of `scene`'s walkers that walk one, seen by `camera` (frames of its size)
/// in a window of `window` pixels, at time `time`.
pub fn overlays(scene: &Scene, camera: &Camera, window: (u32, u32), time: f64) -> Vec<PathOverlay> {
    let (origin, extent) = letterbox((camera.width, camera.height), window);
    let scale = extent[0] / camera.width.max(1) as f32;
    let to_window = |p: glam::Vec3| {
        camera
            .project(p)
            .map(|px| Vec2::new(origin[0], origin[1]) + (px + 0.5) * scale)
    };
    let mut out = Vec::new();
    for (i, w) in scene.instances.iter().enumerate() {
        let Some(path) = w.path.as_ref().filter(|p| !p.is_still()) else {
            continue;
        };
        let (t0, t1) = path.span();
        let n = (((t1 - t0) / SAMPLE_S).ceil() as usize).clamp(1, MOST_POINTS);
        let mut runs: Vec<Vec<Vec2>> = vec![Vec::new()];
        for k in 0..=n {
            let t = t0 + (t1 - t0) * k as f64 / n as f64;
            match to_window(path.position(t)) {
                Some(p) => runs.last_mut().expect("one run at least").push(p),
                None if runs.last().is_some_and(|r| !r.is_empty()) => runs.push(Vec::new()),
                None => {}
            }
        }
        runs.retain(|r| r.len() > 1);
        out.push(PathOverlay {
            walker: i,
            runs,
            now: to_window(scene.placement(i, time).position),
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn a_path_is_drawn_where_the_camera_sees_it_and_the_walker_on_it() {
        let text = "[time]\nend = 2.0\nfps = 10\n[lighting]\nenv = \"sky\"\n\
            [camera]\norbit = { radius = 3.0, height = 1.4 }\n\
            [[instance]]\n[[instance.key]]\ntime = 0.0\nposition = [-1.0, 0.0, 0.0]\n\
            [[instance.key]]\ntime = 2.0\nposition = [1.0, 0.0, 0.0]\n\
            [[instance]]\nposition = [0.5, 0.0, 0.5]\n";
        let scene = Scene::parse(Path::new("/s.toml"), text).unwrap();
        let camera = Camera::look_at(
            glam::Vec3::new(0.0, 1.5, 4.0),
            glam::Vec3::new(0.0, 0.5, 0.0),
            glam::Vec3::Y,
            0.8,
            200,
            100,
        )
        .unwrap();
        // A window twice as wide as the frame's aspect: bars left and right.
        let o = overlays(&scene, &camera, (800, 200), 1.0);
        assert_eq!(o.len(), 1, "the standing walker has no path");
        assert_eq!(o[0].walker, 0);
        let run = &o[0].runs[0];
        assert_eq!(run.len(), 61);
        // Left to right across the frame's 400 pixels in the middle of the window.
        assert!(run[0].x < run[60].x);
        assert!(run.iter().all(|p| p.x > 200.0 && p.x < 600.0), "{run:?}");
        // Half way along it at 1 s: at the middle of the window.
        let now = o[0].now.unwrap();
        assert!((now.x - 400.0).abs() < 2.0, "{now}");
    }
}
