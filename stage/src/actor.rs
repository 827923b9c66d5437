//! The articulated walker: 16 rigid parts (capsules and ellipsoids) on a kinematic
//! skeleton, posed from a [`crate::gait::Posture`] in the subject frame, walking on the
//! treadmill (`y = 0`) and facing `+x` ([`frf_core::conventions`]): the upper body by
//! forward kinematics from the pelvis, each foot where the gait plants it, and each leg
//! by inverse kinematics ([`crate::leg`]) from its hip joint to its ankle.
//!
//! Every surface point is identified by its part and its coordinates in that part's
//! frame; texture is a function of those, so a point keeps its colour as the body moves
//! and the true optical flow between two images is the motion of that point.

use frf_core::camera::Rigid;
use glam::{Mat3, Vec3};

use crate::body::{FOOT_CENTRE, FOOT_RADII, HIP, SHIN_LENGTH, THIGH_LENGTH};
use crate::gait::{Gait, Perturbation, Posture, posture};
use crate::geometry::{Aabb, Ray, Shape, hits_sphere};
use crate::leg::{self, LegSolution};
use crate::material::Material;

/// The parts of the body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
#[allow(missing_docs)]
pub enum Part {
    Pelvis,
    Torso,
    Neck,
    Head,
    UpperArmLeft,
    UpperArmRight,
    ForearmLeft,
    ForearmRight,
    HandLeft,
    HandRight,
    ThighLeft,
    ThighRight,
    ShinLeft,
    ShinRight,
    FootLeft,
    FootRight,
}

/// Number of parts.
pub const PART_COUNT: usize = 16;

impl Part {
    /// All parts, in index order.
    pub const ALL: [Part; PART_COUNT] = [
        Part::Pelvis,
        Part::Torso,
        Part::Neck,
        Part::Head,
        Part::UpperArmLeft,
        Part::UpperArmRight,
        Part::ForearmLeft,
        Part::ForearmRight,
        Part::HandLeft,
        Part::HandRight,
        Part::ThighLeft,
        Part::ThighRight,
        Part::ShinLeft,
        Part::ShinRight,
        Part::FootLeft,
        Part::FootRight,
    ];

    /// The part's shape in its own frame (metres; a 1.85 m adult, proportions after
    /// Winter's segment lengths).
    pub fn shape(self) -> Shape {
        use Part::*;
        let capsule = |len: f32, radius: f32| Shape::Capsule {
            a: Vec3::ZERO,
            b: Vec3::new(0.0, -len, 0.0),
            radius,
        };
        let ellipsoid = |centre: [f32; 3], radii: [f32; 3]| Shape::Ellipsoid {
            centre: Vec3::from(centre),
            radii: Vec3::from(radii),
        };
        match self {
            Pelvis => ellipsoid([0.0, 0.0, 0.0], [0.11, 0.10, 0.165]),
            Torso => ellipsoid([0.0, 0.23, 0.0], [0.115, 0.25, 0.175]),
            Neck => Shape::Capsule {
                a: Vec3::ZERO,
                b: Vec3::new(0.0, NECK_LENGTH, 0.0),
                radius: 0.052,
            },
            Head => ellipsoid([0.01, 0.11, 0.0], [0.10, 0.12, 0.085]),
            UpperArmLeft | UpperArmRight => capsule(UPPER_ARM_LENGTH, 0.045),
            ForearmLeft | ForearmRight => capsule(FOREARM_LENGTH, 0.037),
            HandLeft | HandRight => ellipsoid([0.0, -0.08, 0.0], [0.045, 0.085, 0.025]),
            ThighLeft | ThighRight => capsule(THIGH_LENGTH, 0.072),
            ShinLeft | ShinRight => capsule(SHIN_LENGTH, 0.05),
            FootLeft | FootRight => Shape::Ellipsoid {
                centre: FOOT_CENTRE,
                radii: FOOT_RADII,
            },
        }
    }

    /// What the part is made of.
    pub fn material(self) -> Material {
        use Part::*;
        match self {
            Pelvis | ThighLeft | ThighRight | ShinLeft | ShinRight => Material::Trousers,
            Torso | UpperArmLeft | UpperArmRight => Material::Shirt,
            Head => Material::Head,
            Neck | ForearmLeft | ForearmRight | HandLeft | HandRight => Material::Skin,
            FootLeft | FootRight => Material::Shoe,
        }
    }

    /// The part with index `i`.
    pub fn from_index(i: usize) -> Option<Part> {
        Self::ALL.get(i).copied()
    }
}

