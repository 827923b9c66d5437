//! The fixed hardware of the virtual light stage, in the world frame: the lighting dome's
//! 26 basis conditions and its track lights, the three cameras, the turntable, and the
//! 33-slot schedule of a lighting set (docs/design.md section 5.1).
//!
//! **Basis.** The sphere is cut into 26 cells, symmetric about the vertical axis: a zenith
//! cap and three rings of 6, 8 and 8 cells in the upper hemisphere (23 conditions, all of
//! equal solid angle 2π/23 ≈ 0.273 sr: the ring boundaries at 73.0°, 44.1° and 20.3°
//! elevation make them so), and three 120° sectors of the lower hemisphere (the floor
//! conditions: light that a lit ground plane would send up). Each condition is an
//! `n x n` grid of lights over its cell, equal-area in (azimuth, sin elevation); each light
//! stands for its sub-cell and carries irradiance `Ω_light · L_c`, with `L_c` its
//! condition's radiance ([`condition_radiance`]). A condition at coefficient 1 therefore
//! approximates a uniform radiance `L_c` over its cell, and an environment's coefficient
//! for it is its mean radiance over the cell divided by `L_c`.
//!
//! **Exposure.** Every condition delivers the same irradiance, as a real stage sets each
//! condition's lights to use the sensor's range: the upper cells at radiance `L_dome`,
//! the floor sectors (7.7 times the solid angle) at `L_dome · (2π/23) / (2π/3)`. At
//! `L_dome` the floor sectors drove the lower legs and shoes to 3.1 times full scale and
//! clipped 3 % of a view's pixels (small preset, measured with `frf eval
//! --ingest-budget`'s `sensor` component: the floor conditions' frames, registered
//! with the true motion and matted with the true alpha, reached 18 dB against the
//! truth, the upper ones 31 to 43 dB).

use std::f32::consts::{PI, TAU};

use frf_core::camera::Camera;
use frf_core::light::{DirLight, direction_from_azimuth_elevation};
use glam::Vec3;

use crate::studio::Illumination;
use serde::{Deserialize, Serialize};

/// Lighting sets per second (30 in the original).
pub const SET_RATE_HZ: f64 = 30.0;
/// Camera frame rate (990 fps in the original).
pub const FRAME_RATE_HZ: f64 = 990.0;
/// Turntable rotation per walk cycle, degrees.
pub const DEGREES_PER_CYCLE: f64 = 10.0;
/// Camera elevations, degrees (the original's 0, 17 and 34).
pub const CAMERA_ELEVATIONS_DEG: [f32; 3] = [0.0, 17.0, 34.0];
/// Distance of the cameras from the point they look at, metres: just outside the
/// original's 8 m dome.
pub const CAMERA_DISTANCE_M: f32 = 4.5;
/// Height of the point the cameras look at: the dome's equator, 0.85 m above the
/// turntable in the original, rounded to frame a 1.85 m walker.
pub const LOOK_AT_HEIGHT_M: f32 = 0.9;
/// Vertical field of view, degrees: frames 2.2 m at the turntable axis.
pub const VERTICAL_FOV_DEG: f32 = 27.5;
/// Radiance of the dome over a lit upper condition's cell: sets the exposure (a white
/// diffuse surface facing one upper condition reads ≈ 0.7 of full scale).
pub const DOME_RADIANCE: f32 = 8.0;
/// Solid angle of every upper cell, steradians: the upper hemisphere in 23 equal parts.
const UPPER_CELL_SR: f32 = TAU / 23.0;

/// The radiance of a condition's lights over `cell`: with [`Exposure::Equal`] every
/// condition delivers what an upper cell at [`DOME_RADIANCE`] delivers (see the module
/// docs on exposure); with [`Exposure::Dome`] every cell is at [`DOME_RADIANCE`].
pub fn condition_radiance(cell: &Cell, exposure: Exposure) -> f32 {
    match exposure {
        Exposure::Equal => DOME_RADIANCE * UPPER_CELL_SR / cell.solid_angle(),
        Exposure::Dome => DOME_RADIANCE,
    }
}
/// Track frames light every condition at this fraction of a basis frame's light,
/// at its centre: evenly lit, exposed like a basis frame.
const TRACK_FRACTION: f32 = 0.08;
/// Irradiance of a camera's ring light on the subject in matte frames: weak, so the
/// subject stays dark while the retro-reflective floor returns it brightly.
const RING_IRRADIANCE: f32 = 0.1;

