//! One front for both renderers: poses made resident either on the GPU ([`crate::gpu`])
//! or in memory for the CPU reference ([`crate::cpu`]), and frames drawn the same way.
//! The command line, scenes and the evaluation use this, so that `--cpu` changes nothing
//! else.
//!
//! - [`Device`]: where rendering happens; it makes poses resident ([`Resident`]), sets
//!   their shadow, makes backdrops resident and draws frames of one or more walkers
//!   ([`Device::render_frame`]): each walker's pose seen by the camera from its subject
//!   frame, back to front, over the backdrop darkened by their shadows.
//! - [`Renderer`]: one pose, one walker at the origin, one backdrop: the simple case.

use frf_core::camera::{Camera, Rigid};
use frf_core::image::{Image, Rgb, Rgba};

use crate::composite::{Backdrop, Layers, back_to_front, compose, stack, stack_by_depth};
use crate::cpu::{FrameStats, depth_cpu_within, render_cpu, render_cpu_within};
use crate::error::Result;
use crate::footprint::PixelBox;
use crate::gpu::composite::{GpuBackdrop, GpuInstanceRef};
use crate::gpu::time_morph::GpuBetween;
use crate::gpu::turn_light::TurnedLight;
use crate::gpu::{Gpu, GpuPose};
use crate::morph::Variant;
use crate::motion::{TimePair, time_morph};
use crate::pose_plan::PosePlan;
use crate::resident::{PoseSource, ResidentPose};
use crate::shadow::{RelitShadow, ShadowMaps};
use frf_core::grid::PoseStep;
use frf_core::subject_motion::motion_to_image;
use frf_reflectance::FieldFile;
use frf_reflectance::container::ReadAt;
use frf_reflectance::yaw_light::YawLight;

/// Where rendering happens.
pub enum Device {
    /// A wgpu adapter.
    Gpu(Box<Gpu>),
    /// The CPU reference (rayon).
    Cpu,
}

/// Where a scene's shadow comes from.
#[derive(Debug, Clone)]
pub enum SceneShadow {
    /// No shadow.
    None,
    /// The pose's attenuation maps, relit with the lighting the pose was relit with
    /// (shared: every walker of a pose holds the same copy).
    Maps(std::sync::Arc<ShadowMaps>),
    /// A relit shadow computed elsewhere (e.g. [`crate::shadow::traced_shadow`]).
    Relit(RelitShadow),
}

enum ResidentKind {
    Gpu(Box<GpuPose>),
    Cpu {
        pose: Box<ResidentPose>,
        shadow: Option<RelitShadow>,
    },
}

/// A pose made resident on a [`Device`], relit; relit again under a new light by
/// [`Device::relight`] from the basis codes it keeps (on the GPU, shared with the other
/// residents made from the same [`PoseSource`] views).
pub struct Resident {
    kind: ResidentKind,
    /// The views it was made from (their basis codes, shared; the coefficients of its
    /// current light).
    source: PoseSource,
    /// The shadow maps it casts its shadow from, relit with it.
    shadow_maps: Option<std::sync::Arc<ShadowMaps>>,
    /// Its motion toward the next and the previous pose ([`frf_core::grid::PoseStep`]
    /// order), when made ([`Device::set_motion`]), or lent by another resident of the
    /// same views ([`Resident::share_motion`]): it does not depend on the light.
    motion: [Option<std::sync::Arc<ResidentKind>>; 2],
    ground_coefficients: Option<Vec<Rgb>>,
    shadow: bool,
    /// The pose.
    pub pose: u32,
}

impl Resident {
    /// Bytes the pose holds where it is rendered (GPU memory, or the CPU's copy), what
    /// it may share with other residents left out ([`Resident::shared`]).
    pub fn bytes(&self) -> u64 {
        kind_bytes(&self.kind)
    }

