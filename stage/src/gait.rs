//! The cyclic gait: joint angles of the walker as smooth periodic functions of the gait
//! phase `φ ∈ [0, 1)`, for walking and running, and the small seeded cycle-to-cycle
//! perturbations that make consecutive cycles (and so horizontal neighbours in the grid
//! of views) show the actor in not exactly the same place.
//!
//! The curves are a compact caricature of clinical gait data (Winter, "Biomechanics and
//! Motor Control of Human Movement", 2009): hip flexion ±20° (walk) / ±32° (run) in
//! phase with the leg's swing, knee flexion peaking near mid-swing (~60° walk, ~100° run),
//! arms swinging against the legs, a little torso counter-rotation and lateral sway.

use std::f32::consts::TAU;

use serde::{Deserialize, Serialize};

use crate::rng::{gaussian, hash};

/// The kind of cyclic motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Gait {
    /// Walking, 1.0 s per cycle.
    Walk,
    /// Running, 0.7 s per cycle, with a flight phase.
    Run,
}

impl Gait {
    /// Duration of one cycle, seconds (typical cadences: ~1 stride/s walking,
    /// ~1.4 strides/s jogging).
    pub fn cycle_seconds(self) -> f64 {
        match self {
            Gait::Walk => 1.0,
            Gait::Run => 0.7,
        }
    }
}

/// Angles of one side's limbs, radians.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LimbAngles {
    /// Hip flexion (thigh forward positive).
    pub hip: f32,
    /// Knee flexion (shin backward positive).
    pub knee: f32,
    /// Ankle angle relative to the shin (toes up positive).
    pub ankle: f32,
    /// Shoulder flexion (upper arm forward positive).
    pub shoulder: f32,
    /// Elbow flexion (forearm forward positive).
    pub elbow: f32,
}

/// The whole body's joint angles and root motion at one instant.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Posture {
    /// Left limbs.
    pub left: LimbAngles,
    /// Right limbs.
    pub right: LimbAngles,
    /// Pelvis yaw about `+y`, radians.
    pub pelvis_yaw: f32,
    /// Torso yaw relative to the pelvis, radians.
    pub torso_yaw: f32,
    /// Forward lean of the torso, radians.
    pub lean: f32,
    /// Head pitch (nod), radians.
    pub head_pitch: f32,
    /// Lateral sway of the root along `+z`, metres.
    pub sway: f32,
    /// Extra height of the root above ground contact (flight phase), metres.
    pub lift: f32,
}

/// Per-cycle deviations from the mean gait (one draw per cycle and seed).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Perturbation {
    /// Offset of the body on the treadmill along `x` and `z`, metres.
    pub offset_x: f32,
    /// Offset along `z`, metres.
    pub offset_z: f32,
    /// Extra yaw of the whole body, radians.
    pub yaw: f32,
    /// Phase lead, cycles.
    pub phase: f32,
    /// Offsets added to the hip, knee, shoulder and elbow angles (both sides), radians.
    pub joints: [f32; 4],
}

/// Standard deviations of the per-cycle perturbation at scale 1: a walker on a treadmill
/// keeps its place to within about a centimetre and its timing to a few milliseconds
/// once it follows a metronome (the original used an audible one).
const SIGMA_OFFSET_M: f32 = 0.006;
const SIGMA_YAW_RAD: f32 = 0.8 * std::f32::consts::PI / 180.0;
const SIGMA_PHASE_CYCLES: f32 = 0.004;
const SIGMA_JOINT_RAD: f32 = 1.2 * std::f32::consts::PI / 180.0;

impl Perturbation {
    /// The perturbation of cycle `cycle` for `seed`, scaled by `scale` (0 = none).
    pub fn for_cycle(seed: u64, cycle: usize, scale: f32) -> Self {
        let g = |k: u64| gaussian(hash(&[seed, 0xC1C1E, cycle as u64, k])) * scale;
        Self {
            offset_x: g(0) * SIGMA_OFFSET_M,
            offset_z: g(1) * SIGMA_OFFSET_M,
            yaw: g(2) * SIGMA_YAW_RAD,
            phase: g(3) * SIGMA_PHASE_CYCLES,
            joints: [g(4), g(5), g(6), g(7)].map(|v| v * SIGMA_JOINT_RAD),
        }
    }
}