/// How bright each basis condition's lights are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Exposure {
    /// Every condition delivers the same irradiance: the floor sectors, 7.7 times an
    /// upper cell's solid angle, at a lower radiance (what a real stage's operator
    /// would set, so that no condition clips; the module docs). New captures.
    Equal,
    /// Every cell at the dome's radiance: the floor conditions clip the lower legs.
    /// Captures whose `stage.toml` predates the choice were made so.
    Dome,
}

/// A cell of the sphere: azimuth range and elevation range (radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// Azimuth of the cell's centre.
    pub azimuth: f32,
    /// Azimuthal width.
    pub width: f32,
    /// Lower elevation.
    pub elevation_min: f32,
    /// Upper elevation.
    pub elevation_max: f32,
}

impl Cell {
    /// Solid angle, steradians.
    pub fn solid_angle(&self) -> f32 {
        self.width * (self.elevation_max.sin() - self.elevation_min.sin())
    }

    /// The centre of the cell in (azimuth, sin elevation).
    pub fn centre(&self) -> Vec3 {
        let s = (self.elevation_min.sin() + self.elevation_max.sin()) / 2.0;
        direction_from_azimuth_elevation(self.azimuth, s.asin())
    }

    /// An `n x n` equal-area grid of directions over the cell, with the solid angle
    /// each stands for.
    pub fn grid(&self, n: u32) -> Vec<(Vec3, f32)> {
        let (s0, s1) = (self.elevation_min.sin(), self.elevation_max.sin());
        let omega = self.solid_angle() / (n * n) as f32;
        let mut out = Vec::with_capacity((n * n) as usize);
        for i in 0..n {
            let s = s0 + (s1 - s0) * (i as f32 + 0.5) / n as f32;
            for j in 0..n {
                let a = self.azimuth - self.width / 2.0 + self.width * (j as f32 + 0.5) / n as f32;
                out.push((direction_from_azimuth_elevation(a, s.asin()), omega));
            }
        }
        out
    }
}

/// One basis condition of the stage.
#[derive(Debug, Clone, PartialEq)]
pub struct BasisCondition {
    /// Name, e.g. `ring2-3`.
    pub name: String,
    /// Floor condition?
    pub floor: bool,
    /// Its cell of the sphere.
    pub cell: Cell,
    /// Its lights, with the solid angle each stands for.
    pub lights: Vec<(DirLight, f32)>,
    /// The radiance its lights stand for over its cell ([`condition_radiance`]).
    pub radiance: f32,
}

/// The 26 cells: cap, rings of 6, 8, 8, and 3 floor sectors.
pub fn basis_cells() -> Vec<(String, bool, Cell)> {
    let deg = |d: f32| d.to_radians();
    // Ring boundaries making every upper cell 2π/23 sr: the cap ends where
    // 1 - sin e = 1/23, each ring where the next 6 or 8 cells' worth is used up.
    let share = 1.0 / 23.0f32;
    let e1 = (1.0 - share).asin();
    let e2 = (e1.sin() - 6.0 * share).asin();
    let e3 = (e2.sin() - 8.0 * share).asin().max(0.0);
    let mut cells = vec![(
        "cap".to_string(),
        false,
        Cell {
            azimuth: 0.0,
            width: TAU,
            elevation_min: e1,
            elevation_max: PI / 2.0,
        },
    )];
    for (ring, count, lo, hi, offset) in [
        (1, 6, e2, e1, 0.0),
        (2, 8, e3, e2, 0.5),
        (3, 8, 0.0, e3, 0.0),
    ] {
        for k in 0..count {
            let width = TAU / count as f32;
            cells.push((
                format!("ring{ring}-{k}"),
                false,
                Cell {
                    azimuth: (k as f32 + offset) * width,
                    width,
                    elevation_min: lo,
                    elevation_max: hi,
                },
            ));
        }
    }
    for k in 0..3 {
        cells.push((
            format!("floor-{k}"),
            true,
            Cell {
                azimuth: deg(60.0) + k as f32 * deg(120.0),
                width: deg(120.0),
                elevation_min: -PI / 2.0,
                elevation_max: 0.0,
            },
        ));
    }
    cells
}

/// The basis conditions with `n x n` lights each, exposed as `exposure` says.
pub fn basis(lights_per_axis: u32, exposure: Exposure) -> Vec<BasisCondition> {
    basis_cells()
        .into_iter()
        .map(|(name, floor, cell)| {
            let radiance = condition_radiance(&cell, exposure);
            BasisCondition {
                lights: cell
                    .grid(lights_per_axis)
                    .into_iter()
                    .map(|(direction, omega)| {
                        (
                            DirLight {
                                direction,
                                irradiance: [omega * radiance; 3],
                            },
                            omega,
                        )
                    })
                    .collect(),
                name,
                floor,
                cell,
                radiance,
            }
        })
        .collect()
}

