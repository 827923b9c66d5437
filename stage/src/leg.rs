//! Analytic inverse kinematics of a leg: the thigh and shin (two rigid links, a hinge at
//! the knee) that carry the ankle from the hip joint to a target, the knee bending
//! forward.
//!
//! The hip-to-ankle distance `d` fixes the knee's flexion `κ` by the law of cosines,
//! `d² = a² + b² + 2ab cos κ` (`a`, `b` the thigh and shin); the leg lies in the plane
//! through the hip–ankle line that holds the pelvis's forward direction, with the knee on
//! the forward side, so the hip both flexes and, when the ankle is off the pelvis's
//! sagittal plane, abducts. A target closer than the folded leg or farther than the
//! straight one is clamped to the nearest reachable distance along the same line, and
//! the solution says so; the gait keeps its targets well inside.

use glam::{Mat3, Vec3};

use crate::body::{SHIN_LENGTH, THIGH_LENGTH};

/// A solved leg.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegSolution {
    /// Rotation of the thigh's frame (the hinge is its `+z`, the thigh runs along its
    /// `-y` from the hip joint to the knee), in the frame the hip and target were given.
    pub thigh: Mat3,
    /// Knee flexion, radians: 0 is a straight leg, positive bends the shin backward.
    pub knee_flexion: f32,
    /// Whether the ankle reaches the target (false: the target was clamped).
    pub reached: bool,
}

/// The leg from the hip joint `hip` to the ankle target `ankle`, the knee toward
/// `forward` (the pelvis's forward direction; any vector not along the hip–ankle line).
pub fn solve(hip: Vec3, ankle: Vec3, forward: Vec3) -> LegSolution {
    let (a, b) = (THIGH_LENGTH, SHIN_LENGTH);
    let d = ankle - hip;
    // Clamp to (|a - b|, a + b): a straight or a fully folded knee has no unique plane.
    let (shortest, longest) = ((a - b).abs() + 1e-4, a + b - 1e-6);
    let length = d.length();
    let reach = length.clamp(shortest, longest);
    let e = if length > 0.0 {
        d / length
    } else {
        Vec3::NEG_Y
    };
    let f = (forward - e * forward.dot(e)).normalize_or(Vec3::X);
    let cos_knee = ((reach * reach - a * a - b * b) / (2.0 * a * b)).clamp(-1.0, 1.0);
    let cos_hip = ((a * a + reach * reach - b * b) / (2.0 * a * reach)).clamp(-1.0, 1.0);
    let sin_hip = (1.0 - cos_hip * cos_hip).max(0.0).sqrt();
    // The thigh leaves the hip–ankle line toward f by the hip's angle in the triangle.
    let along_thigh = e * cos_hip + f * sin_hip;
    let y = -along_thigh;
    let z = e.cross(f).normalize();
    let x = y.cross(z);
    LegSolution {
        thigh: Mat3::from_cols(x, y, z),
        knee_flexion: cos_knee.acos(),
        reached: (reach - length).abs() < 1e-5,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ankle where the solution's thigh and shin put it.
    fn ankle_of(hip: Vec3, s: &LegSolution) -> (Vec3, Vec3) {
        let knee = hip + s.thigh * Vec3::new(0.0, -THIGH_LENGTH, 0.0);
        let shin = s.thigh * Mat3::from_rotation_z(-s.knee_flexion);
        (knee, knee + shin * Vec3::new(0.0, -SHIN_LENGTH, 0.0))
    }

    #[test]
    fn the_ankle_reaches_its_target_with_the_knee_forward() {
        let hip = Vec3::new(0.01, 0.86, -0.095);
        for target in [
            Vec3::new(0.3, 0.09, -0.1),
            Vec3::new(-0.33, 0.09, -0.08),
            Vec3::new(0.0, 0.3, -0.12),
            Vec3::new(-0.25, 0.4, -0.095),
        ] {
            let s = solve(hip, target, Vec3::X);
            assert!(s.reached);
            let (knee, ankle) = ankle_of(hip, &s);
            assert!((ankle - target).length() < 1e-5, "{ankle} vs {target}");
            // The knee lies forward of the hip–ankle line.
            let e = (target - hip).normalize();
            let off = (knee - hip) - e * (knee - hip).dot(e);
            assert!(off.x > 0.0 && s.knee_flexion > 0.0);
            // A rotation, right-handed.
            assert!((s.thigh.determinant() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn targets_out_of_reach_are_clamped_and_said_so() {
        let s = solve(Vec3::ZERO, Vec3::new(0.0, -1.0, 0.0), Vec3::X);
        assert!(!s.reached && s.knee_flexion < 0.01);
        let (_, ankle) = ankle_of(Vec3::ZERO, &s);
        assert!((ankle.length() - (THIGH_LENGTH + SHIN_LENGTH)).abs() < 1e-4);
    }
}