fn deg(d: f32) -> f32 {
    d.to_radians()
}

/// `max(0, x)^p`, the one-sided bumps the curves are made of.
fn bump(x: f32, p: i32) -> f32 {
    x.max(0.0).powi(p)
}

fn limbs(gait: Gait, phase: f32) -> LimbAngles {
    let w = TAU * phase;
    // The leg swings forward while sin(w) rises, i.e. while cos(w) > 0.
    match gait {
        Gait::Walk => {
            let hip = deg(20.0) * w.sin() + deg(4.0);
            let knee = deg(6.0)
                + deg(56.0) * bump((w + TAU * 0.06).cos(), 2)
                + deg(10.0) * bump((w - TAU * 0.45).cos(), 4);
            LimbAngles {
                hip,
                knee,
                ankle: -(hip - knee) + deg(10.0) * (w - TAU * 0.1).sin(),
                shoulder: -deg(16.0) * w.sin(),
                elbow: deg(18.0) + deg(14.0) * bump(-w.sin(), 1),
            }
        }
        Gait::Run => {
            let hip = deg(32.0) * w.sin() + deg(8.0);
            let knee = deg(20.0) + deg(80.0) * bump((w + TAU * 0.03).cos(), 2);
            LimbAngles {
                hip,
                knee,
                ankle: -(hip - knee) * 0.8 + deg(12.0) * (w - TAU * 0.1).sin(),
                shoulder: -deg(30.0) * w.sin(),
                elbow: deg(80.0) + deg(12.0) * w.sin(),
            }
        }
    }
}

/// The posture at gait phase `phase` (cycles), with a perturbation.
pub fn posture(gait: Gait, phase: f32, p: &Perturbation) -> Posture {
    let phase = (phase + p.phase).rem_euclid(1.0);
    let w = TAU * phase;
    let add = |mut l: LimbAngles| {
        l.hip += p.joints[0];
        l.knee += p.joints[1];
        l.shoulder += p.joints[2];
        l.elbow += p.joints[3];
        l
    };
    let (lean, lift) = match gait {
        Gait::Walk => (deg(3.0), 0.0),
        // Flight twice per cycle, between the stances of the two legs.
        Gait::Run => (deg(9.0), 0.04 * bump((2.0 * w + TAU * 0.3).sin(), 2)),
    };
    Posture {
        left: add(limbs(gait, phase)),
        right: add(limbs(gait, phase + 0.5)),
        pelvis_yaw: -deg(4.0) * w.sin() + p.yaw,
        torso_yaw: deg(7.0) * w.sin(),
        lean,
        head_pitch: deg(2.0) * (2.0 * w).sin(),
        sway: 0.02 * (w + TAU * 0.25).sin(),
        lift,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gait_is_periodic_and_legs_alternate() {
        let p = Perturbation::default();
        for gait in [Gait::Walk, Gait::Run] {
            let a = posture(gait, 0.3, &p);
            let b = posture(gait, 1.3, &p);
            assert!((a.left.hip - b.left.hip).abs() < 1e-5);
            let c = posture(gait, 0.8, &p);
            assert!((a.left.hip - c.right.hip).abs() < 1e-5);
        }
    }

    #[test]
    fn perturbations_are_seeded_and_small() {
        let a = Perturbation::for_cycle(1, 3, 1.0);
        assert_eq!(a, Perturbation::for_cycle(1, 3, 1.0));
        assert_ne!(a, Perturbation::for_cycle(2, 3, 1.0));
        assert_eq!(Perturbation::for_cycle(1, 3, 0.0), Perturbation::default());
        assert!(a.offset_x.abs() < 0.05 && a.yaw.abs() < 0.1);
    }
}