/// Track frames use no light within this angle of a camera's direction (seen from the
/// stage centre). The retro-reflective floor returns any light that lines up with a
/// camera's sightline from some floor point (those sightlines span about ±25° of
/// azimuth and up to 30° of elevation around the camera direction) as a glare brighter
/// than the matte frame's, which would corrupt the mattes. Measured: with all 26 lights,
/// 0.3 % of the top camera's background pixels were misclassified; with the clearance,
/// none.
const TRACK_CAMERA_CLEARANCE_RAD: f32 = 35.0 * PI / 180.0;

/// The lights of a track frame: one at the centre of every cell that is clear of the
/// cameras' sightlines, each at a fraction of its condition's light.
pub fn track_lights(basis: &[BasisCondition], cameras: &[Camera]) -> Vec<DirLight> {
    let centre = Vec3::new(0.0, LOOK_AT_HEIGHT_M, 0.0);
    let camera_dirs: Vec<Vec3> = cameras
        .iter()
        .map(|c| (c.centre() - centre).normalize())
        .collect();
    basis
        .iter()
        .map(|c| DirLight {
            direction: c.cell.centre(),
            irradiance: [c.cell.solid_angle() * c.radiance * TRACK_FRACTION; 3],
        })
        .filter(|l| {
            camera_dirs
                .iter()
                .all(|d| d.dot(l.direction) < TRACK_CAMERA_CLEARANCE_RAD.cos())
        })
        .collect()
}

/// The three cameras (world frame) at `width x height`.
pub fn cameras(width: u32, height: u32) -> Vec<Camera> {
    let target = Vec3::new(0.0, LOOK_AT_HEIGHT_M, 0.0);
    CAMERA_ELEVATIONS_DEG
        .iter()
        .map(|&e| {
            let eye =
                target + direction_from_azimuth_elevation(0.0, e.to_radians()) * CAMERA_DISTANCE_M;
            Camera::look_at(
                eye,
                target,
                Vec3::Y,
                VERTICAL_FOV_DEG.to_radians(),
                width,
                height,
            )
            .expect("the stage's own cameras are well-formed")
        })
        .collect()
}

/// What a slot of the stage's lighting set holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StageSlot {
    /// Basis condition.
    Basis(usize),
    /// Track frame `T_k`.
    Track(u32),
    /// Matte frame `M_k`.
    Matte(u32),
    /// Unused.
    Unused,
}

/// The 33-slot schedule: 8 basis, T0, M0, 6 basis, T1, M1, 6 basis, T2, M2, 6 basis,
/// unused. T1 is slot 16, the middle of the set.
pub fn schedule() -> Vec<StageSlot> {
    let mut slots = Vec::with_capacity(33);
    let mut condition = 0;
    for (block, track) in [(8, Some(0)), (6, Some(1)), (6, Some(2)), (6, None)] {
        for _ in 0..block {
            slots.push(StageSlot::Basis(condition));
            condition += 1;
        }
        match track {
            Some(k) => slots.extend([StageSlot::Track(k), StageSlot::Matte(k)]),
            None => slots.push(StageSlot::Unused),
        }
    }
    slots
}

/// Slot of the reference track frame T1.
pub const REFERENCE_SLOT: usize = 16;

/// Time of slot `slot` relative to T1, seconds.
pub fn slot_time_offset_s(slot: usize) -> f64 {
    (slot as f64 - REFERENCE_SLOT as f64) / FRAME_RATE_HZ
}