    /// What it may share with residents made from the same views, each as an identity
    /// (equal for those that share it) and the bytes it holds where it is rendered: its
    /// basis codes, and its motion toward each neighbouring pose that it holds.
    pub fn shared(&self) -> Vec<(usize, u64)> {
        let id = std::sync::Arc::as_ptr(&self.source.basis) as usize;
        let basis = match &self.kind {
            ResidentKind::Gpu(p) => (id, p.basis().map_or(0, |b| b.bytes())),
            ResidentKind::Cpu { .. } => (id, self.source.basis_bytes()),
        };
        let motion = self.motion.iter().flatten();
        std::iter::once(basis)
            .chain(motion.map(|m| (std::sync::Arc::as_ptr(m) as usize, kind_bytes(m))))
            .collect()
    }

    /// Takes the motion `other` holds toward each neighbouring pose where it holds none
    /// and `other` was made from the same views (the motion is the views' own, whatever
    /// their light): shared, not made or uploaded again. Whether it then holds each
    /// ([`frf_core::grid::PoseStep`] order).
    pub fn share_motion(&mut self, other: &Resident) -> [bool; 2] {
        if std::sync::Arc::ptr_eq(&self.source.basis, &other.source.basis) {
            for (mine, theirs) in self.motion.iter_mut().zip(&other.motion) {
                if mine.is_none() {
                    mine.clone_from(theirs);
                }
            }
        }
        [0, 1].map(|k| self.motion[k].is_some())
    }

    /// The views it was made from, with the coefficients of its current light.
    pub fn source(&self) -> &PoseSource {
        &self.source
    }

    /// Where its subject can show ([`crate::geometry::PoseGeometry::bounds`]).
    pub fn bounds(&self) -> crate::footprint::SubjectBounds {
        match &self.kind {
            ResidentKind::Gpu(p) => p.geometry.bounds,
            ResidentKind::Cpu { pose, .. } => pose.geometry.bounds,
        }
    }

    /// Whether its motion toward `step`'s pose is resident.
    pub fn has_motion(&self, step: PoseStep) -> bool {
        self.motion[step.index()].is_some()
    }

    /// Whether the pose carries a shadow.
    pub fn has_shadow(&self) -> bool {
        self.shadow
    }

    /// The walker of a GPU frame this pose is, standing at `world_from_subject`.
    pub fn gpu_instance(&self, world_from_subject: Rigid) -> Result<GpuInstanceRef<'_>> {
        match &self.kind {
            ResidentKind::Gpu(pose) => Ok(GpuInstanceRef {
                pose,
                world_from_subject,
                between: None,
                within: None,
            }),
            ResidentKind::Cpu { .. } => Err(crate::RenderError::Misuse(
                "a CPU-resident pose given to the GPU renderer".into(),
            )),
        }
    }
}

/// A backdrop made resident on a [`Device`].
pub struct DeviceBackdrop {
    cpu: Backdrop,
    gpu: Option<GpuBackdrop>,
}

impl DeviceBackdrop {
    /// The backdrop resident on the GPU; `None` on the CPU.
    pub fn gpu(&self) -> Option<&GpuBackdrop> {
        self.gpu.as_ref()
    }

    /// Whether `camera` can see it (a plate is seen by its own camera's size).
    pub fn check(&self, camera: &Camera) -> Result<()> {
        self.cpu.check(camera)
    }
}

/// A walker of a frame: a resident pose and where it stands.
#[derive(Clone, Copy)]
pub struct Walker<'a> {
    /// Its pose, relit for it.
    pub resident: &'a Resident,
    /// Its subject frame in the world.
    pub world_from_subject: Rigid,
    /// Between `resident`'s pose and a later one: that pose (relit alike, with its motion
    /// toward `resident`'s, which has its motion toward it), and the fraction of the way
    /// ([`crate::motion`]).
    pub between: Option<(&'a Resident, f32)>,
    /// The pixels where it may show ([`crate::footprint::subject_box`]): only these are
    /// shaded; `None`, the whole frame.
    pub within: Option<PixelBox>,
}

