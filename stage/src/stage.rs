//! [`Stage`]: the configured virtual light stage. It knows where the actor is at any
//! instant of any cycle, how each slot is lit, and renders capture frames and clean
//! plates exactly as the capture's manifest ([`Stage::manifest`]) describes them.

use frf_core::camera::{Camera, Rigid};
use frf_core::image::RgbImage;
use frf_core::light::DirLight;
use frf_core::manifest::{
    CameraSpec, ConditionSpec, FORMAT, FileSpec, LightSpec, Manifest, SlotSpec, Timing, Turntable,
    VERSION,
};

use crate::actor::Actor;
use crate::config::StageConfig;
use crate::error::{Result, StageError};
use crate::gait::{self, FootContact, Perturbation};
use crate::render::{Rendered, Scene, render};
use crate::rig::{self, BasisCondition, StageSlot};
use crate::rng::hash;
use crate::sensor::{self, MAX_CODE};

/// Clean plates are the average of 16 empty frames: a quarter of a frame's noise.
const CLEAN_PLATE_NOISE_SCALE: f32 = 0.25;

/// A camera and the actor it sees, both in the world frame, at one instant.
#[derive(Debug, Clone)]
pub struct ViewSetup {
    /// The camera (world frame).
    pub camera: Camera,
    /// The actor, placed by the turntable in the world frame.
    pub actor: Actor,
}

/// The configured stage.
#[derive(Debug, Clone)]
pub struct Stage {
    config: StageConfig,
    basis: Vec<BasisCondition>,
    track: Vec<DirLight>,
    cameras: Vec<Camera>,
    schedule: Vec<StageSlot>,
}

