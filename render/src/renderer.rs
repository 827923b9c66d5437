//! One front for both renderers: a pose made resident either on the GPU ([`crate::gpu`])
//! or in memory for the CPU reference ([`crate::cpu`]), rendering frames the same way.
//! The command line and the evaluation use this, so that `--cpu` changes nothing else.

use frf_core::camera::Camera;
use frf_core::image::{Image, Rgba};

use crate::cpu::{FrameStats, render_cpu};
use crate::error::Result;
use crate::gpu::{Gpu, GpuPose};
use crate::morph::Variant;
use crate::resident::{PoseSource, ResidentPose};

enum Backend {
    Gpu { gpu: Box<Gpu>, pose: Box<GpuPose> },
    Cpu(Box<ResidentPose>),
}

/// A resident pose and the renderer that draws it.
pub struct Renderer {
    backend: Backend,
    device: String,
}

impl Renderer {
    /// Makes `source` resident on `gpu` (relit there), or relights it on the CPU when
    /// `gpu` is `None`.
    pub fn new(source: &PoseSource, gpu: Option<Gpu>) -> Result<Self> {
        Ok(match gpu {
            Some(gpu) => {
                let pose = gpu.upload_pose(source)?;
                Self {
                    device: format!("GPU {}", gpu.adapter()),
                    backend: Backend::Gpu {
                        gpu: Box::new(gpu),
                        pose: Box::new(pose),
                    },
                }
            }
            None => Self {
                device: format!("CPU reference ({} threads)", rayon::current_num_threads()),
                backend: Backend::Cpu(Box::new(ResidentPose::relight_cpu(source))),
            },
        })
    }

    /// Renders one frame: premultiplied linear RGBA, and what happened to its pixels.
    pub fn render(&self, camera: &Camera, variant: Variant) -> Result<(Image<Rgba>, FrameStats)> {
        match &self.backend {
            Backend::Gpu { gpu, pose } => gpu.render(pose, camera, variant),
            Backend::Cpu(pose) => Ok(render_cpu(pose, camera, variant)),
        }
    }

    /// Bytes the pose holds where it is rendered (GPU memory, or the CPU's copy).
    pub fn resident_bytes(&self) -> u64 {
        match &self.backend {
            Backend::Gpu { pose, .. } => pose.geometry.resident_bytes(),
            Backend::Cpu(pose) => pose.resident_bytes(),
        }
    }

    /// What renders, in words.
    pub fn device(&self) -> &str {
        &self.device
    }
}