impl<'a> Walker<'a> {
    /// The walker of a GPU frame (its poses resident on the GPU).
    pub fn gpu_instance(&self) -> Result<GpuInstanceRef<'a>> {
        let mut i = self.resident.gpu_instance(self.world_from_subject)?;
        i.within = self.within;
        if let Some((after, s)) = self.between {
            let gpu = |k: Option<&'a ResidentKind>, of: &Resident, step| match k {
                Some(ResidentKind::Gpu(p)) => Ok(&**p),
                Some(ResidentKind::Cpu { .. }) => Err(crate::RenderError::Misuse(
                    "a CPU-resident pose given to the GPU renderer".into(),
                )),
                None => Err(no_motion(of, step)),
            };
            let before = self.resident;
            i.between = Some(GpuBetween {
                after: gpu(Some(&after.kind), after, PoseStep::Next)?,
                before_motion: gpu(before.motion[0].as_deref(), before, PoseStep::Next)?,
                after_motion: gpu(after.motion[1].as_deref(), after, PoseStep::Prev)?,
                s,
            });
        }
        Ok(i)
    }

    /// The pose whose shadow the walker casts: the nearer of the two between poses.
    fn shadow_source(&self) -> &Resident {
        match self.between {
            Some((after, s)) if s >= 0.5 => after,
            _ => self.resident,
        }
    }
}

/// A frame drawn and not yet read back ([`Device::submit_frame`]): on the GPU, its
/// submission with its staging set; on the CPU, the frame itself.
pub enum FrameInFlight {
    /// Submitted to the GPU, its readback mapping.
    Gpu(crate::gpu::readback::PendingFrame),
    /// Rendered by the CPU reference.
    Done(Frame),
}

/// A composited frame.
#[derive(Debug, Clone)]
pub struct Frame {
    /// The walkers over their shadowed backdrop (premultiplied linear RGBA).
    pub composite: Image<Rgba>,
    /// The layers, when asked for.
    pub layers: Option<Layers>,
    /// What happened to the pixels of the walkers, summed.
    pub stats: FrameStats,
}

impl Device {
    /// The GPU (the default adapter; lavapipe on machines without one), or the CPU
    /// reference when `cpu`.
    pub fn open(cpu: bool) -> Result<Self> {
        Ok(if cpu {
            Device::Cpu
        } else {
            Device::Gpu(Box::new(Gpu::new()?))
        })
    }

    /// The GPU adapter, why it was taken and what else was found; `None` on the CPU.
    pub fn adapter_report(&self) -> Option<&crate::gpu::adapter::AdapterReport> {
        match self {
            Device::Gpu(gpu) => Some(gpu.adapter_report()),
            Device::Cpu => None,
        }
    }

    /// What renders, in words.
    pub fn name(&self) -> String {
        match self {
            Device::Gpu(gpu) => format!("GPU {}", gpu.adapter()),
            Device::Cpu => format!("CPU reference ({} threads)", rayon::current_num_threads()),
        }
    }

    /// The most walkers a frame can draw on this device (`None`: no limit but memory,
    /// on the CPU): a walker between two poses draws three renders, each of which may
    /// take a layer of an array texture of the frame's size, so a third of the device's
    /// layers (2048 on lavapipe and on NVIDIA's Vulkan drivers: 682 walkers).
    pub fn max_walkers(&self) -> Option<usize> {
        match self {
            Device::Gpu(gpu) => Some(gpu.max_texture_layers() as usize / 3),
            Device::Cpu => None,
        }
    }

    /// Makes `source` resident, relit (on the GPU, or on the CPU).
    pub fn make_resident(&self, source: &PoseSource) -> Result<Resident> {
        self.make_resident_sharing(source, None)
    }

