//! The flowed reflectance field as data: a [`FieldHeader`] (the grid, every view's
//! camera and turntable angle, the lighting basis, codec parameters) and, per pose and
//! view, a [`ViewData`] (basis images, alpha, flows to the grid neighbours), plus per-pose
//! shadow attenuation maps.
//!
//! The header's geometry is self-contained: each view of each pose carries its camera
//! as seen from the subject frame and the turntable angle that relighting must rotate the
//! environment by ([`frf_core::conventions`]). A turntable capture fills it from its
//! manifest ([`FieldHeader::from_capture`]); a calibrated ring of photographs fills it from
//! its calibration, with one "condition" (the photo) and no relighting.

use frf_core::camera::{Camera, Intrinsics, Rigid};
use frf_core::capture::Capture;
use frf_core::grid::{Neighbour, PoseStep};
use frf_core::image::{FlowImage, GrayImage, RgbImage};
use frf_core::light::DirLight;
use frf_core::volume::GroundGrid;
use glam::{Mat3, Vec3};
use serde::{Deserialize, Serialize};

use crate::error::{ReflectanceError, Result};
use crate::flowcodec::quant::LogQuantizer;

/// A camera as stored: intrinsics and the rows of `[R | t]` (`world_from_camera`,
/// subject frame).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraRecord {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Focal lengths and principal point, pixels.
    pub intrinsics: [f32; 4],
    /// Rows of the 3x4 matrix `[R | t]`.
    pub world_from_camera: [[f32; 4]; 3],
}

impl CameraRecord {
    /// The record of a camera.
    pub fn from_camera(c: &Camera) -> Self {
        let r = c.world_from_camera.rotation;
        let t = c.world_from_camera.translation;
        let row = |k: usize| [r.col(0)[k], r.col(1)[k], r.col(2)[k], t[k]];
        let k = &c.intrinsics;
        Self {
            width: c.width,
            height: c.height,
            intrinsics: [k.fx, k.fy, k.cx, k.cy],
            world_from_camera: [row(0), row(1), row(2)],
        }
    }

    /// The camera, checked (finite, positive focal lengths, a rotation).
    pub fn to_camera(&self) -> std::result::Result<Camera, String> {
        let [fx, fy, cx, cy] = self.intrinsics;
        if !(fx > 0.0
            && fy > 0.0
            && fx.is_finite()
            && fy.is_finite()
            && cx.is_finite()
            && cy.is_finite())
        {
            return Err(format!("bad intrinsics {:?}", self.intrinsics));
        }
        let m = &self.world_from_camera;
        let col = |k: usize| Vec3::new(m[0][k], m[1][k], m[2][k]);
        let pose = Rigid {
            rotation: Mat3::from_cols(col(0), col(1), col(2)),
            translation: col(3),
        };
        pose.validate(1e-3)?;
        Ok(Camera {
            width: self.width,
            height: self.height,
            intrinsics: Intrinsics { fx, fy, cx, cy },
            world_from_camera: pose,
        })
    }
}

/// A light of a basis condition (dome frame).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LightRecord {
    /// Unit direction toward the light.
    pub direction: [f32; 3],
    /// RGB irradiance at normal incidence.
    pub intensity: [f32; 3],
    /// Solid angle this light stands for, steradians.
    pub solid_angle_sr: f32,
}

/// A basis condition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConditionRecord {
    /// Name.
    pub name: String,
    /// Floor condition (light from the ground)?
    pub floor: bool,
    /// Lights.
    pub lights: Vec<LightRecord>,
}

impl ConditionRecord {
    /// The lights as [`DirLight`]s.
    pub fn dir_lights(&self) -> Vec<DirLight> {
        self.lights
            .iter()
            .map(|l| DirLight {
                direction: Vec3::from(l.direction),
                irradiance: l.intensity,
            })
            .collect()
    }
}

/// One view of one pose.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ViewRecord {
    /// The camera, as seen from the subject frame.
    pub camera: CameraRecord,
    /// Turntable angle of this view, degrees: the environment is rotated by it before
    /// projection onto the basis.
    pub turntable_deg: f32,
}

