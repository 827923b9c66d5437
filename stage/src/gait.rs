//! The cyclic gait of the walker on the treadmill, as functions of the gait phase
//! `φ ∈ [0, 1)`, for walking and running: where each foot is and how it is pitched, how
//! high the pelvis rides, and the angles of arms, torso and head; and the small seeded
//! cycle-to-cycle perturbations that make consecutive cycles (and so horizontal
//! neighbours in the grid of views) show the actor in not exactly the same place.
//!
//! **The legs walk on a belt.** Each leg has a stance, a fraction `duty` of the cycle
//! (0.6 walking, 0.35 running), in which its foot is level (pitch 0) with the sole's
//! lowest point on the treadmill `y = 0`, and moves along `-x` at exactly the belt's
//! speed `v` ([`Gait::speed_mps`]): a planted foot does not slide. In the swing the foot
//! lifts, pitches toes-down then slightly toes-up, and returns forward, its position and
//! velocity continuous at lift-off and touch-down (where it moves with the belt). The legs
//! are half a cycle apart, so a walk always has a foot down and a run has two flight
//! phases. The hip and knee angles follow from the feet by inverse kinematics
//! ([`crate::leg`]) from hip joints that ride on the pelvis (its yaw, sway and bob); the
//! pelvis's height is a constant plus a smooth bob chosen to keep every foot within reach
//! with the knee bent (see [`GaitShape::pelvis_m`]).
//!
//! Arms, torso and head keep a compact caricature of clinical gait data (Winter,
//! "Biomechanics and Motor Control of Human Movement", 2009): arms swinging against the
//! legs, a little torso counter-rotation, lateral sway.

use std::f32::consts::TAU;

use glam::{Mat3, Vec3};
use serde::{Deserialize, Serialize};

use crate::body::{HIP, SOLE_POINT, foot_depth};
use crate::rng::{gaussian, hash};

/// The kind of cyclic motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
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

    /// The treadmill belt's speed, metres per second: how fast a planted foot moves
    /// backward (`-x`) in the subject frame.
    pub fn speed_mps(self) -> f64 {
        self.shape().speed_mps
    }

    /// Metres of belt per cycle (speed x cycle): the stride, twice the spacing of
    /// consecutive footfalls.
    pub fn stride_m(self) -> f64 {
        self.speed_mps() * self.cycle_seconds()
    }

    /// Fraction of the cycle each foot is on the belt.
    pub fn duty_factor(self) -> f32 {
        self.shape().duty
    }

    fn shape(self) -> &'static GaitShape {
        match self {
            Gait::Walk => &WALK,
            Gait::Run => &RUN,
        }
    }
}

/// The numbers that make a gait's legs and pelvis.
#[derive(Debug)]
struct GaitShape {
    /// Fraction of the cycle a foot is down.
    duty: f32,
    /// Belt speed, m/s.
    speed_mps: f64,
    /// Height of the early-swing lift of the ankle (the heel kicking up), metres, and
    /// the exponent `n` of its shape `s² (1 - s)ⁿ` (peak at `s = 2 / (2 + n)`).
    kick: (f32, i32),
    /// Height of the late-swing lift (the foot reaching forward above the belt), metres,
    /// and the exponent `m` of its shape `sᵐ (1 - s)²` (peak at `s = m / (m + 2)`).
    reach: (f32, i32),
    /// Swing pitch `k s² (1 - s)² (s - s₀)`: gain `k` (degrees) and turn `s₀` (toes
    /// down before it, up after).
    pitch: (f32, f32),
    /// Pelvis height above the belt, metres:
    /// `h₀ + a₁ cos 2ω + b₁ sin 2ω + a₂ cos 4ω + b₂ sin 4ω` with `ω = 2πφ`.
    pelvis_m: [f32; 5],
}

/// Walking. The speed keeps the current walker's stride: its ankles swept 0.63 m fore
/// and aft of the hip between the hip's extremes (flexion 24° to -16°, knee 6°-14°), and a
/// planted foot now sweeps the same 0.63 m during its 0.6 s stance: 1.05 m/s, a stride of
/// 1.05 m. The swing lifts (8 cm kick, 2 cm reach) and pitches (-25° to +6°) for a swing
/// knee peaking at 60° (the clinical curves: ~60°). The pelvis was fitted (a random
/// search minimising the largest stance knee flexion while every knee stays bent at
/// least 9°, at both feet's extremes of reach, pelvis yaw included): it bobs 6.7 cm,
/// highest in single support; the stance knee stays within 15°-37°, the swing knee
/// within 9°-60°. (Level feet cost reach: spacing the footfalls as far apart as the
/// former ankles reached, 1.26 m/s, would bend the stance knee to 46°, a crouch.)
const WALK: GaitShape = GaitShape {
    duty: 0.6,
    speed_mps: 1.05,
    kick: (0.08, 6),
    reach: (0.02, 4),
    pitch: (1600.0, 0.65),
    pelvis_m: [0.956, 0.030, -0.010, -0.002, -0.006],
};