    /// [`Device::make_resident`], sharing the basis codes `like` holds when it was made
    /// from the same views (e.g. [`PoseSource::relit`] of its source): on the GPU they
    /// are not uploaded again.
    pub fn make_resident_sharing(
        &self,
        source: &PoseSource,
        like: Option<&Resident>,
    ) -> Result<Resident> {
        let kind = match self {
            Device::Gpu(gpu) => {
                let basis = like.and_then(|r| match &r.kind {
                    ResidentKind::Gpu(p) => p.basis(),
                    ResidentKind::Cpu { .. } => None,
                });
                ResidentKind::Gpu(Box::new(gpu.upload_pose_sharing(source, basis)?))
            }
            Device::Cpu => ResidentKind::Cpu {
                pose: Box::new(ResidentPose::relight_cpu(source)),
                shadow: None,
            },
        };
        Ok(Resident {
            kind,
            source: source.clone(),
            shadow_maps: None,
            ground_coefficients: source.ground_coefficients.clone(),
            shadow: false,
            pose: source.geometry.pose,
            motion: [None, None],
        })
    }

    /// Lets go of `resident`'s basis codes on the GPU ([`GpuPose::release_basis`]): for a
    /// pose whose light will not change. Relighting it later uploads them again.
    pub fn release_basis(&self, resident: &mut Resident) {
        if let ResidentKind::Gpu(pose) = &mut resident.kind {
            pose.release_basis();
        }
    }

    /// Relights `resident` with `source`'s coefficients, `source` being its own views
    /// under a new light ([`PoseSource::relit`]), and its shadow maps with them. On the
    /// GPU this records one relighting dispatch pair per batch of views (sent with the next
    /// frame, the shadow relit by the frame that draws it), and uploads nothing but the
    /// coefficients.
    pub fn relight(&self, resident: &mut Resident, source: &PoseSource) -> Result<()> {
        if !std::sync::Arc::ptr_eq(&resident.source.basis, &source.basis) {
            return Err(crate::RenderError::Misuse(
                "a pose relit from views it was not made from".into(),
            ));
        }
        match (&mut resident.kind, self) {
            (ResidentKind::Gpu(pose), Device::Gpu(gpu)) => gpu.relight_pose(pose, source)?,
            (ResidentKind::Cpu { pose, .. }, _) => **pose = ResidentPose::relight_cpu(source),
            (ResidentKind::Gpu(_), Device::Cpu) => {
                return Err(crate::RenderError::Misuse(
                    "a GPU-resident pose given to the CPU renderer".into(),
                ));
            }
        }
        resident.source = source.clone();
        resident.ground_coefficients = source.ground_coefficients.clone();
        if let Some(maps) = resident.shadow_maps.clone() {
            self.set_shadow(resident, SceneShadow::Maps(maps))?;
        }
        Ok(())
    }

    /// Relights `resident` under `light` (in its walker's frame; `plan`, what its pose's
    /// reading left out), as [`Device::relight`] does with [`PoseSource::relit`]'s
    /// coefficients. On the GPU the views' coefficients are looked up on the device
    /// ([`Gpu::relight_turned`]) and the host writes a record, whatever the views; the
    /// resident's host copy of the coefficients then stays that of the light it was made
    /// under (the GPU's are the light's). Elsewhere, and where the device cannot, the host
    /// works them out.
    pub fn relight_tabled<R: ReadAt>(
        &self,
        resident: &mut Resident,
        field: &FieldFile<R>,
        light: &YawLight,
        plan: Option<&PosePlan>,
    ) -> Result<()> {
        if let (ResidentKind::Gpu(pose), Device::Gpu(gpu)) = (&mut resident.kind, self) {
            let h = field.header();

            let turned = TurnedLight {
                light,
                conditions: &h.conditions,
                pose: h.pose(resident.source.geometry.pose)?,
                used: plan.map(|p| p.conditions.as_slice()),
            };
            if gpu.relight_turned(pose, &resident.source, &turned)? {
                resident.ground_coefficients = Some(light.ground(h.conditions.len())?);
                if let Some(maps) = resident.shadow_maps.clone() {
                    self.set_shadow(resident, SceneShadow::Maps(maps))?;
                }
                return Ok(());
            }
        }
        let lighting = crate::resident::Lighting::Tabled(light.clone());
        let source = resident.source.relit(field, &lighting, plan)?;
        self.relight(resident, &source)
    }

