//! One front for both renderers: a pose made resident either on the GPU ([`crate::gpu`])
//! or in memory for the CPU reference ([`crate::cpu`]), rendering frames the same way.
//! The command line and the evaluation use this, so that `--cpu` changes nothing else.
//!
//! A renderer draws the subject alone ([`Renderer::render`]) or, once given a scene
//! ([`Renderer::set_scene`]: a backdrop and the pose's shadow maps), composites it with
//! its shadow over the backdrop ([`Renderer::render_frame`]).

use frf_core::camera::Camera;
use frf_core::image::{Image, Rgb, Rgba};

use crate::composite::{Backdrop, Layers, compose};
use crate::cpu::{FrameStats, render_cpu};
use crate::error::Result;
use crate::gpu::composite::GpuBackdrop;
use crate::gpu::{Gpu, GpuPose};
use crate::morph::Variant;
use crate::resident::{PoseSource, ResidentPose};
use crate::shadow::{RelitShadow, ShadowMaps};

enum Backend {
    Gpu {
        gpu: Box<Gpu>,
        pose: Box<GpuPose>,
        backdrop: Option<GpuBackdrop>,
    },
    Cpu {
        pose: Box<ResidentPose>,
        shadow: Option<RelitShadow>,
    },
}

/// Where a scene's shadow comes from.
#[derive(Debug, Clone)]
pub enum SceneShadow<'a> {
    /// No shadow.
    None,
    /// The pose's attenuation maps, relit with the lighting the pose was relit with.
    Maps(&'a ShadowMaps),
    /// A relit shadow computed elsewhere (e.g. [`crate::shadow::traced_shadow`]).
    Relit(RelitShadow),
}

/// A composited frame.
#[derive(Debug, Clone)]
pub struct Frame {
    /// The subject over its shadowed backdrop (premultiplied linear RGBA).
    pub composite: Image<Rgba>,
    /// The layers, when asked for.
    pub layers: Option<Layers>,
    /// What happened to the pixels of the subject.
    pub stats: FrameStats,
}

/// A resident pose and the renderer that draws it.
pub struct Renderer {
    backend: Backend,
    device: String,
    ground_coefficients: Option<Vec<Rgb>>,
    backdrop: Backdrop,
    shadow_relit: bool,
}

impl Renderer {
    /// Makes `source` resident on `gpu` (relit there), or relights it on the CPU when
    /// `gpu` is `None`.
    pub fn new(source: &PoseSource, gpu: Option<Gpu>) -> Result<Self> {
        let (backend, device) = match gpu {
            Some(gpu) => {
                let pose = gpu.upload_pose(source)?;
                (
                    Backend::Gpu {
                        pose: Box::new(pose),
                        backdrop: None,
                        gpu: Box::new(gpu),
                    },
                    String::new(),
                )
            }
            None => (
                Backend::Cpu {
                    pose: Box::new(ResidentPose::relight_cpu(source)),
                    shadow: None,
                },
                format!("CPU reference ({} threads)", rayon::current_num_threads()),
            ),
        };
        let device = match &backend {
            Backend::Gpu { gpu, .. } => format!("GPU {}", gpu.adapter()),
            Backend::Cpu { .. } => device,
        };
        Ok(Self {
            backend,
            device,
            ground_coefficients: source.ground_coefficients.clone(),
            backdrop: Backdrop::None,
            shadow_relit: false,
        })
    }

    /// Sets what frames are composited over: `backdrop`, and the subject's shadow
    /// (see [`SceneShadow`]; maps without an environment give none).
    pub fn set_scene(&mut self, backdrop: Backdrop, shadow: SceneShadow) -> Result<()> {
        let shadow = match shadow {
            SceneShadow::Maps(m) => self
                .ground_coefficients
                .as_deref()
                .map(|c| (Some(m), m.relight(c), c)),
            SceneShadow::Relit(r) => Some((None, r, &[][..])),
            SceneShadow::None => None,
        };
        match &mut self.backend {
            Backend::Gpu {
                gpu,
                pose,
                backdrop: resident,
            } => {
                *resident = Some(gpu.upload_backdrop(&backdrop)?);
                match &shadow {
                    // The GPU relights the maps itself (tested against the CPU's).
                    Some((Some(m), _, c)) => gpu.set_shadow(pose, m, c)?,
                    Some((None, r, _)) => gpu.upload_shadow(pose, r)?,
                    None => pose.clear_shadow(),
                }
            }
            Backend::Cpu { shadow: relit, .. } => {
                *relit = shadow.as_ref().map(|s| s.1.clone());
            }
        }
        self.shadow_relit = shadow.is_some();
        self.backdrop = backdrop;
        Ok(())
    }

    /// Whether frames carry the subject's shadow.
    pub fn has_shadow(&self) -> bool {
        self.shadow_relit
    }

    /// The relit shadow of the ground (read back from the GPU), if there is one.
    pub fn relit_shadow(&self) -> Result<Option<RelitShadow>> {
        Ok(match &self.backend {
            Backend::Cpu { shadow, .. } => shadow.clone(),
            Backend::Gpu { gpu, pose, .. } => {
                match (gpu.read_shadow(pose)?, pose.shadow_ground()) {
                    (Some(image), Some(ground)) => Some(RelitShadow { ground, image }),
                    _ => None,
                }
            }
        })
    }

    /// Renders the subject of a frame: premultiplied linear RGBA, and what happened to
    /// its pixels.
    pub fn render(&self, camera: &Camera, variant: Variant) -> Result<(Image<Rgba>, FrameStats)> {
        match &self.backend {
            Backend::Gpu { gpu, pose, .. } => gpu.render(pose, camera, variant),
            Backend::Cpu { pose, .. } => Ok(render_cpu(pose, camera, variant)),
        }
    }

    /// Renders a frame composited over the scene set by [`Renderer::set_scene`] (over
    /// nothing before that), with its layers when `layers`.
    pub fn render_frame(&self, camera: &Camera, variant: Variant, layers: bool) -> Result<Frame> {
        self.backdrop.check(camera)?;
        match &self.backend {
            Backend::Gpu {
                gpu,
                pose,
                backdrop,
            } => {
                let owned;
                let backdrop = match backdrop {
                    Some(b) => b,
                    None => {
                        owned = gpu.upload_backdrop(&Backdrop::None)?;
                        &owned
                    }
                };
                let (composite, l, stats) =
                    gpu.render_composite(pose, backdrop, camera, variant, layers)?;
                Ok(Frame {
                    composite,
                    layers: l,
                    stats,
                })
            }
            Backend::Cpu { pose, shadow } => {
                let (subject, stats) = render_cpu(pose, camera, variant);
                let at = |p: glam::Vec3| shadow.as_ref().map_or([1.0; 3], |s| s.at(p.x, p.z));
                let (composite, l) = compose(subject, camera, &self.backdrop, &at)?;
                Ok(Frame {
                    composite,
                    layers: layers.then_some(l),
                    stats,
                })
            }
        }
    }

    /// Bytes the pose holds where it is rendered (GPU memory, or the CPU's copy).
    pub fn resident_bytes(&self) -> u64 {
        match &self.backend {
            Backend::Gpu { pose, .. } => pose.geometry.resident_bytes(),
            Backend::Cpu { pose, .. } => pose.resident_bytes(),
        }
    }

    /// What renders, in words.
    pub fn device(&self) -> &str {
        &self.device
    }
}