/// How slot `slot` is lit, seen from camera `camera` (world frame).
pub fn illumination(
    slot: StageSlot,
    camera: &Camera,
    basis: &[BasisCondition],
    track: &[DirLight],
) -> Illumination {
    match slot {
        StageSlot::Basis(c) => Illumination::Lights(basis[c].lights.iter().map(|l| l.0).collect()),
        StageSlot::Track(_) => Illumination::Lights(track.to_vec()),
        StageSlot::Matte(_) => Illumination::Matte {
            ring: DirLight {
                direction: (camera.centre() - Vec3::new(0.0, LOOK_AT_HEIGHT_M, 0.0)).normalize(),
                irradiance: [RING_IRRADIANCE; 3],
            },
        },
        StageSlot::Unused => Illumination::Dark,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_has_23_equal_upper_cells_and_tiles_the_sphere() {
        let cells = basis_cells();
        assert_eq!(cells.len(), 26);
        let upper: Vec<_> = cells.iter().filter(|c| !c.1).collect();
        assert_eq!(upper.len(), 23);
        for (_, _, c) in &upper {
            assert!((c.solid_angle() - TAU / 23.0).abs() < 1e-4, "{c:?}");
        }
        let total: f32 = cells.iter().map(|c| c.2.solid_angle()).sum();
        assert!((total - 4.0 * PI).abs() < 1e-3);
        // Lights stay inside their cells and carry the cell's solid angle.
        for cond in basis(3, Exposure::Equal) {
            let sum: f32 = cond.lights.iter().map(|l| l.1).sum();
            assert!((sum - cond.cell.solid_angle()).abs() < 1e-4);
            for (l, _) in &cond.lights {
                let e = l.direction.y.asin();
                assert!(e >= cond.cell.elevation_min - 1e-5 && e <= cond.cell.elevation_max + 1e-5);
            }
        }
    }

    #[test]
    fn every_condition_delivers_the_same_light_unless_the_dome_is_asked_for() {
        let delivered =
            |c: &BasisCondition| c.lights.iter().map(|l| l.0.irradiance[0]).sum::<f32>();
        let equal = basis(3, Exposure::Equal);
        let upper = delivered(&equal[0]);
        assert!((upper - DOME_RADIANCE * TAU / 23.0).abs() < 1e-3, "{upper}");
        for c in &equal {
            assert!(
                (delivered(c) / upper - 1.0).abs() < 1e-4,
                "{}: {}",
                c.name,
                delivered(c)
            );
        }
        // Captures made before: every cell at the dome's radiance, the floor sectors
        // delivering their 7.7 times larger solid angle's worth.
        let dome = basis(3, Exposure::Dome);
        for (d, e) in dome.iter().zip(&equal) {
            let ratio = delivered(d) / delivered(e);
            let expected = if d.floor { 23.0 / 3.0 } else { 1.0 };
            assert!((ratio - expected).abs() < 1e-3, "{}: {ratio}", d.name);
            assert_eq!(d.radiance, DOME_RADIANCE);
        }
    }

    #[test]
    fn basis_is_symmetric_about_the_vertical_axis() {
        // Turning ring 2 by one cell maps its conditions onto each other.
        let b = basis(2, Exposure::Equal);
        let ring: Vec<_> = b.iter().filter(|c| c.name.starts_with("ring2")).collect();
        let turn = glam::Mat3::from_rotation_y(TAU / 8.0);
        for (i, c) in ring.iter().enumerate() {
            let next = ring[(i + 1) % ring.len()];
            for (a, bl) in c.lights.iter().zip(&next.lights) {
                assert!((turn * a.0.direction - bl.0.direction).length() < 1e-5);
            }
        }
    }

    #[test]
    fn schedule_has_the_original_layout() {
        let s = schedule();
        assert_eq!(s.len(), 33);
        assert_eq!(s[REFERENCE_SLOT], StageSlot::Track(1));
        assert_eq!(
            s.iter()
                .filter(|x| matches!(x, StageSlot::Basis(_)))
                .count(),
            26
        );
        for k in 0..3 {
            let t = s.iter().position(|x| *x == StageSlot::Track(k)).unwrap();
            assert_eq!(s[t + 1], StageSlot::Matte(k));
        }
        assert_eq!(s[32], StageSlot::Unused);
    }

    #[test]
    fn track_lights_light_evenly_but_clear_the_cameras() {
        let b = basis(2, Exposure::Equal);
        let cams = cameras(64, 90);
        let track = track_lights(&b, &cams);
        assert!(
            track.len() >= 18 && track.len() < 26,
            "{} track lights",
            track.len()
        );
        // Lights remain on every side of the subject.
        for az in [0.0f32, 90.0, 180.0, 270.0] {
            let d = direction_from_azimuth_elevation(az.to_radians(), 0.3);
            assert!(
                track.iter().any(|l| l.direction.dot(d) > 0.5),
                "nothing near azimuth {az}"
            );
        }
    }

    #[test]
    fn cameras_look_at_the_subject_from_their_elevations() {
        for (cam, e) in cameras(64, 90).iter().zip(CAMERA_ELEVATIONS_DEG) {
            let p = cam.project(Vec3::new(0.0, LOOK_AT_HEIGHT_M, 0.0)).unwrap();
            assert!((p.x - 31.5).abs() < 1e-3 && (p.y - 44.5).abs() < 1e-3);
            let c = cam.centre() - Vec3::new(0.0, LOOK_AT_HEIGHT_M, 0.0);
            assert!((c.y.atan2(c.z).to_degrees() - e).abs() < 1e-3);
        }
    }
}