    /// Sets the motion `resident` carries toward its next and previous poses
    /// ([`frf_core::grid::PoseStep`] order; [`crate::motion::pose_motion`]); a `None`
    /// leaves what it holds toward that pose.
    pub fn set_motion(
        &self,
        resident: &mut Resident,
        motion: [Option<ResidentPose>; 2],
    ) -> Result<()> {
        for (slot, m) in resident.motion.iter_mut().zip(motion) {
            let made = match (m, self) {
                (None, _) => continue,
                (Some(m), Device::Gpu(gpu)) => ResidentKind::Gpu(Box::new(gpu.upload_motion(&m)?)),
                (Some(m), Device::Cpu) => ResidentKind::Cpu {
                    pose: Box::new(m),
                    shadow: None,
                },
            };
            *slot = Some(std::sync::Arc::new(made));
        }
        Ok(())
    }

    /// Sets the shadow `resident` casts (maps without an environment give none).
    pub fn set_shadow(&self, resident: &mut Resident, shadow: SceneShadow) -> Result<()> {
        // Maps are relit for the pose's own coefficients of the ground; without them
        // (no environment) they give no shadow.
        let shadow = match shadow {
            SceneShadow::Maps(m) => match resident.ground_coefficients.as_deref() {
                Some(_) => SceneShadow::Maps(m),
                None => SceneShadow::None,
            },
            other => other,
        };
        let coefficients = resident.ground_coefficients.clone().unwrap_or_default();
        let cast = !matches!(shadow, SceneShadow::None);
        resident.shadow_maps = match &shadow {
            SceneShadow::Maps(m) => Some(m.clone()),
            _ => None,
        };
        match (&mut resident.kind, self) {
            (ResidentKind::Gpu(pose), Device::Gpu(gpu)) => match shadow {
                // The GPU relights the maps itself (tested against the CPU's).
                SceneShadow::Maps(m) => gpu.set_shadow(pose, &m, &coefficients)?,
                SceneShadow::Relit(r) => gpu.upload_shadow(pose, &r)?,
                SceneShadow::None => pose.clear_shadow(),
            },
            (ResidentKind::Cpu { shadow: relit, .. }, _) => {
                *relit = match shadow {
                    SceneShadow::Maps(m) => Some(m.relight(&coefficients)),
                    SceneShadow::Relit(r) => Some(r),
                    SceneShadow::None => None,
                };
            }
            (ResidentKind::Gpu(_), Device::Cpu) => {
                return Err(crate::RenderError::Misuse(
                    "a GPU-resident pose given to the CPU renderer".into(),
                ));
            }
        }
        resident.shadow = cast;
        Ok(())
    }

    /// The relit shadow of `resident` (read back from the GPU), if there is one.
    pub fn relit_shadow(&self, resident: &Resident) -> Result<Option<RelitShadow>> {
        Ok(match (&resident.kind, self) {
            (ResidentKind::Cpu { shadow, .. }, _) => shadow.clone(),
            (ResidentKind::Gpu(pose), Device::Gpu(gpu)) => {
                match (gpu.read_shadow(pose)?, pose.shadow_ground()) {
                    (Some(image), Some(ground)) => Some(RelitShadow { ground, image }),
                    _ => None,
                }
            }
            (ResidentKind::Gpu(_), Device::Cpu) => None,
        })
    }

    /// Makes `backdrop` resident.
    pub fn backdrop(&self, backdrop: Backdrop) -> Result<DeviceBackdrop> {
        Ok(DeviceBackdrop {
            gpu: match self {
                Device::Gpu(gpu) => Some(gpu.upload_backdrop(&backdrop)?),
                Device::Cpu => None,
            },
            cpu: backdrop,
        })
    }

