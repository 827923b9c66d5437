//! The subject's motion between two captured poses (docs/design.md section 4.7), as
//! cameras see it: a view's pose-to-pose flow is in true pixels of both images, so it
//! holds the turntable's turn between the two instants as well as the walk.
//! [`subject_motion`] takes the turn out (the later camera's ray through the flow's end
//! meets the plane through the subject's axis facing the earlier camera, as the
//! inter-view flows are rectified; that point, seen by the earlier camera, is where the
//! subject moved), and [`motion_to_image`] turns metres across the subject's axis
//! (tangential to the circle of cameras) and up it into a camera's pixels, so that
//! [`view_motion_m`] can store a view's motion in the two directions every camera round
//! the grid sees alike. The renderer (`frf_render::motion`) and the export (the player's
//! morph in time) both take motion from here.

use glam::{Mat2, Vec2, Vec3};

use crate::camera::Camera;
use crate::filter::extend_nearest;
use crate::flo::UNKNOWN_THRESHOLD;
use crate::image::FlowImage;

/// The map from a subject motion at the axis (metres across the axis, tangential to the
/// circle of cameras, and metres up it) to the displacement `camera` sees (pixels),
/// linearised at its [`Camera::axis_point`]; zero where the camera does not see that
/// point.
pub fn motion_to_image(camera: &Camera) -> Mat2 {
    let p = camera.axis_point();
    let c = camera.centre();
    let radial = Vec3::new(c.x, 0.0, c.z);
    let across = if radial.length_squared() > 1e-8 {
        Vec3::Y.cross(radial).normalize()
    } else {
        // Straight above or below the axis: across is the camera's own right.
        let r = camera.world_from_camera.rotation.x_axis;
        Vec3::new(r.x, 0.0, r.z).try_normalize().unwrap_or(Vec3::X)
    };
    const STEP_M: f32 = 0.01;
    match (
        camera.project(p),
        camera.project(p + across * STEP_M),
        camera.project(p + Vec3::Y * STEP_M),
    ) {
        (Some(p0), Some(pa), Some(py)) => Mat2::from_cols((pa - p0) / STEP_M, (py - p0) / STEP_M),
        _ => Mat2::ZERO,
    }
}

/// The subject's motion in `camera`'s pixels seen at pixel `x` whose pose-to-pose flow is
/// `flow` toward the image of `later` (the turn between the cameras taken out; see the
/// module docs); `None` where the flow is unknown or the ray misses the plane.
pub fn subject_motion(camera: &Camera, later: &Camera, x: Vec2, flow: [f32; 2]) -> Option<Vec2> {
    if !(flow[0].abs() < UNKNOWN_THRESHOLD && flow[1].abs() < UNKNOWN_THRESHOLD) {
        return None;
    }
    let (point, normal) = (camera.axis_point(), camera.forward());
    let dir = later.ray_direction(x + Vec2::from(flow));
    let along = dir.dot(normal);
    if along.abs() < 1e-6 {
        return None;
    }
    let t = (point - later.centre()).dot(normal) / along;
    camera
        .project(later.centre() + dir * t)
        .map(|seen| seen - x)
        .filter(|m| m.is_finite())
}

/// The motion (metres across the axis and up it) of each texel of view `camera`, whose
/// pose-to-pose flow toward the image `later` filmed is `flow`; texel `k` of the
/// `width x height` result reads the flow at captured pixel `pixel(k)`. Beyond the known
/// flow each texel takes the nearest known one's motion (a limb's border moves with the
/// limb), zero where none is known; `None` when `camera` does not see the axis point.
pub fn view_motion_m(
    camera: &Camera,
    later: &Camera,
    flow: &FlowImage,
    (width, height): (usize, usize),
    pixel: impl Fn(usize) -> (usize, usize),
) -> Option<Vec<Vec2>> {
    let to_metres = motion_to_image(camera).inverse();
    if !to_metres.is_finite() {
        return None;
    }
    let mut metres: Vec<Option<Vec2>> = (0..width * height)
        .map(|k| {
            let (x, y) = pixel(k);
            let at = Vec2::new(x as f32, y as f32);
            subject_motion(camera, later, at, flow.get(x, y)).map(|m| to_metres * m)
        })
        .collect();
    extend_nearest(&mut metres, width, height, Option::is_some);
    Some(
        metres
            .into_iter()
            .map(|m| m.unwrap_or(Vec2::ZERO))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(azimuth_deg: f32, elevation_deg: f32) -> Camera {
        let target = Vec3::new(0.0, 0.9, 0.0);
        let eye = target
            + crate::light::direction_from_azimuth_elevation(
                azimuth_deg.to_radians(),
                elevation_deg.to_radians(),
            ) * 4.5;
        Camera::look_at(eye, target, Vec3::Y, 0.48, 64, 90).unwrap()
    }

    /// A point moving up the axis and across it is seen to move by what projecting it
    /// before and after says, by cameras anywhere round it.
    #[test]
    fn motion_maps_to_what_the_camera_sees() {
        for (az, el) in [(0.0, 0.0), (95.0, 10.0), (200.0, -20.0)] {
            let c = camera(az, el);
            let m = motion_to_image(&c);
            let p = c.axis_point();
            let radial = Vec3::new(c.centre().x, 0.0, c.centre().z);
            let across = Vec3::Y.cross(radial).normalize();
            let d = Vec2::new(0.004, -0.003);
            let seen = c.project(p + across * d.x + Vec3::Y * d.y).unwrap() - c.project(p).unwrap();
            assert!(
                (m * d - seen).length() < 0.01 * seen.length(),
                "{az}: {} vs {seen}",
                m * d
            );
        }
    }

    /// The turn between two cameras is no motion: a point on the plane stays put.
    #[test]
    fn the_turntables_turn_is_not_motion() {
        let (a, b) = (camera(17.0, 5.0), camera(17.4, 5.0));
        // A point of the plane through the axis facing `a` (across is square to its view).
        let across = Vec3::Y.cross(a.forward()).normalize();
        let p = a.axis_point() + across * 0.2;
        let x = a.project(p).unwrap();
        let flow = b.project(p).unwrap() - x;
        let m = subject_motion(&a, &b, x, flow.into()).unwrap();
        assert!(m.length() < 1e-3, "{m}");
        assert!(subject_motion(&a, &b, x, [2e10, 0.0]).is_none());
    }
}