/// One pose: its time, the geometry of its views (`u`-major: index `u * rows + v`) and
/// the quantizer of its flows (fitted to them, so that each pose can be ingested, stored
/// and merged on its own).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoseRecord {
    /// Pose index within the cycle.
    pub pose: u32,
    /// Time of the pose within the cycle, seconds.
    pub time_s: f64,
    /// The views.
    pub views: Vec<ViewRecord>,
    /// The quantizer of this pose's flows.
    pub flow_quantizer: LogQuantizer,
    /// The poses its pose-to-pose flows lead to, in [`PoseStep::ALL`] order: `None` when
    /// it holds none (or was written before they were recorded). A field draws the walk
    /// between *its* consecutive poses, so these must be those
    /// ([`FieldHeader::check_pose_flows`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pose_flows_to: Option<[Option<u32>; 2]>,
}

impl PoseRecord {
    /// Per view, its turntable angle, radians (what turns the dome's light for it).
    pub fn turntables(&self) -> Vec<f32> {
        (self.views.iter())
            .map(|v| v.turntable_deg.to_radians())
            .collect()
    }
}

/// The shadow maps of a field (docs/design.md section 2.4): their ground grid and the
/// basis conditions they belong to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShadowSpec {
    /// The ground patch under the subject (128 x 128 texels over 3 m x 3 m in the
    /// original).
    pub ground: GroundGrid,
    /// The basis conditions with a map, in map order (the upper-hemisphere ones).
    pub conditions: Vec<usize>,
    /// Directions traced per light ([`crate::shadow::attenuation_maps`]).
    #[serde(default = "one")]
    pub light_samples: usize,
}

fn one() -> usize {
    1
}

/// The visual hulls of a field: one per pose, each in its own box.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HullSpec {
    /// Voxel side, metres.
    pub voxel_m: f32,
    /// Views allowed to disagree when carving ([`crate::hull::VoxelHull::carve`]) a
    /// pose of the full grid; a pose of fewer views allows as many in proportion,
    /// rounded up.
    pub misses: usize,
}

/// Everything about a field except its images and flows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FieldHeader {
    /// Where the field comes from.
    pub description: String,
    /// Horizontal views (cycles).
    pub columns: usize,
    /// Vertical views (cameras).
    pub rows: usize,
    /// Whether the columns close into a circle (a full turntable turn).
    pub wraps: bool,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Duration of a cycle, seconds.
    pub cycle_seconds: f64,
    /// Poses per cycle.
    pub poses_per_cycle: u32,
    /// The lighting basis (dome frame).
    pub conditions: Vec<ConditionRecord>,
    /// The poses stored, with their view geometry.
    pub poses: Vec<PoseRecord>,
    /// Whether flow codes are predicted from their neighbours.
    pub flow_predicted: bool,
    /// JPEG quality of the basis mosaics.
    pub jpeg_quality: u8,
    /// The shadow maps' ground grid, if the field has shadows.
    pub shadows: Option<ShadowSpec>,
    /// How the visual hulls were carved, if the field has them.
    #[serde(default)]
    pub hulls: Option<HullSpec>,
    /// Speed of the treadmill's belt during the capture, metres per second (how fast a
    /// planted foot moves backward in the subject frame; a walker placed on a path
    /// advances its gait by the distance walked over it), when the capture said so.
    /// Fields without it (older fields, real captures) can measure it from their hulls
    /// ([`crate::gait_speed::measure`], [`crate::gait_speed::gait_speed_mps`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gait_speed_mps: Option<f64>,
}