    /// Renders the subject of `resident` alone, seen by `camera` (its subject frame):
    /// premultiplied linear RGBA, and what happened to its pixels.
    pub fn render_subject(
        &self,
        resident: &Resident,
        camera: &Camera,
        variant: Variant,
    ) -> Result<(Image<Rgba>, FrameStats)> {
        match (&resident.kind, self) {
            (ResidentKind::Gpu(pose), Device::Gpu(gpu)) => gpu.render(pose, camera, variant),
            (ResidentKind::Cpu { pose, .. }, _) => Ok(render_cpu(pose, camera, variant)),
            (ResidentKind::Gpu(_), Device::Cpu) => Err(crate::RenderError::Misuse(
                "a GPU-resident pose given to the CPU renderer".into(),
            )),
        }
    }

    /// Renders a frame of `camera` (world frame): the walkers over `backdrop`, its ground
    /// darkened by their shadows; with the layers when `layers`.
    pub fn render_frame(
        &self,
        walkers: &[Walker],
        backdrop: &DeviceBackdrop,
        camera: &Camera,
        variant: Variant,
        layers: bool,
    ) -> Result<Frame> {
        let drawn = self.submit_frame(walkers, backdrop, camera, variant, layers)?;
        self.finish_frame(drawn)
    }

    /// Draws a frame as [`Device::render_frame`] does and, on the GPU, submits it without
    /// waiting: [`Device::finish_frame`] reads it back, and a sequence draws the next
    /// frame first (the walkers' poses may then be relit or replaced: the frame in flight
    /// was recorded before). The CPU reference renders it here.
    pub fn submit_frame(
        &self,
        walkers: &[Walker],
        backdrop: &DeviceBackdrop,
        camera: &Camera,
        variant: Variant,
        layers: bool,
    ) -> Result<FrameInFlight> {
        backdrop.cpu.check(camera)?;
        if let (Device::Gpu(gpu), Some(b)) = (self, &backdrop.gpu) {
            let instances = gpu_instances(walkers)?;
            let pending = gpu.submit_composite(&instances, b, camera, variant, layers)?;
            return Ok(FrameInFlight::Gpu(pending));
        }
        Ok(FrameInFlight::Done(self.render_frame_cpu(
            walkers, backdrop, camera, variant, layers,
        )?))
    }

    /// Draws a frame as [`Device::submit_frame`] does and waits until it is drawn,
    /// reading nothing back (what a viewer presenting it waits for); the CPU reference
    /// renders it and lets it go.
    pub fn draw_frame_unread(
        &self,
        walkers: &[Walker],
        backdrop: &DeviceBackdrop,
        camera: &Camera,
        variant: Variant,
    ) -> Result<()> {
        backdrop.cpu.check(camera)?;
        if let (Device::Gpu(gpu), Some(b)) = (self, &backdrop.gpu) {
            return gpu.draw_composite_unread(&gpu_instances(walkers)?, b, camera, variant);
        }
        self.render_frame_cpu(walkers, backdrop, camera, variant, false)
            .map(drop)
    }

    /// The frame `drawn` ([`Device::submit_frame`]), read back once its submission is
    /// done.
    pub fn finish_frame(&self, drawn: FrameInFlight) -> Result<Frame> {
        match (drawn, self) {
            (FrameInFlight::Done(frame), _) => Ok(frame),
            (FrameInFlight::Gpu(pending), Device::Gpu(gpu)) => {
                let (composite, layers, stats) = gpu.finish_drawn(pending)?;
                Ok(Frame {
                    composite,
                    layers,
                    stats,
                })
            }
            (FrameInFlight::Gpu(_), Device::Cpu) => Err(crate::RenderError::Misuse(
                "a frame submitted to the GPU finished on the CPU".into(),
            )),
        }
    }

