//! The suns' maps of a pose's visual hull made on the GPU (`shaders/sun_depth.wgsl`), twin
//! of [`SunDepth::reach`]: the host sets each map's frame ([`SunDepth::new`], a few
//! products), and one invocation a texel walks the hull the frame pass already holds, into
//! the pose's slots that the relight pass reads. A light that turns moves its suns, so
//! their maps are made again for every relight: on the GPU that is one dispatch, where the
//! host walked a ray per texel of every map of every walker's pose.
//!
//! Other walkers in the way of a sun ([`frf_reflectance::sun_depth::Occluder`]) are walked
//! after it, one dispatch each, their hulls uploaded once and kept ([`OCCLUDER_HULLS`]).

use std::sync::Arc;

use frf_reflectance::hull::VoxelHull;
use frf_reflectance::sun_depth::SunDepth;
use frf_reflectance::sun_light::{MAX_SUNS, SunLight};
use frf_shaders::types::{GpuSunDepthJob, GpuSunOccluderJob};
use wgpu::util::DeviceExt;

use super::Gpu;
use super::bind::{bind_group, compute_pipeline, empty_buffer, storage};
use super::kept::Kept;
use super::timing::compute_pass_writes;

/// Other walkers' hulls kept on the GPU, the most recently used (a crowd's neighbours).
pub const OCCLUDER_HULLS: usize = 64;

/// An occluder's hull as the pass binds it: its grid and its words (and the hull, so that
/// the address keying it stays its own).
struct OccluderHull {
    _hull: Arc<VoxelHull>,
    proxy: wgpu::Buffer,
    words: wgpu::Buffer,
}

/// Workgroup size of the pass (`@workgroup_size(64)`).
const WORKGROUP: u32 = 64;

/// The pass's layout and pipeline.
pub struct SunDepthPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    occluder_layout: wgpu::BindGroupLayout,
    occluder_pipeline: wgpu::ComputePipeline,
    /// Occluders' hulls, by address.
    hulls: Kept<usize, OccluderHull>,
}

impl SunDepthPass {
    /// Builds the pass on `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("sun depth"),
            source: wgpu::ShaderSource::Wgsl(frf_shaders::sun_depth_pass().into()),
        });
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sun depth"),
            entries: &[
                storage::<frf_shaders::types::GpuProxy>(0, true, c),
                storage::<u32>(1, true, c),
                storage::<GpuSunDepthJob>(2, true, c),
                storage::<f32>(3, false, c),
            ],
        });
        let pipeline = compute_pipeline(device, "sun depth", &[&layout], &module, "sun_depth");
        let occluder_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sun occluder"),
            entries: &[
                storage::<frf_shaders::types::GpuProxy>(0, true, c),
                storage::<u32>(1, true, c),
                storage::<f32>(3, false, c),
                storage::<GpuSunOccluderJob>(4, true, c),
            ],
        });
        let occluder_pipeline = compute_pipeline(
            device,
            "sun occluder",
            &[&occluder_layout],
            &module,
            "sun_occluder",
        );
        Self {
            layout,
            pipeline,
            occluder_layout,
            occluder_pipeline,
            hulls: Kept::new(OCCLUDER_HULLS),
        }
    }
}

/// A pose's [`MAX_SUNS`] slots of a sun's map, each of the most texels a map of its hull
/// can have ([`SunDepth::most_texels`]), and what the pass binds to fill them.
pub struct PoseSunMaps {
    jobs: wgpu::Buffer,
    /// The maps' values, slot after slot: what the relight pass reads.
    pub(super) reach: wgpu::Buffer,
    slot_texels: usize,
    bind: wgpu::BindGroup,
}

impl PoseSunMaps {
    /// Where slot `s`'s values start in [`PoseSunMaps::reach`].
    pub(super) fn slot_start(&self, s: usize) -> usize {
        s * self.slot_texels
    }
}

/// The job of `map` in slot `s` of slots of `slot_texels` (unused, no shadow, when it
/// would not fit: a map never has more texels than [`SunDepth::most_texels`]).
fn job(map: &SunDepth, s: usize, slot_texels: usize) -> GpuSunDepthJob {
    let fits = map.texels() <= slot_texels;
    GpuSunDepthJob {
        toward: map.toward.extend(map.far).to_array(),
        axis_x: map.axes[0].extend(map.corner.x).to_array(),
        axis_y: map.axes[1].extend(map.corner.y).to_array(),
        size: [
            map.size[0],
            map.size[1],
            (s * slot_texels) as u32,
            u32::from(fits),
        ],
        texel: [map.texel, 0.0, 0.0, 0.0],
    }
}

