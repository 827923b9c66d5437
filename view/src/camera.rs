//! The viewer's camera: a point looked at, the camera's distance from it and its
//! direction (azimuth about `+y` from `+z` toward `+x`, as an orbit's; elevation above
//! the horizon), and a vertical field of view. Orbiting turns the camera about the point,
//! dollying changes the distance, panning and flying move the point (and the camera with
//! it), looking turns the camera in place. A camera is a camera path's [`Key`], so what the
//! viewer shows is what `frf render` draws of the same key.

use frf_core::camera::Camera;
use frf_scene::path::Key;
use glam::Vec3;

/// Steepest elevation, radians: the camera never looks straight down or up (where `+y`
/// cannot be its up).
const MAX_ELEVATION: f32 = 89.0 * std::f32::consts::PI / 180.0;
/// Nearest and farthest distance to the point looked at, metres.
const DISTANCE: (f32, f32) = (0.05, 200.0);
/// Narrowest and widest vertical field of view, degrees.
const FOV_DEG: (f32, f32) = (2.0, 150.0);

/// The viewer's camera (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewCamera {
    /// The point looked at, metres.
    pub target: Vec3,
    /// Distance from the camera to `target`, metres.
    pub distance: f32,
    /// Direction from `target` to the camera about `+y`, radians (0 on `+z`).
    pub azimuth: f32,
    /// Its elevation above the horizontal, radians.
    pub elevation: f32,
    /// Vertical field of view, degrees.
    pub fov_deg: f32,
}

/// The unit direction of `azimuth` and `elevation`.
fn direction(azimuth: f32, elevation: f32) -> Vec3 {
    Vec3::new(
        azimuth.sin() * elevation.cos(),
        elevation.sin(),
        azimuth.cos() * elevation.cos(),
    )
}

impl ViewCamera {
    /// The camera at `position` looking at `target` with a vertical field of view of
    /// `fov_deg`; `None` when they coincide or are not finite.
    pub fn looking(position: Vec3, target: Vec3, fov_deg: f32) -> Option<Self> {
        let d = position - target;
        let distance = d.length();
        if !(distance > 1e-6 && distance.is_finite() && target.is_finite()) {
            return None;
        }
        let u = d / distance;
        let mut c = Self {
            target,
            distance,
            azimuth: u.x.atan2(u.z),
            elevation: u.y.clamp(-1.0, 1.0).asin(),
            fov_deg,
        };
        c.clamp();
        Some(c)
    }

    /// A captured camera's centre and view direction, looking at the point of its view
    /// axis nearest the vertical axis through `axis_at` (the subject's), with its vertical
    /// field of view.
    pub fn of_camera(camera: &Camera, axis_at: Vec3) -> Option<Self> {
        let c = camera.centre();
        let f = camera.forward();
        // Along the view ray, the point nearest the vertical axis (horizontally).
        let (cx, fx) = (
            glam::Vec2::new(c.x - axis_at.x, c.z - axis_at.z),
            glam::Vec2::new(f.x, f.z),
        );
        let along = if fx.length_squared() > 1e-6 {
            (-cx.dot(fx) / fx.length_squared()).max(0.1)
        } else {
            cx.length().max(1.0)
        };
        Self::looking(c, c + f * along, camera.vertical_fov().to_degrees())
    }

    /// Where the camera is.
    pub fn position(&self) -> Vec3 {
        self.target + self.distance * direction(self.azimuth, self.elevation)
    }

    /// The camera path key of this camera at `time`.
    pub fn key(&self, time: f64) -> Key {
        Key {
            time,
            position: self.position().to_array(),
            look_at: self.target.to_array(),
            fov_deg: self.fov_deg,
        }
    }

    /// The camera of `width x height` frames, as `frf render` makes it of [`Self::key`].
    pub fn camera(&self, width: u32, height: u32) -> frf_scene::Result<Camera> {
        self.key(0.0).camera(width, height)
    }

    fn clamp(&mut self) {
        self.elevation = self.elevation.clamp(-MAX_ELEVATION, MAX_ELEVATION);
        self.distance = self.distance.clamp(DISTANCE.0, DISTANCE.1);
        self.fov_deg = self.fov_deg.clamp(FOV_DEG.0, FOV_DEG.1);
        self.azimuth = self.azimuth.rem_euclid(std::f32::consts::TAU);
    }

    /// Turns the camera about the point looked at, radians.
    pub fn orbit(&mut self, azimuth: f32, elevation: f32) {
        self.azimuth += azimuth;
        self.elevation += elevation;
        self.clamp();
    }