    /// The CPU reference of [`Device::render_frame`]: each walker alone, put over each
    /// other by depth at every pixel ([`stack_by_depth`]), then composited.
    fn render_frame_cpu(
        &self,
        walkers: &[Walker],
        backdrop: &DeviceBackdrop,
        camera: &Camera,
        variant: Variant,
        layers: bool,
    ) -> Result<Frame> {
        let positions: Vec<_> = walkers
            .iter()
            .map(|w| w.world_from_subject.translation)
            .collect();
        let mut drawn = Vec::with_capacity(walkers.len());
        let mut depths = Vec::with_capacity(walkers.len());
        let mut stats = FrameStats::default();
        let mut shadows = Vec::new();
        for k in back_to_front(camera, &positions) {
            let w = &walkers[k];
            let subject_from_world = w.world_from_subject.inverse();
            let seen = camera.transformed(&subject_from_world);
            let render = |pose, seen: &Camera| render_cpu_within(pose, seen, variant, w.within);
            let (img, s) = render(cpu_pose(&w.resident.kind)?, &seen);
            stats = stats.merge(s);
            if walkers.len() > 1 {
                // Between two poses, the nearer of their depths ([`crate::proxy`]).
                let mut depth = depth_cpu_within(cpu_pose(&w.resident.kind)?, &seen, w.within);
                if let Some((after, _)) = w.between {
                    let other = depth_cpu_within(cpu_pose(&after.kind)?, &seen, w.within);
                    for (d, o) in depth.pixels_mut().iter_mut().zip(other.pixels()) {
                        *d = d.min(*o);
                    }
                }
                depths.push(depth);
            }
            drawn.push(match w.between {
                None => img,
                Some((after, s)) => {
                    let [next, prev] = [PoseStep::Next, PoseStep::Prev].map(|step| {
                        let of = match step {
                            PoseStep::Next => w.resident,
                            PoseStep::Prev => after,
                        };
                        of.motion[step.index()]
                            .as_deref()
                            .ok_or_else(|| no_motion(of, step))
                    });
                    let after_img = render(cpu_pose(&after.kind)?, &seen).0;
                    let before_motion = render(cpu_pose(next?)?, &seen).0;
                    let after_motion = render(cpu_pose(prev?)?, &seen).0;
                    let pair = TimePair {
                        before: &img,
                        after: &after_img,
                        before_motion: &before_motion,
                        after_motion: &after_motion,
                    };
                    time_morph(&pair, s, motion_to_image(&seen))?
                }
            });
            if let ResidentKind::Cpu {
                shadow: Some(relit),
                ..
            } = &w.shadow_source().kind
            {
                shadows.push((subject_from_world, relit));
            }
        }
        let shadow = |p: glam::Vec3| {
            let mut s = [1.0f32; 3];
            for (m, relit) in &shadows {
                let q = m.transform_point(p);
                let r = relit.at(q.x, q.z);
                for c in 0..3 {
                    s[c] *= r[c];
                }
            }
            s
        };
        // One walker is itself; several are put over each other by depth, pixel by pixel.
        let subjects = if depths.is_empty() {
            stack(drawn)?
        } else {
            stack_by_depth(drawn.into_iter().zip(depths).collect())?
        };
        let (composite, l) = compose(subjects, camera, &backdrop.cpu, &shadow)?;
        Ok(Frame {
            composite,
            layers: layers.then_some(l),
            stats,
        })
    }
}

/// The GPU's view of every walker of a frame ([`Walker::gpu_instance`]); a walker that
/// cannot be drawn is named.
fn gpu_instances<'a>(walkers: &[Walker<'a>]) -> Result<Vec<GpuInstanceRef<'a>>> {
    (walkers.iter().enumerate())
        .map(|(k, w)| {
            w.gpu_instance().map_err(|e| match e {
                crate::RenderError::Misuse(m) => {
                    crate::RenderError::Misuse(format!("walker {k}: {m}"))
                }
                other => other,
            })
        })
        .collect()
}

/// Bytes `kind` holds where it is rendered.
fn kind_bytes(kind: &ResidentKind) -> u64 {
    match kind {
        ResidentKind::Gpu(p) => p.geometry.resident_bytes(),
        ResidentKind::Cpu { pose, .. } => pose.resident_bytes(),
    }
}