impl Stage {
    /// A stage for `config` (validated).
    pub fn new(config: StageConfig) -> Result<Self> {
        config.validate()?;
        let basis = rig::basis(config.lights_per_axis, config.exposure);
        let cameras = rig::cameras(config.width, config.height);
        let track = rig::track_lights(&basis, &cameras);
        Ok(Self {
            basis,
            track,
            cameras,
            schedule: rig::schedule(),
            config,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &StageConfig {
        &self.config
    }

    /// The cameras, world frame, lowest first.
    pub fn cameras(&self) -> &[Camera] {
        &self.cameras
    }

    /// The basis conditions.
    pub fn basis(&self) -> &[BasisCondition] {
        &self.basis
    }

    /// The slots of a lighting set.
    pub fn schedule(&self) -> &[StageSlot] {
        &self.schedule
    }

    /// Number of cycles (horizontal views).
    pub fn cycles(&self) -> usize {
        self.config.cycles as usize
    }

    /// Turntable rotation per cycle, degrees: the cycles cover the full circle.
    pub fn degrees_per_cycle(&self) -> f64 {
        360.0 / self.config.cycles as f64
    }

    /// Time of pose `pose`'s reference frame T1 since the start of its cycle, seconds.
    pub fn pose_time_s(&self, pose: u32) -> f64 {
        pose as f64 / rig::SET_RATE_HZ
    }

    /// Turntable angle in cycle `cycle` at `time_s` into it, radians.
    pub fn turntable_angle(&self, cycle: usize, time_s: f64) -> f32 {
        let deg =
            self.degrees_per_cycle() * (cycle as f64 + time_s / self.config.gait.cycle_seconds());
        deg.to_radians() as f32
    }

    /// The actor in the subject frame at `time_s` into cycle `cycle`, with that cycle's
    /// perturbation; `None` gives the unperturbed mean walker (used for ground truth of
    /// novel views).
    pub fn actor(&self, cycle: Option<usize>, time_s: f64) -> Actor {
        let perturbation = cycle
            .map(|c| Perturbation::for_cycle(self.config.seed, c, self.config.perturbation))
            .unwrap_or_default();
        let phase = (time_s / self.config.gait.cycle_seconds()) as f32;
        Actor::walker(self.config.gait, phase, &perturbation)
    }

    /// The feet of the unperturbed walker `time_s` seconds into its cycle, left then
    /// right (subject frame): each foot's sole point [`crate::body::SOLE_POINT`] and
    /// whether it is on the belt. A foot on the belt lies on `y = 0` and moves at exactly
    /// `-`[`crate::Gait::speed_mps`] along `x`.
    pub fn feet_at(&self, time_s: f64) -> [FootContact; 2] {
        let phase = (time_s / self.config.gait.cycle_seconds()) as f32;
        gait::contacts(self.config.gait, phase)
    }

    /// Camera `camera` and the actor of cycle `cycle`, pose `pose`, `offset_s` after the
    /// pose's reference time, in the world frame.
    pub fn view_setup(
        &self,
        pose: u32,
        cycle: usize,
        camera: usize,
        offset_s: f64,
    ) -> Result<ViewSetup> {
        self.check_view(cycle, camera)?;
        let t = self.pose_time_s(pose) + offset_s;
        let world_from_subject = Rigid::rotation_y(self.turntable_angle(cycle, t));
        Ok(ViewSetup {
            camera: self.cameras[camera],
            actor: self.actor(Some(cycle), t).transformed(&world_from_subject),
        })
    }

    fn check_view(&self, cycle: usize, camera: usize) -> Result<()> {
        if cycle >= self.cycles() {
            return Err(StageError::OutOfRange {
                what: "cycle",
                value: cycle.to_string(),
            });
        }
        if camera >= self.cameras.len() {
            return Err(StageError::OutOfRange {
                what: "camera",
                value: camera.to_string(),
            });
        }
        Ok(())
    }

    fn slot(&self, slot: usize) -> Result<StageSlot> {
        self.schedule
            .get(slot)
            .copied()
            .ok_or(StageError::OutOfRange {
                what: "slot",
                value: slot.to_string(),
            })
    }

    /// Renders slot `slot` of pose `pose` from view `(cycle, camera)` without noise or
    /// quantization (linear, unclipped).
    pub fn render_frame(
        &self,
        pose: u32,
        cycle: usize,
        camera: usize,
        slot: usize,
    ) -> Result<Rendered> {
        let kind = self.slot(slot)?;
        let setup = self.view_setup(pose, cycle, camera, rig::slot_time_offset_s(slot))?;
        let illumination = rig::illumination(kind, &setup.camera, &self.basis, &self.track);
        let scene = Scene {
            actor: Some(&setup.actor),
            studio: true,
            illumination: &illumination,
        };
        Ok(render(&setup.camera, &scene, self.config.samples_per_axis))
    }

    /// The captured frame as the camera records it: [`Stage::render_frame`] plus sensor
    /// noise and 12-bit quantization, in linear units (`code / 4095`).
    pub fn capture_frame(
        &self,
        pose: u32,
        cycle: usize,
        camera: usize,
        slot: usize,
    ) -> Result<RgbImage> {
        Ok(self.capture(pose, cycle, camera, slot)?.1)
    }

    /// Both the noise-free render (with its coverage and surface points) and the
    /// captured frame.
    pub fn capture(
        &self,
        pose: u32,
        cycle: usize,
        camera: usize,
        slot: usize,
    ) -> Result<(Rendered, RgbImage)> {
        let rendered = self.render_frame(pose, cycle, camera, slot)?;
        let key = hash(&[
            self.config.seed,
            0xF4A3E,
            pose as u64,
            cycle as u64,
            camera as u64,
            slot as u64,
        ]);
        let exposed = sensor::expose(&rendered.color, key, self.config.noise, 1.0);
        Ok((rendered, exposed))
    }

    /// The clean plate of camera `camera` for slot `slot`: the empty stage, lit alike.
    pub fn clean_plate(&self, camera: usize, slot: usize) -> Result<RgbImage> {
        let color = self.render_clean_plate(camera, slot)?;
        let key = hash(&[self.config.seed, 0xC1EA4, camera as u64, slot as u64]);
        Ok(sensor::expose(
            &color,
            key,
            self.config.noise,
            CLEAN_PLATE_NOISE_SCALE,
        ))
    }

    /// [`Stage::clean_plate`] as the lens forms it: without noise or quantization
    /// (linear, unclipped).
    pub fn render_clean_plate(&self, camera: usize, slot: usize) -> Result<RgbImage> {
        self.check_view(0, camera)?;
        let kind = self.slot(slot)?;
        let cam = &self.cameras[camera];
        let illumination = rig::illumination(kind, cam, &self.basis, &self.track);
        let scene = Scene {
            actor: None,
            studio: true,
            illumination: &illumination,
        };
        Ok(render(cam, &scene, self.config.samples_per_axis).color)
    }

    /// The lights of basis condition `condition` (world frame).
    pub fn condition_lights(&self, condition: usize) -> Result<Vec<DirLight>> {
        self.basis
            .get(condition)
            .map(|c| c.lights.iter().map(|l| l.0).collect())
            .ok_or(StageError::OutOfRange {
                what: "basis condition",
                value: condition.to_string(),
            })
    }

    /// The capture manifest describing what [`crate::write_capture`] writes.
    pub fn manifest(&self) -> Manifest {
        let cameras = self
            .cameras
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let r = c.world_from_camera.rotation;
                let t = c.world_from_camera.translation;
                let row =
                    |k: usize| [r.col(0)[k], r.col(1)[k], r.col(2)[k], t[k]].map(|v| v as f64);
                CameraSpec {
                    name: format!("cam{i}-{}deg", rig::CAMERA_ELEVATIONS_DEG[i]),
                    width: c.width,
                    height: c.height,
                    fx: c.intrinsics.fx as f64,
                    fy: c.intrinsics.fy as f64,
                    cx: c.intrinsics.cx as f64,
                    cy: c.intrinsics.cy as f64,
                    world_from_camera: [row(0), row(1), row(2)],
                }
            })
            .collect();
        let conditions = self
            .basis
            .iter()
            .map(|c| ConditionSpec {
                name: c.name.clone(),
                floor: c.floor,
                lights: c
                    .lights
                    .iter()
                    .map(|(l, omega)| LightSpec {
                        direction: l.direction.to_array().map(|v| v as f64),
                        intensity: l.irradiance.map(|v| v as f64),
                        solid_angle_sr: *omega as f64,
                    })
                    .collect(),
            })
            .collect();
        let schedule = self
            .schedule
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let (kind, condition, index) = match *s {
                    StageSlot::Basis(c) => ("basis", Some(c), None),
                    StageSlot::Track(k) => ("track", None, Some(k)),
                    StageSlot::Matte(k) => ("matte", None, Some(k)),
                    StageSlot::Unused => ("unused", None, None),
                };
                SlotSpec {
                    kind: kind.into(),
                    condition,
                    index,
                    time_offset_s: rig::slot_time_offset_s(i),
                }
            })
            .collect();
        Manifest {
            format: FORMAT.into(),
            version: VERSION,
            description: format!(
                "virtual light stage, preset {:?}, seed {}, {:?}",
                self.config.preset, self.config.seed, self.config.gait
            ),
            timing: Timing {
                cycle_seconds: self.config.gait.cycle_seconds(),
                poses_per_cycle: self.config.poses_per_cycle(),
                set_rate_hz: rig::SET_RATE_HZ,
                frame_rate_hz: rig::FRAME_RATE_HZ,
                poses: self.config.poses.clone(),
                reference_track: 1,
                gait_speed_mps: Some(self.config.gait.speed_mps()),
            },
            turntable: Turntable {
                azimuth_deg: (0..self.cycles())
                    .map(|u| u as f64 * self.degrees_per_cycle())
                    .collect(),
                degrees_per_cycle: self.degrees_per_cycle(),
            },
            cameras,
            conditions,
            schedule,
            files: FileSpec {
                frame: FRAME_PATTERN.into(),
                clean_plate: CLEAN_PLATE_PATTERN.into(),
                // 12-bit codes are stored in the top bits of 16: code 4095 -> 65520.
                full_scale: (MAX_CODE * 16.0) as f64,
            },
            filmed: self.config.filmed.clone(),
        }
    }
}

/// Where the stage writes frames, relative to the capture directory.
pub const FRAME_PATTERN: &str = "frames/p{pose:02}/v{camera}/u{cycle:02}/s{slot:02}.png";
/// Where the stage writes clean plates.
pub const CLEAN_PLATE_PATTERN: &str = "clean/v{camera}/s{slot:02}.png";