    /// Moves the camera toward the point looked at (`factor < 1`) or away from it.
    pub fn dolly(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.distance *= factor;
            self.clamp();
        }
    }

    /// The camera's right and up directions.
    fn frame(&self) -> (Vec3, Vec3, Vec3) {
        let forward = -direction(self.azimuth, self.elevation);
        let right = forward.cross(Vec3::Y).normalize_or_zero();
        let up = right.cross(forward);
        (forward, right, up)
    }

    /// Moves the point looked at, and the camera with it, across the view: `right` and
    /// `up` in fractions of the distance.
    pub fn pan(&mut self, right: f32, up: f32) {
        let (_, r, u) = self.frame();
        self.target += (r * right + u * up) * self.distance;
    }

    /// Moves the camera and the point looked at together, metres along the view, to its
    /// right and up (`+y`).
    pub fn fly(&mut self, forward: f32, right: f32, up: f32) {
        let (f, r, _) = self.frame();
        self.target += f * forward + r * right + Vec3::Y * up;
    }

    /// Turns the camera in place (it stays where it is; the point looked at moves),
    /// radians to the right and up.
    pub fn look(&mut self, right: f32, up: f32) {
        let position = self.position();
        // The camera looks along −direction: turning right lowers the azimuth of the
        // direction back to the camera by the same angle, looking up lowers its elevation.
        self.azimuth -= right;
        self.elevation -= up;
        self.clamp();
        self.target = position - self.distance * direction(self.azimuth, self.elevation);
    }

    /// Widens (`factor > 1`) or narrows the field of view.
    pub fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.fov_deg *= factor;
            self.clamp();
        }
    }
}

/// Of `views` (captured cameras, in the frame the viewer's camera is in), the one whose
/// direction from the vertical axis through `axis_at` is nearest the camera at
/// `position`'s.
pub fn nearest_view(views: &[Camera], position: Vec3, axis_at: Vec3) -> Option<usize> {
    let dir = (position - axis_at).normalize_or_zero();
    views
        .iter()
        .enumerate()
        .max_by(|(_, a), (_, b)| {
            let cos = |c: &Camera| (c.centre() - axis_at).normalize_or_zero().dot(dir);
            cos(a).total_cmp(&cos(b))
        })
        .map(|(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-4
    }

    #[test]
    fn a_camera_round_trips_through_its_key() {
        let c = ViewCamera::looking(Vec3::new(2.5, 1.4, 3.0), Vec3::new(0.0, 0.9, 0.0), 30.0)
            .expect("a camera");
        let k = c.key(1.5);
        assert!(close(Vec3::from(k.position), Vec3::new(2.5, 1.4, 3.0)));
        assert_eq!(k.look_at, [0.0, 0.9, 0.0]);
        assert_eq!((k.time, k.fov_deg), (1.5, 30.0));
        assert!(ViewCamera::looking(Vec3::ONE, Vec3::ONE, 30.0).is_none());
        assert!(ViewCamera::looking(Vec3::NAN, Vec3::ONE, 30.0).is_none());
    }

    #[test]
    fn orbit_keeps_the_point_and_distance_look_keeps_the_camera() {
        let mut c = ViewCamera::looking(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, 1.0, 0.0), 30.0)
            .expect("a camera");
        c.orbit(std::f32::consts::FRAC_PI_2, 0.0);
        // A quarter turn from +z toward +x.
        assert!(
            close(c.position(), Vec3::new(3.0, 1.0, 0.0)),
            "{}",
            c.position()
        );
        assert!(close(c.target, Vec3::new(0.0, 1.0, 0.0)));
        let before = c.position();
        c.look(0.3, -0.2);
        assert!(close(c.position(), before));
        assert!(!close(c.target, Vec3::new(0.0, 1.0, 0.0)));
        // Elevation stops short of the pole; distance and field of view stay in range.
        c.orbit(0.0, 10.0);
        assert!(c.elevation <= MAX_ELEVATION);
        c.dolly(1e-9);
        assert_eq!(c.distance, DISTANCE.0);
        c.zoom(1e9);
        assert_eq!(c.fov_deg, FOV_DEG.1);
        assert!(c.camera(64, 48).is_ok());
    }

    #[test]
    fn pan_and_fly_move_camera_and_point_together() {
        let mut c = ViewCamera::looking(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, 1.0, 0.0), 30.0)
            .expect("a camera");
        let offset = c.position() - c.target;
        c.pan(0.1, 0.0);
        // Looking along −z, the camera's right is +x.
        assert!(close(c.target, Vec3::new(0.3, 1.0, 0.0)), "{}", c.target);
        c.fly(1.0, 0.0, 0.5);
        assert!(close(c.target, Vec3::new(0.3, 1.5, -1.0)), "{}", c.target);
        assert!(close(c.position() - c.target, offset));
    }

    #[test]
    fn a_captured_camera_is_met_again_and_is_the_nearest_view() {
        let views: Vec<Camera> = (0..8)
            .map(|k| {
                let a = k as f32 * std::f32::consts::TAU / 8.0;
                let eye = Vec3::new(3.0 * a.sin(), 1.2, 3.0 * a.cos());
                Camera::look_at(eye, Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 0.6, 64, 48)
                    .expect("a camera")
            })
            .collect();
        let c = ViewCamera::of_camera(&views[3], Vec3::ZERO).expect("a camera");
        let back = c.camera(64, 48).expect("a camera");
        assert!(close(back.centre(), views[3].centre()));
        assert!(back.forward().dot(views[3].forward()) > 0.99999);
        assert!((back.intrinsics.fy - views[3].intrinsics.fy).abs() < 1e-2);
        // Slightly turned from view 5: view 5 is still the nearest.
        let mut near5 = ViewCamera::of_camera(&views[5], Vec3::ZERO).expect("a camera");
        near5.orbit(0.2, 0.1);
        assert_eq!(nearest_view(&views, near5.position(), Vec3::ZERO), Some(5));
    }
}