/// The CPU reference's copy of a resident pose.
fn cpu_pose(kind: &ResidentKind) -> Result<&ResidentPose> {
    match kind {
        ResidentKind::Cpu { pose, .. } => Ok(pose),
        ResidentKind::Gpu(_) => Err(crate::RenderError::Misuse(
            "a GPU-resident pose given to the CPU renderer".into(),
        )),
    }
}

/// The error of a frame between poses whose pose `of` lacks its motion toward `step`
/// (not made: the field holds no flow to that pose, or the plan did not ask for it).
fn no_motion(of: &Resident, step: PoseStep) -> crate::RenderError {
    crate::RenderError::Misuse(format!(
        "a frame between poses lacks pose {}'s motion {} (no flow between the poses was \
         read for it)",
        of.source.geometry.pose,
        step.name()
    ))
}

/// A resident pose and the renderer that draws it: one walker at the origin.
pub struct Renderer {
    device: Device,
    resident: Resident,
    backdrop: Option<DeviceBackdrop>,
}

impl Renderer {
    /// Makes `source` resident on the GPU ([`Gpu::new`]'s adapter), or on the CPU when
    /// `cpu`.
    pub fn open(source: &PoseSource, cpu: bool) -> Result<Self> {
        Self::new(source, if cpu { None } else { Some(Gpu::new()?) })
    }

    /// Makes `source` resident on `gpu` (relit there), or relights it on the CPU when
    /// `gpu` is `None`.
    pub fn new(source: &PoseSource, gpu: Option<Gpu>) -> Result<Self> {
        let device = match gpu {
            Some(g) => Device::Gpu(Box::new(g)),
            None => Device::Cpu,
        };
        let resident = device.make_resident(source)?;
        Ok(Self {
            device,
            resident,
            backdrop: None,
        })
    }

    /// Sets what frames are composited over: `backdrop`, and the subject's shadow.
    pub fn set_scene(&mut self, backdrop: Backdrop, shadow: SceneShadow) -> Result<()> {
        self.device.set_shadow(&mut self.resident, shadow)?;
        self.backdrop = Some(self.device.backdrop(backdrop)?);
        Ok(())
    }

    /// Whether frames carry the subject's shadow.
    pub fn has_shadow(&self) -> bool {
        self.resident.has_shadow()
    }

    /// The relit shadow of the ground (read back from the GPU), if there is one.
    pub fn relit_shadow(&self) -> Result<Option<RelitShadow>> {
        self.device.relit_shadow(&self.resident)
    }

    /// Renders the subject of a frame: premultiplied linear RGBA, and what happened to
    /// its pixels.
    pub fn render(&self, camera: &Camera, variant: Variant) -> Result<(Image<Rgba>, FrameStats)> {
        self.device.render_subject(&self.resident, camera, variant)
    }

    /// Renders a frame composited over the scene set by [`Renderer::set_scene`] (over
    /// nothing before that), with its layers when `layers`.
    pub fn render_frame(&self, camera: &Camera, variant: Variant, layers: bool) -> Result<Frame> {
        let owned;
        let backdrop = match &self.backdrop {
            Some(b) => b,
            None => {
                owned = self.device.backdrop(Backdrop::None)?;
                &owned
            }
        };
        let walker = Walker {
            resident: &self.resident,
            world_from_subject: Rigid {
                rotation: glam::Mat3::IDENTITY,
                translation: glam::Vec3::ZERO,
            },
            between: None,
            within: None,
        };
        self.device
            .render_frame(&[walker], backdrop, camera, variant, layers)
    }

    /// Bytes the pose holds where it is rendered (GPU memory, or the CPU's copy).
    pub fn resident_bytes(&self) -> u64 {
        self.resident.bytes()
    }

    /// What renders, in words.
    pub fn device(&self) -> String {
        self.device.name()
    }
}