/// Running. The speed keeps the current runner's stride: its ankles reached 0.90 m apart
/// fore and aft at the hip's extremes, taken as the spacing of footfalls (half a stride):
/// a stride of 1.80 m in 0.7 s, 2.57 m/s. (Sweeping those 0.90 m within one 0.245 s stance
/// would need 3.7 m/s and more reach than a level foot leaves the leg.) The swing kicks
/// the heel up 20 cm and reaches forward 8 cm above the belt, pitching -37° to +3°,
/// for a swing knee peaking near 97° (the clinical curves: ~100°). The pelvis rides 2 cm
/// higher in flight than in mid-stance, as high as the extended legs allow at touch-down
/// and lift-off: the stance knee flexes 16°-51° (runners: ~45° at mid-stance), the swing
/// knee 10°-97°.
const RUN: GaitShape = GaitShape {
    duty: 0.35,
    speed_mps: 2.57,
    kick: (0.20, 6),
    reach: (0.08, 8),
    pitch: (1800.0, 0.75),
    pelvis_m: [0.927, -0.010, 0.0, 0.0, 0.0],
};

/// Exponent `p` of the swing's forward velocity profile `-v + U (1 - |1 - 2s|ᵖ)`: large
/// enough that the lifted foot, still moving back with the belt, turns forward within
/// 0.9 cm (walking) and 4.5 cm (running) of where it left the belt (1.7 and 7.7 cm with a
/// sine profile, which left the running legs short of reach), and overshoots its
/// touch-down point as little.
const SWING_PROFILE_EXPONENT: i32 = 4;

/// The pose of one foot, subject frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FootPose {
    /// The ankle (origin of the foot's frame), metres.
    pub ankle: Vec3,
    /// Pitch of the foot about `+z`, radians (toes up positive); 0 in stance. The foot
    /// does not yaw: its frame is `R_z(pitch)` placed at the ankle.
    pub pitch: f32,
    /// Whether the foot is on the belt (stance).
    pub down: bool,
}

impl FootPose {
    /// The foot's frame in the subject frame.
    pub fn frame(&self) -> (Mat3, Vec3) {
        (Mat3::from_rotation_z(self.pitch), self.ankle)
    }
}

/// One foot as data: a fixed material point of its sole and whether it is down.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FootContact {
    /// The sole's point [`SOLE_POINT`] (its lowest point when the foot is level), subject
    /// frame, metres. While the foot is down it lies on `y = 0` and moves at exactly
    /// `-`[`Gait::speed_mps`] along `x`.
    pub point: Vec3,
    /// Whether the foot is on the belt.
    pub down: bool,
}

/// Angles of one arm, radians.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ArmAngles {
    /// Shoulder flexion (upper arm forward positive).
    pub shoulder: f32,
    /// Elbow flexion (forearm forward positive).
    pub elbow: f32,
}

/// The whole body's pose at one instant, subject frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Posture {
    /// Left arm.
    pub left_arm: ArmAngles,
    /// Right arm.
    pub right_arm: ArmAngles,
    /// Left foot (`-z` side).
    pub left_foot: FootPose,
    /// Right foot (`+z` side).
    pub right_foot: FootPose,
    /// Centre of the pelvis (the skeleton's root), metres: its height above the belt,
    /// its lateral sway along `z` and any offset of the whole body.
    pub pelvis: Vec3,
    /// Pelvis yaw about `+y`, radians.
    pub pelvis_yaw: f32,
    /// Torso yaw relative to the pelvis, radians.
    pub torso_yaw: f32,
    /// Forward lean of the torso, radians.
    pub lean: f32,
    /// Head pitch (nod), radians.
    pub head_pitch: f32,
}