const NECK_LENGTH: f32 = 0.09;
const UPPER_ARM_LENGTH: f32 = 0.28;
const FOREARM_LENGTH: f32 = 0.25;
/// Shoulder joints: height above the torso frame and half-width.
const SHOULDER: (f32, f32) = (0.40, 0.205);
/// Outward tilt of the upper arms.
const ARM_ABDUCTION_RAD: f32 = 0.10;

/// One part, posed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PosedPart {
    /// The part.
    pub part: Part,
    /// Part frame to the actor's frame.
    pub world_from_part: Rigid,
    /// The inverse.
    pub part_from_world: Rigid,
    /// Bounding sphere centre (actor frame).
    pub sphere_centre: Vec3,
    /// Bounding sphere radius.
    pub sphere_radius: f32,
}

impl PosedPart {
    fn new(part: Part, world_from_part: Rigid) -> Self {
        let (c, r) = part.shape().bounding_sphere();
        Self {
            part,
            world_from_part,
            part_from_world: world_from_part.inverse(),
            sphere_centre: world_from_part.transform_point(c),
            sphere_radius: r,
        }
    }
}

/// A ray's hit on the actor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActorHit {
    /// The part hit.
    pub part: Part,
    /// Distance along the ray.
    pub t: f32,
    /// The point in the part's frame.
    pub local: Vec3,
    /// Outward unit normal (actor frame).
    pub normal: Vec3,
}

/// The posed body.
#[derive(Debug, Clone, PartialEq)]
pub struct Actor {
    parts: [PosedPart; PART_COUNT],
    bounds: Aabb,
}

fn translate(x: f32, y: f32, z: f32) -> Rigid {
    Rigid {
        rotation: Mat3::IDENTITY,
        translation: Vec3::new(x, y, z),
    }
}

fn rotate(m: Mat3) -> Rigid {
    Rigid {
        rotation: m,
        translation: Vec3::ZERO,
    }
}

/// Lowest `y` of a posed shape (support function along `-y`).
fn lowest_y(pose: &Rigid, shape: Shape) -> f32 {
    match shape {
        Shape::Ellipsoid { centre, radii } => {
            let c = pose.transform_point(centre);
            let r = pose.rotation;
            let ext = (0..3)
                .map(|k| (r.col(k).y * radii[k]).powi(2))
                .sum::<f32>()
                .sqrt();
            c.y - ext
        }
        Shape::Capsule { a, b, radius } => {
            pose.transform_point(a).y.min(pose.transform_point(b).y) - radius
        }
    }
}

impl Actor {
    /// The walker at gait phase `phase` (cycles) with a perturbation, in the subject frame:
    /// its feet where the gait puts them (a foot in stance level on the treadmill).
    pub fn walker(gait: Gait, phase: f32, perturbation: &Perturbation) -> Self {
        Self::from_posture(&posture(gait, phase, perturbation))
    }

    /// The legs of a posture: per side (left, right), the hip joint (subject frame) and
    /// the solved leg from it to the ankle.
    pub fn legs(p: &Posture) -> [(Vec3, LegSolution); 2] {
        let root = Self::root(p);
        let forward = root.rotation * Vec3::X;
        [(-1.0f32, &p.left_foot), (1.0, &p.right_foot)].map(|(side, foot)| {
            let hip = root.transform_point(Vec3::new(0.0, -HIP.0, side * HIP.1));
            (hip, leg::solve(hip, foot.ankle, forward))
        })
    }

    /// The pelvis's frame (the skeleton's root), subject frame.
    fn root(p: &Posture) -> Rigid {
        translate(p.pelvis.x, p.pelvis.y, p.pelvis.z)
            .compose(&rotate(Mat3::from_rotation_y(p.pelvis_yaw)))
    }