impl FieldHeader {
    /// The header of a field built from `capture`, for `poses` (each must be captured).
    pub fn from_capture(
        capture: &Capture,
        poses: &[u32],
        flow_quantizer: LogQuantizer,
        jpeg_quality: u8,
    ) -> Result<Self> {
        let m = capture.manifest();
        let conditions = capture
            .conditions()
            .iter()
            .map(|c| ConditionRecord {
                name: c.name.clone(),
                floor: c.floor,
                lights: c
                    .lights
                    .iter()
                    .map(|l| LightRecord {
                        direction: l.light.direction.to_array(),
                        intensity: l.light.irradiance,
                        solid_angle_sr: l.solid_angle_sr,
                    })
                    .collect(),
            })
            .collect();
        let rows = capture.cameras().len();
        let poses = poses
            .iter()
            .map(|&pose| {
                if !capture.poses().contains(&pose) {
                    return Err(ReflectanceError::NoSuchPose {
                        file: None,
                        within: "capture",
                        pose,
                        held: listed(capture.poses()),
                    });
                }
                let views = (0..capture.cycles())
                    .flat_map(|u| (0..rows).map(move |v| (u, v)))
                    .map(|(u, v)| ViewRecord {
                        camera: CameraRecord::from_camera(&capture.subject_camera(u, v, pose)),
                        turntable_deg: capture.view_angle(u, pose).to_degrees(),
                    })
                    .collect();
                Ok(PoseRecord {
                    pose,
                    time_s: capture.pose_time_s(pose),
                    views,
                    flow_quantizer,
                    pose_flows_to: None,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let cam = &capture.cameras()[0];
        let covered: f64 = m.turntable.degrees_per_cycle * capture.cycles() as f64;
        Ok(Self {
            description: m.description.clone(),
            columns: capture.cycles(),
            rows,
            // The grid closes when the cycles cover the full circle.
            wraps: (covered.abs() - 360.0).abs() < 1e-3,
            width: cam.width,
            height: cam.height,
            cycle_seconds: m.timing.cycle_seconds,
            poses_per_cycle: m.timing.poses_per_cycle,
            conditions,
            poses,
            flow_predicted: true,
            jpeg_quality,
            shadows: None,
            hulls: None,
            gait_speed_mps: m.timing.gait_speed_mps,
        })
    }

    /// Views per pose.
    pub fn views_per_pose(&self) -> usize {
        self.columns * self.rows
    }

    /// Index of view `(u, v)` in a pose's view list.
    pub fn view_index(&self, u: usize, v: usize) -> usize {
        u * self.rows + v
    }

    /// The record of pose `pose`, mutable.
    pub fn pose_mut(&mut self, pose: u32) -> Result<&mut PoseRecord> {
        let available: Vec<u32> = self.poses.iter().map(|p| p.pose).collect();
        self.poses
            .iter_mut()
            .find(|p| p.pose == pose)
            .ok_or_else(|| ReflectanceError::NoSuchPose {
                file: None,
                within: "field",
                pose,
                held: listed(&available),
            })
    }

    /// The record of pose `pose`.
    pub fn pose(&self, pose: u32) -> Result<&PoseRecord> {
        self.poses
            .iter()
            .find(|p| p.pose == pose)
            .ok_or_else(|| ReflectanceError::NoSuchPose {
                file: None,
                within: "field",
                pose,
                held: listed(&self.poses.iter().map(|p| p.pose).collect::<Vec<_>>()),
            })
    }

    /// The neighbour of view `(u, v)` in direction `n`, if any.
    pub fn neighbour(&self, u: usize, v: usize, n: Neighbour) -> Option<(usize, usize)> {
        n.of(u, v, self.columns, self.rows, self.wraps)
    }

    /// The poses held, sorted.
    pub fn pose_list(&self) -> Vec<u32> {
        let mut poses: Vec<u32> = self.poses.iter().map(|p| p.pose).collect();
        poses.sort_unstable();
        poses
    }

    /// Records on pose `pose` that its pose-to-pose flows were measured toward its
    /// neighbours among `poses` (sorted).
    pub fn record_pose_flows(&mut self, pose: u32, poses: &[u32]) -> Result<()> {
        self.pose_mut(pose)?.pose_flows_to = Some(PoseStep::ALL.map(|s| s.target(pose, poses)));
        Ok(())
    }

    /// Checks that every pose's recorded pose-to-pose flows lead to its neighbours among
    /// the poses this field holds (when it holds several), the motion a frame between two
    /// of them needs; says
    /// which pose's do not (the pose, and the problem in words), and where they lead.
    pub fn check_pose_flows(&self) -> std::result::Result<(), (u32, String)> {
        let poses = self.pose_list();
        for p in &self.poses {
            let Some(to) = p.pose_flows_to else { continue };
            for step in PoseStep::ALL {
                let (held, needed) = (to[step.index()], step.target(p.pose, &poses));
                // A one-pose field (a part to merge) has no neighbour to check against.
                if held.is_some() && needed.is_some() && held != needed {
                    let said = |t: Option<u32>| t.map_or("none".into(), |t| format!("pose {t}"));
                    return Err((
                        p.pose,
                        format!(
                            "pose {}'s flow {} leads to {}, but the pose {} it here is {} (it was \
                         measured among other poses than this field's {poses:?}): ingest these \
                         poses with --pose-flow in one run (frf ingest --poses {}), or parts of \
                         one pose each from a capture of exactly them",
                            p.pose,
                            step.name(),
                            said(held),
                            match step {
                                PoseStep::Next => "after",
                                PoseStep::Prev => "before",
                            },
                            said(needed),
                            poses
                                .iter()
                                .map(u32::to_string)
                                .collect::<Vec<_>>()
                                .join(",")
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Checks the header's consistency, saying what is wrong.
    pub fn validate(&self) -> std::result::Result<(), String> {
        let max = frf_core::io::limits::MAX_DIMENSION;
        if self.columns == 0 || self.rows == 0 || self.columns * self.rows > 1 << 16 {
            return Err(format!(
                "grid {}x{} is empty or absurd",
                self.columns, self.rows
            ));
        }
        if self.width == 0 || self.height == 0 || self.width > max || self.height > max {
            return Err(format!("image size {}x{}", self.width, self.height));
        }
        if self.conditions.is_empty() || self.conditions.iter().any(|c| c.lights.is_empty()) {
            return Err("a field needs basis conditions with lights".into());
        }
        if !(1..=100).contains(&self.jpeg_quality) {
            return Err(format!("JPEG quality {}", self.jpeg_quality));
        }
        for p in &self.poses {
            LogQuantizer::new(p.flow_quantizer.scale, p.flow_quantizer.range)
                .map_err(|e| format!("pose {}: {e}", p.pose))?;
            if self.poses.iter().filter(|q| q.pose == p.pose).count() > 1 {
                return Err(format!("pose {} listed twice", p.pose));
            }
            if p.views.len() != self.views_per_pose() {
                return Err(format!(
                    "pose {} has {} views, the grid {}",
                    p.pose,
                    p.views.len(),
                    self.views_per_pose()
                ));
            }
            for (i, v) in p.views.iter().enumerate() {
                let cam = v
                    .camera
                    .to_camera()
                    .map_err(|e| format!("pose {} view {i}: {e}", p.pose))?;
                if (cam.width, cam.height) != (self.width, self.height)
                    || !v.turntable_deg.is_finite()
                {
                    return Err(format!("pose {} view {i}: size or turntable angle", p.pose));
                }
            }
        }
        if let Some(v) = self.gait_speed_mps
            && !(v.is_finite() && v >= 0.0)
        {
            return Err(format!(
                "gait_speed_mps {v}: a belt speed is a finite number of metres per second, at least 0"
            ));
        }
        if let Some(s) = &self.shadows {
            s.ground
                .validate()
                .map_err(|e| format!("shadow maps: {e}"))?;
            if let Some(c) = s.conditions.iter().find(|&&c| c >= self.conditions.len()) {
                return Err(format!(
                    "shadow maps: condition {c} of {}",
                    self.conditions.len()
                ));
            }
        }
        if let Some(h) = &self.hulls
            && !(h.voxel_m.is_finite() && h.voxel_m > 0.0)
        {
            return Err(format!("visual hulls: voxel side {}", h.voxel_m));
        }
        Ok(())
    }
}

/// The data of one view of one pose.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewData {
    /// Basis images, one per condition: premultiplied linear RGB.
    pub basis: Vec<RgbImage>,
    /// Alpha.
    pub alpha: GrayImage,
    /// Flow to each neighbour, in [`Neighbour::ALL`] order (`None` where there is none).
    pub flows: [Option<FlowImage>; 4],
}
/// Poses listed for a message: `0, 1, 2`, or `none`.
pub fn listed(poses: &[u32]) -> String {
    if poses.is_empty() {
        return "none".into();
    }
    poses
        .iter()
        .map(u32::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}