/// Per-cycle deviations from the mean gait (one draw per cycle and seed).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Perturbation {
    /// Offset of the body on the treadmill along `x` and `z`, metres.
    pub offset_x: f32,
    /// Offset along `z`, metres.
    pub offset_z: f32,
    /// Extra yaw of the pelvis and all it carries (the feet stay aligned with the belt),
    /// radians.
    pub yaw: f32,
    /// Phase lead, cycles.
    pub phase: f32,
    /// Offsets of the hip, knee, shoulder and elbow angles (both sides), radians. The
    /// arms take theirs; the legs do not take the hip and knee offsets, as their angles
    /// follow from the planted feet (an offset would make a foot slide or leave the
    /// belt), so those two only vary the draw of the others.
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

/// `max(0, x)^p`, the one-sided bumps the arm curves are made of.
fn bump(x: f32, p: i32) -> f32 {
    x.max(0.0).powi(p)
}

fn arm(gait: Gait, phase: f32) -> ArmAngles {
    let w = TAU * phase;
    // The leg on the same side is forward at phase 1/4: the arm swings against it.
    match gait {
        Gait::Walk => ArmAngles {
            shoulder: -deg(16.0) * w.sin(),
            elbow: deg(18.0) + deg(14.0) * bump(-w.sin(), 1),
        },
        Gait::Run => ArmAngles {
            shoulder: -deg(30.0) * w.sin(),
            elbow: deg(80.0) + deg(12.0) * w.sin(),
        },
    }
}

/// The integral over `[0, s]` of `1 - |1 - 2t|ᵖ` (the swing's velocity shape).
fn swing_progress(s: f32) -> f32 {
    let p = SWING_PROFILE_EXPONENT;
    let half = |s: f32| s - (1.0 - (1.0 - 2.0 * s).powi(p + 1)) / (2.0 * (p + 1) as f32);
    if s <= 0.5 {
        half(s)
    } else {
        2.0 * half(0.5) - half(1.0 - s)
    }
}

/// `sᵃ (1 - s)ᵇ` scaled to peak at 1.
fn lift_shape(s: f32, a: i32, b: i32) -> f32 {
    let peak = a as f32 / (a + b) as f32;
    (s.powi(a) * (1.0 - s).powi(b)) / (peak.powi(a) * (1.0 - peak).powi(b))
}

/// The foot of a leg at `leg_phase` cycles after its touch-down, in the sagittal plane
/// (`z = 0`), its stance centred under the pelvis.
fn foot(gait: Gait, leg_phase: f32) -> FootPose {
    let shape = gait.shape();
    let cycle = gait.cycle_seconds() as f32;
    let v = shape.speed_mps as f32;
    let psi = leg_phase.rem_euclid(1.0);
    // The belt carries a planted foot this far during a stance.
    let step = v * shape.duty * cycle;
    if psi < shape.duty {
        return FootPose {
            ankle: Vec3::new(step / 2.0 - v * psi * cycle, -SOLE_POINT.y, 0.0),
            pitch: 0.0,
            down: true,
        };
    }
    let s = (psi - shape.duty) / (1.0 - shape.duty);
    let swing = (1.0 - shape.duty) * cycle;
    // Velocity -v + U (1 - |1 - 2s|ᵖ): -v at both ends (the belt's), and U such that the
    // foot ends where the next stance starts.
    let p = SWING_PROFILE_EXPONENT as f32;
    let u = (step + v * swing) / (swing * p / (p + 1.0));
    let x = -step / 2.0 - v * swing * s + u * swing * swing_progress(s);
    // Pitch and lift have zero rate at both ends, so the sole's every point leaves and
    // meets the belt with the belt's velocity.
    let pitch = deg(shape.pitch.0) * s * s * (1.0 - s).powi(2) * (s - shape.pitch.1);
    let lift = shape.kick.0 * lift_shape(s, 2, shape.kick.1)
        + shape.reach.0 * lift_shape(s, shape.reach.1, 2);
    FootPose {
        // The lowest point of the pitched foot rides `lift` above the belt.
        ankle: Vec3::new(x, foot_depth(pitch) + lift, 0.0),
        pitch,
        down: false,
    }
}

/// The phase at which the left foot touches down: its stance is centred on phase 1/2
/// (the right's on 0), where the arms and the pelvis's yaw have the left leg back.
fn left_touch_down(gait: Gait) -> f32 {
    0.5 - gait.shape().duty / 2.0
}

/// The two feet of the unperturbed walker at gait phase `phase` (cycles), subject frame:
/// left (`-z`) then right (`+z`), each at the hip's half-width from the axis.
pub fn feet(gait: Gait, phase: f32) -> [FootPose; 2] {
    let td = left_touch_down(gait);
    [(-1.0f32, td), (1.0, td + 0.5)].map(|(side, touch_down)| {
        let mut f = foot(gait, phase - touch_down);
        f.ankle.z = side * HIP.1;
        f
    })
}