    /// Poses the parts for a posture (subject frame).
    pub fn from_posture(p: &Posture) -> Self {
        use Part::*;
        let root = Self::root(p);
        let torso = root.compose(&translate(0.0, 0.08, 0.0)).compose(&rotate(
            Mat3::from_rotation_y(p.torso_yaw) * Mat3::from_rotation_z(-p.lean),
        ));
        let neck = torso.compose(&translate(0.0, 0.46, 0.0));
        let head = neck
            .compose(&translate(0.0, NECK_LENGTH, 0.0))
            .compose(&rotate(Mat3::from_rotation_z(p.lean * 0.7 - p.head_pitch)));
        let mut poses = vec![(Pelvis, root), (Torso, torso), (Neck, neck), (Head, head)];
        let legs = Self::legs(p);
        for (side, arm, foot, (hip, leg)) in [
            (-1.0f32, &p.left_arm, &p.left_foot, legs[0]),
            (1.0f32, &p.right_arm, &p.right_foot, legs[1]),
        ] {
            let left = side < 0.0;
            let pick = |l: Part, r: Part| if left { l } else { r };
            let shoulder = torso
                .compose(&translate(0.0, SHOULDER.0, side * SHOULDER.1))
                .compose(&rotate(
                    Mat3::from_rotation_z(arm.shoulder + p.lean)
                        * Mat3::from_rotation_x(-side * ARM_ABDUCTION_RAD),
                ));
            let elbow = shoulder
                .compose(&translate(0.0, -UPPER_ARM_LENGTH, 0.0))
                .compose(&rotate(Mat3::from_rotation_z(arm.elbow)));
            let wrist = elbow.compose(&translate(0.0, -FOREARM_LENGTH, 0.0));
            let thigh = Rigid {
                rotation: leg.thigh,
                translation: hip,
            };
            let knee = thigh
                .compose(&translate(0.0, -THIGH_LENGTH, 0.0))
                .compose(&rotate(Mat3::from_rotation_z(-leg.knee_flexion)));
            let (rotation, translation) = foot.frame();
            poses.extend([
                (pick(UpperArmLeft, UpperArmRight), shoulder),
                (pick(ForearmLeft, ForearmRight), elbow),
                (pick(HandLeft, HandRight), wrist),
                (pick(ThighLeft, ThighRight), thigh),
                (pick(ShinLeft, ShinRight), knee),
                (
                    pick(FootLeft, FootRight),
                    Rigid {
                        rotation,
                        translation,
                    },
                ),
            ]);
        }
        let mut parts = [PosedPart::new(Pelvis, Rigid::IDENTITY); PART_COUNT];
        for (part, pose) in poses {
            parts[part as usize] = PosedPart::new(part, pose);
        }
        Self::from_parts(parts)
    }

    fn from_parts(parts: [PosedPart; PART_COUNT]) -> Self {
        let mut bounds = Aabb::EMPTY;
        for p in &parts {
            bounds.include_sphere(p.sphere_centre, p.sphere_radius);
        }
        Self { parts, bounds }
    }

    /// The same actor after a rigid motion (e.g. the turntable: `world_from_subject`).
    pub fn transformed(&self, new_from_old: &Rigid) -> Self {
        let mut parts = self.parts;
        for p in &mut parts {
            *p = PosedPart::new(p.part, new_from_old.compose(&p.world_from_part));
        }
        Self::from_parts(parts)
    }

    /// The lowest `y` of the body's surface, metres (exact, from every part's shape).
    pub fn lowest_y(&self) -> f32 {
        self.parts
            .iter()
            .map(|p| lowest_y(&p.world_from_part, p.part.shape()))
            .fold(f32::INFINITY, f32::min)
    }

    /// The posed parts.
    pub fn parts(&self) -> &[PosedPart; PART_COUNT] {
        &self.parts
    }

    /// A box containing the whole body.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// A point given in a part's frame, in the actor's frame.
    pub fn point(&self, part: Part, local: Vec3) -> Vec3 {
        self.parts[part as usize]
            .world_from_part
            .transform_point(local)
    }

