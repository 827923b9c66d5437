//! `frf render --explain`: what the plan's savings are worth, measured by reading and
//! relighting the plan's first pose with everything and as planned.

use std::time::Instant;

use frf_reflectance::FieldFile;
use frf_reflectance::container::ReadAt;
use frf_render::renderer::Device;
use frf_render::resident::{Lighting, PoseSource};

use crate::Scene;
use crate::error::Result;
use crate::plan::Plan;

/// One pose read and relit with everything and as planned.
#[derive(Debug, Clone)]
pub struct Explained {
    /// The pose measured (the plan's first).
    pub pose: u32,
    /// The device it was made resident on.
    pub device: String,
    /// Seconds and bytes read with every view, flow and condition.
    pub full: (f64, u64),
    /// Seconds and bytes read as planned.
    pub planned: (f64, u64),
}

/// Measures the plan's first pose (`None` for a plan of no pose) on the GPU, or the CPU
/// with `cpu`.
pub fn explain<R: ReadAt>(
    scene: &Scene,
    field: &FieldFile<R>,
    plan: &Plan,
    cpu: bool,
) -> Result<Option<Explained>> {
    let Some(first) = plan.poses.first() else {
        return Ok(None);
    };
    let lighting = match &scene.lighting[0].env.load()? {
        Some(env) => Lighting::Environment {
            env: env
                .rotated(frf_core::light::turn_radians(scene.lighting[0].yaw_deg))
                .scaled(scene.lighting[0].intensity),
            floor: scene.floor,
        },
        None => Lighting::Unlit,
    };
    let device = Device::open(cpu)?;
    let measure = |planned: bool| -> Result<(f64, u64)> {
        let before = field.bytes_read();
        let t = Instant::now();
        let source =
            PoseSource::load_planned(field, first.pose, &lighting, planned.then_some(first))?;
        let resident = device.make_resident(&source)?;
        drop(resident);
        Ok((t.elapsed().as_secs_f64(), field.bytes_read() - before))
    };
    // Once untimed (caches, pipelines), then each way.
    measure(false)?;
    let full = measure(false)?;
    let planned = measure(true)?;
    Ok(Some(Explained {
        pose: first.pose,
        device: device.name(),
        full,
        planned,
    }))
}

impl Explained {
    /// The measurement for a person, with what the savings are worth over `plan`.
    pub fn describe(&self, plan: &Plan) -> String {
        let ((full_s, full_b), (planned_s, planned_b)) = (self.full, self.planned);
        let c = &plan.counts;
        [
            format!(
                "measured on pose {} ({}), reading and relighting one pose:",
                self.pose, self.device
            ),
            format!(
                "  every view, flow and condition: {full_s:.3} s, {:.2} MB read",
                full_b as f64 / 1e6
            ),
            format!(
                "  as planned:                     {planned_s:.3} s, {:.2} MB read",
                planned_b as f64 / 1e6
            ),
            format!(
                "  views, flows and conditions left out save {:.3} s and {:.2} MB per pose, {:.2} s over the {} poses drawn",
                full_s - planned_s,
                (full_b.saturating_sub(planned_b)) as f64 / 1e6,
                (full_s - planned_s) * c.poses_used as f64,
                c.poses_used
            ),
            format!(
                "  the {} poses never drawn save {:.2} s (each as a full pose)",
                c.poses_total - c.poses_used,
                full_s * (c.poses_total - c.poses_used) as f64
            ),
        ]
        .join("\n")
    }
}