/// [`feet`] as contacts: the sole's point [`SOLE_POINT`] of each foot and whether it is
/// down.
pub fn contacts(gait: Gait, phase: f32) -> [FootContact; 2] {
    feet(gait, phase).map(|f| {
        let (rotation, ankle) = f.frame();
        FootContact {
            point: ankle + rotation * SOLE_POINT,
            down: f.down,
        }
    })
}

/// The pelvis's height above the belt at gait phase `phase`, metres.
fn pelvis_height(gait: Gait, phase: f32) -> f32 {
    let [h, a1, b1, a2, b2] = gait.shape().pelvis_m;
    let w = TAU * phase;
    h + a1 * (2.0 * w).cos() + b1 * (2.0 * w).sin() + a2 * (4.0 * w).cos() + b2 * (4.0 * w).sin()
}

/// The posture at gait phase `phase` (cycles), with a perturbation.
pub fn posture(gait: Gait, phase: f32, p: &Perturbation) -> Posture {
    let phase = (phase + p.phase).rem_euclid(1.0);
    let w = TAU * phase;
    let add = |mut a: ArmAngles| {
        a.shoulder += p.joints[2];
        a.elbow += p.joints[3];
        a
    };
    let lean = match gait {
        Gait::Walk => deg(3.0),
        Gait::Run => deg(9.0),
    };
    let offset = Vec3::new(p.offset_x, 0.0, p.offset_z);
    let [left_foot, right_foot] = feet(gait, phase).map(|mut f| {
        f.ankle += offset;
        f
    });
    Posture {
        left_arm: add(arm(gait, phase)),
        right_arm: add(arm(gait, phase + 0.5)),
        left_foot,
        right_foot,
        pelvis: offset + Vec3::new(0.0, pelvis_height(gait, phase), 0.02 * w.cos()),
        pelvis_yaw: -deg(4.0) * w.sin() + p.yaw,
        torso_yaw: deg(7.0) * w.sin(),
        lean,
        head_pitch: deg(2.0) * (2.0 * w).sin(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gait_is_periodic_and_legs_alternate() {
        let p = Perturbation::default();
        for gait in [Gait::Walk, Gait::Run] {
            for phase in [0.0, 0.13, 0.3, 0.77] {
                let a = posture(gait, phase, &p);
                let b = posture(gait, phase + 1.0, &p);
                assert!((a.left_foot.ankle - b.left_foot.ankle).length() < 1e-5);
                assert!((a.pelvis - b.pelvis).length() < 1e-5);
                let c = posture(gait, phase + 0.5, &p);
                let mirrored = c.right_foot.ankle * Vec3::new(1.0, 1.0, -1.0);
                assert!((a.left_foot.ankle - mirrored).length() < 1e-5);
                assert!((a.left_arm.shoulder - c.right_arm.shoulder).abs() < 1e-5);
            }
        }
    }

    /// The swing meets the stance at both ends in position and velocity: a planted foot
    /// leaves and meets the belt moving with it.
    #[test]
    fn the_swing_joins_the_stance_smoothly() {
        for gait in [Gait::Walk, Gait::Run] {
            let duty = gait.duty_factor();
            let v = gait.speed_mps() as f32 * gait.cycle_seconds() as f32; // m per cycle
            let h = 2e-4;
            for edge in [duty, 1.0] {
                let before = foot(gait, edge - h);
                let after = foot(gait, edge + h);
                let at = foot(gait, edge - 1e-6);
                // Positions agree to the belt's motion over 2h; velocities to -v.
                let velocity = (after.ankle - before.ankle) / (2.0 * h);
                assert!(
                    (velocity.x + v).abs() < 0.02 * v,
                    "{gait:?} {edge}: {velocity}"
                );
                assert!(velocity.y.abs() < 0.01, "{gait:?} {edge}: {velocity}");
                assert!((after.pitch - before.pitch).abs() < 1e-4);
                assert!((at.ankle - foot(gait, edge + 1e-6).ankle).length() < 1e-4);
            }
        }
    }

    #[test]
    fn speeds_and_strides_are_stated() {
        assert!((Gait::Walk.speed_mps() - 1.05).abs() < 1e-6);
        assert!((Gait::Run.stride_m() - 2.57 * 0.7).abs() < 1e-6);
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