impl Gpu {
    /// Slots for the suns' maps of a pose whose hull the frame pass binds as `proxy` and
    /// `hull` (its words), of `slot_texels` each.
    pub(super) fn pose_sun_maps(
        &self,
        proxy: &wgpu::Buffer,
        hull: &wgpu::Buffer,
        slot_texels: usize,
    ) -> PoseSunMaps {
        let buffer =
            |label: &str, size: usize, usage| empty_buffer(&self.device, label, size, usage);
        let storage = wgpu::BufferUsages::STORAGE;
        let jobs = buffer(
            "sun depth jobs",
            MAX_SUNS * size_of::<GpuSunDepthJob>(),
            storage | wgpu::BufferUsages::COPY_DST,
        );
        let reach = buffer(
            "sun depths",
            MAX_SUNS * slot_texels.max(1) * 4,
            storage | wgpu::BufferUsages::COPY_SRC,
        );
        let bind = bind_group(
            &self.device,
            "sun depth",
            &self.sun_depth.layout,
            vec![
                proxy.as_entire_binding(),
                hull.as_entire_binding(),
                jobs.as_entire_binding(),
                reach.as_entire_binding(),
            ],
        );
        PoseSunMaps {
            jobs,
            reach,
            slot_texels,
            bind,
        }
    }

    /// Writes the maps' frames of `suns` (those with a map, in slots in their order) and
    /// records the pass that fills their slots into `encoder`.
    pub(super) fn record_sun_maps(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        maps: &PoseSunMaps,
        suns: &[SunLight],
    ) {
        let jobs: Vec<GpuSunDepthJob> = suns
            .iter()
            .take(MAX_SUNS)
            .enumerate()
            .filter_map(|(s, sun)| Some(job(sun.depth.as_ref()?, s, maps.slot_texels)))
            .collect();
        if jobs.is_empty() {
            return;
        }
        let mut all = jobs.clone();
        all.resize(MAX_SUNS, bytemuck::Zeroable::zeroed());
        self.queue
            .write_buffer(&maps.jobs, 0, bytemuck::cast_slice(&all));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("sun depth"),
            timestamp_writes: compute_pass_writes(self.pass_timestamps("sun depth", None)),
        });
        pass.set_pipeline(&self.sun_depth.pipeline);
        pass.set_bind_group(0, &maps.bind, &[]);
        let groups = (maps.slot_texels as u32).div_ceil(WORKGROUP);
        pass.dispatch_workgroups(groups, MAX_SUNS as u32, 1);
        drop(pass);
        self.record_occluders(encoder, maps, suns);
    }

    /// Records, after the suns' own maps, a dispatch per other walker in the way of each
    /// sun ([`SunDepth::with_occluders`]): its hull walked along the map's lines.
    fn record_occluders(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        maps: &PoseSunMaps,
        suns: &[SunLight],
    ) {
        for (s, sun) in suns.iter().take(MAX_SUNS).enumerate() {
            let Some(map) = sun.depth.as_ref() else {
                continue;
            };
            for o in &map.occluders {
                let hull = self.sun_depth.hulls.get(Arc::as_ptr(&o.hull) as usize, || {
                    let (proxy, words) = crate::proxy::Proxy::new(Some((*o.hull).clone())).gpu();
                    let upload = |label, bytes: &[u8]| {
                        self.device
                            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                                label: Some(label),
                                contents: bytes,
                                usage: wgpu::BufferUsages::STORAGE,
                            })
                    };
                    OccluderHull {
                        _hull: o.hull.clone(),
                        proxy: upload("occluder hull", bytemuck::bytes_of(&proxy)),
                        words: upload("occluder hull words", bytemuck::cast_slice(&words)),
                    }
                });
                let there = o.here_from_there.inverse();
                let r = there.rotation;
                let job = GpuSunOccluderJob {
                    map: job(map, s, maps.slot_texels),
                    there_x: r.x_axis.extend(0.0).to_array(),
                    there_y: r.y_axis.extend(0.0).to_array(),
                    there_z: r.z_axis.extend(0.0).to_array(),
                    there_t: there.translation.extend(0.0).to_array(),
                };
                let jobs = self
                    .device
                    .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("sun occluder job"),
                        contents: bytemuck::bytes_of(&job),
                        usage: wgpu::BufferUsages::STORAGE,
                    });
                // Bindings 0, 1, 3 and 4 (2 holds the suns' own jobs, which it does not read).
                let entries: Vec<wgpu::BindGroupEntry> = [
                    (0, hull.proxy.as_entire_binding()),
                    (1, hull.words.as_entire_binding()),
                    (3, maps.reach.as_entire_binding()),
                    (4, jobs.as_entire_binding()),
                ]
                .into_iter()
                .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
                .collect();
                let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("sun occluder"),
                    layout: &self.sun_depth.occluder_layout,
                    entries: &entries,
                });
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("sun occluder"),
                    timestamp_writes: compute_pass_writes(
                        self.pass_timestamps("sun occluder", None),
                    ),
                });
                pass.set_pipeline(&self.sun_depth.occluder_pipeline);
                pass.set_bind_group(0, &bind, &[]);
                pass.dispatch_workgroups((map.texels() as u32).div_ceil(WORKGROUP), 1, 1);
            }
        }
    }
}