    /// The nearest hit of a ray within `(t_min, t_max)`.
    pub fn intersect(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<ActorHit> {
        if !self.bounds.hit(ray, t_max) {
            return None;
        }
        let mut best: Option<ActorHit> = None;
        for p in &self.parts {
            let limit = best.map_or(t_max, |b| b.t);
            if !hits_sphere(ray, p.sphere_centre, p.sphere_radius, limit) {
                continue;
            }
            let local_ray = Ray {
                origin: p.part_from_world.transform_point(ray.origin),
                dir: p.part_from_world.transform_vector(ray.dir),
            };
            if let Some((t, n)) = p.part.shape().intersect(&local_ray, t_min, limit) {
                best = Some(ActorHit {
                    part: p.part,
                    t,
                    local: local_ray.origin + local_ray.dir * t,
                    normal: p.world_from_part.transform_vector(n),
                });
            }
        }
        best
    }

    /// Whether the point `p` (actor frame) lies inside the body.
    pub fn contains(&self, p: Vec3) -> bool {
        self.parts.iter().any(|part| {
            (p - part.sphere_centre).length_squared() <= part.sphere_radius * part.sphere_radius
                && part
                    .part
                    .shape()
                    .contains(part.part_from_world.transform_point(p))
        })
    }

    /// Whether anything of the body lies on the ray within `(t_min, t_max)`.
    pub fn occludes(&self, ray: &Ray, t_min: f32, t_max: f32) -> bool {
        if !self.bounds.hit(ray, t_max) {
            return false;
        }
        self.parts.iter().any(|p| {
            hits_sphere(ray, p.sphere_centre, p.sphere_radius, t_max) && {
                let local_ray = Ray {
                    origin: p.part_from_world.transform_point(ray.origin),
                    dir: p.part_from_world.transform_vector(ray.dir),
                };
                p.part.shape().intersect(&local_ray, t_min, t_max).is_some()
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn walker_stands_on_the_treadmill_and_is_human_sized() {
        for gait in [Gait::Walk, Gait::Run] {
            for phase in [0.0, 0.13, 0.5, 0.77] {
                let a = Actor::walker(gait, phase, &Perturbation::default());
                let b = a.bounds();
                let lowest = a.lowest_y();
                assert!(lowest > -1e-4, "{gait:?} {phase}: lowest point {lowest}");
                if gait == Gait::Walk {
                    // A walk always has a foot on the belt.
                    assert!(lowest < 1e-4, "{gait:?} {phase}: lowest point {lowest}");
                }
                let head_top = a.point(Part::Head, Vec3::new(0.01, 0.23, 0.0)).y;
                assert!((1.7..2.0).contains(&head_top), "height {head_top}");
                assert!(b.max.x - b.min.x < 1.6);
            }
        }
    }

    /// Every leg reaches its foot with the knee bent forward, neither locked straight
    /// nor folded, at every instant of both gaits, perturbed or not; the shin ends at the
    /// foot's ankle; nothing goes through the belt.
    #[test]
    fn legs_reach_their_feet_with_the_knee_bent() {
        let mut range = [(f32::INFINITY, f32::NEG_INFINITY); 2];
        for (g, gait) in [Gait::Walk, Gait::Run].into_iter().enumerate() {
            for seed in 0..4u64 {
                let scale = if seed == 0 { 0.0 } else { 1.0 };
                for cycle in 0..3 {
                    let perturbation = Perturbation::for_cycle(seed, cycle, scale);
                    for k in 0..500 {
                        let phase = k as f32 / 500.0;
                        let p = posture(gait, phase, &perturbation);
                        for (_, leg) in Actor::legs(&p) {
                            assert!(leg.reached, "{gait:?} seed {seed} phase {phase}");
                            let knee = leg.knee_flexion.to_degrees();
                            range[g] = (range[g].0.min(knee), range[g].1.max(knee));
                        }
                        let a = Actor::from_posture(&p);
                        for (shin, foot) in [
                            (Part::ShinLeft, Part::FootLeft),
                            (Part::ShinRight, Part::FootRight),
                        ] {
                            let end = a.point(shin, Vec3::new(0.0, -SHIN_LENGTH, 0.0));
                            let ankle = a.point(foot, Vec3::ZERO);
                            assert!((end - ankle).length() < 1e-4, "{gait:?} {phase}");
                        }
                        assert!(a.lowest_y() > -1e-3, "{gait:?} {phase}: {}", a.lowest_y());
                    }
                }
            }
        }
        // Measured, perturbations included: walk 8.7°-60.2°, run 9.4°-97.4°.
        for (lo, hi) in range {
            assert!(lo > 5.0 && hi < 130.0, "knee flexion {lo}°-{hi}°");
        }
        assert!(range[0].1 > 50.0 && range[1].1 > 85.0, "{range:?}");
    }

    #[test]
    fn a_ray_at_the_chest_hits_the_torso() {
        let a = Actor::walker(Gait::Walk, 0.25, &Perturbation::default());
        let chest = a.point(Part::Torso, Vec3::new(0.0, 0.23, 0.0));
        let ray = Ray {
            origin: chest + Vec3::new(3.0, 0.0, 0.0),
            dir: Vec3::NEG_X,
        };
        let hit = a.intersect(&ray, 0.0, 10.0).unwrap();
        assert!(matches!(
            hit.part,
            Part::Torso
                | Part::UpperArmLeft
                | Part::UpperArmRight
                | Part::ForearmLeft
                | Part::ForearmRight
                | Part::HandLeft
                | Part::HandRight
        ));
        assert!(a.occludes(&ray, 0.0, 10.0));
        // The local point maps back onto the ray.
        let p = a.point(hit.part, hit.local);
        assert!((p - (ray.origin + ray.dir * hit.t)).length() < 1e-4);
    }
}
