//! The walker's leg and foot dimensions, shared by the gait (which plants the foot on the
//! treadmill), the leg's inverse kinematics ([`crate::leg`]) and the actor (which poses
//! the parts): a 1.85 m adult, segment lengths after Winter ("Biomechanics and Motor
//! Control of Human Movement", 2009).

use glam::Vec3;

/// Thigh, hip joint to knee, metres.
pub const THIGH_LENGTH: f32 = 0.43;
/// Shin, knee to ankle, metres.
pub const SHIN_LENGTH: f32 = 0.42;
/// Hip joints: depth below the pelvis centre and half-width, metres.
pub const HIP: (f32, f32) = (0.06, 0.095);
/// Centre of the foot's ellipsoid in the foot's frame (origin at the ankle, `+x` toward
/// the toes, `+y` up when the foot is level), metres.
pub const FOOT_CENTRE: Vec3 = Vec3::new(0.06, -0.045, 0.0);
/// Semi-axes of the foot's ellipsoid, metres: a 25 cm shoe, 9 cm tall, 10 cm wide.
pub const FOOT_RADII: Vec3 = Vec3::new(0.125, 0.045, 0.05);
/// The material point of the sole that touches the belt when the foot is level: the
/// ellipsoid's lowest point at pitch 0, in the foot's frame.
pub const SOLE_POINT: Vec3 = Vec3::new(FOOT_CENTRE.x, FOOT_CENTRE.y - FOOT_RADII.y, 0.0);

/// How far the foot's lowest point lies below the ankle when the foot is pitched by
/// `pitch` (radians about `+z`, toes up positive): the support function of the ellipsoid
/// along `-y`. At pitch 0 it is `-SOLE_POINT.y` (9 cm).
pub fn foot_depth(pitch: f32) -> f32 {
    let (s, c) = pitch.sin_cos();
    let centre_y = FOOT_CENTRE.x * s + FOOT_CENTRE.y * c;
    let extent = ((s * FOOT_RADII.x).powi(2) + (c * FOOT_RADII.y).powi(2)).sqrt();
    extent - centre_y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_foot_rests_on_its_sole_point() {
        assert!((foot_depth(0.0) + SOLE_POINT.y).abs() < 1e-7);
        // Toes down, the toe reaches lower than the level sole; toes up, the heel's
        // curve stays above it.
        assert!(foot_depth(-0.4) > foot_depth(0.0) + 0.03);
        assert!(foot_depth(0.3) < foot_depth(0.0));
    }
}
