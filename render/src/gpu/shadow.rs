//! The relit-shadow pass (`shaders/shadow.wgsl`): every walker's shadow of a frame in one
//! dispatch, each its pose's attenuation maps weighted by the light each condition brings
//! to the ground under the walker's light, written into the walker's layer of the frame's
//! shadows that the composite pass samples. Twin of [`crate::shadow::ShadowMaps::relight`].
//!
//! A pose's maps are uploaded once into one buffer shared by every pose
//! ([`MapsArena`]; walkers of one pose and level share their maps' one copy), and a walker
//! keeps only its weights on the host: a new light changes only those, and nothing is
//! recorded until a frame is drawn. A shadow relit on the host (traced) is kept as a
//! texture of its own and copied into its layer instead.

use std::sync::{Arc, Weak};

use frf_core::image::{Rgb, RgbImage};
use frf_shaders::types::GpuShadowJob;

use super::bind::{
    bind_group, buffer_with, compute_pipeline, empty_buffer, storage, storage_texture_array,
};
use super::pose::{GpuPose, PoseShadow, RelitShadowInfo};
use super::{Gpu, shaders};
use crate::error::{RenderError, Result};
use crate::shadow::{RelitShadow, ShadowMaps};

/// Workgroup side of the pass (`@workgroup_size(8, 8)`).
const WORKGROUP: u32 = 8;

/// The pass's layout and pipeline, and the maps of every pose that casts a shadow.
pub struct ShadowPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    arena: std::sync::Mutex<MapsArena>,
}

impl ShadowPass {
    /// Builds the pass on `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        let module = shaders::module(device, "shadow", shaders::SHADOW);
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow"),
            entries: &[
                storage::<f32>(0, true, c),
                storage::<[f32; 4]>(1, true, c),
                storage::<GpuShadowJob>(2, true, c),
                storage_texture_array(3, wgpu::TextureFormat::Rgba32Float),
            ],
        });
        let pipeline = compute_pipeline(device, "shadow", &[&layout], &module, "relight_shadows");
        Self {
            layout,
            pipeline,
            arena: std::sync::Mutex::new(MapsArena::new(device, 1 << 16)),
        }
    }
}

/// Every pose's shadow maps, one after the other in one buffer: each set placed once,
/// while some walker's shadow holds it (the host's copy names it); when the buffer is
/// full, it is made anew, larger, from the sets still held.
struct MapsArena {
    buffer: wgpu::Buffer,
    /// Floats it holds, and those placed.
    capacity: usize,
    used: usize,
    /// The sets placed, and where each starts (floats).
    placed: Vec<(Weak<ShadowMaps>, usize)>,
}

impl MapsArena {
    fn new(device: &wgpu::Device, capacity: usize) -> Self {
        Self {
            buffer: empty_buffer(
                device,
                "shadow maps",
                capacity * 4,
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            ),
            capacity,
            used: 0,
            placed: Vec::new(),
        }
    }

    /// Where `maps` start, placed (and uploaded through `gpu`) if they are not.
    fn place(&mut self, gpu: &Gpu, maps: &Arc<ShadowMaps>) -> Result<usize> {
        if let Some(&(_, at)) = self
            .placed
            .iter()
            .find(|(p, _)| std::ptr::eq(p.as_ptr(), Arc::as_ptr(maps)))
        {
            return Ok(at);
        }
        let len = floats(maps);
        if self.used + len > self.capacity {
            self.grow(gpu, len)?;
        }
        let at = self.used;
        self.upload(gpu, maps, at);
        self.placed.push((Arc::downgrade(maps), at));
        self.used += len;
        Ok(at)
    }

    /// Makes the buffer anew with room for `more` floats after the sets still held,
    /// which are uploaded again (from their host copies) in the order they were placed.
    fn grow(&mut self, gpu: &Gpu, more: usize) -> Result<()> {
        let held: Vec<Arc<ShadowMaps>> = self
            .placed
            .iter()
            .filter_map(|(p, _)| p.upgrade())
            .collect();
        let needed = held.iter().map(|m| floats(m)).sum::<usize>() + more;
        let limit = gpu.device.limits().max_storage_buffer_binding_size as usize / 4;
        if needed > limit {
            return Err(RenderError::Misuse(format!(
                "the walkers' shadow maps need {} MB, more than one storage binding of {} \
                 holds ({} MB): fewer poses at once, or a coarser shadow level",
                (needed * 4) >> 20,
                gpu.adapter(),
                (limit * 4) >> 20
            )));
        }
        *self = Self::new(
            &gpu.device,
            needed.next_power_of_two().min(limit).max(needed),
        );
        for maps in &held {
            let at = self.used;
            self.upload(gpu, maps, at);
            self.placed.push((Arc::downgrade(maps), at));
            self.used += floats(maps);
        }
        Ok(())
    }

    /// Writes `maps` at `at` (floats) with the queue: ahead of any work submitted after,
    /// whichever encoder records it.
    fn upload(&self, gpu: &Gpu, maps: &ShadowMaps, at: usize) {
        let texels: Vec<f32> = maps
            .maps
            .iter()
            .flat_map(|m| m.pixels().iter().copied())
            .collect();
        gpu.queue
            .write_buffer(&self.buffer, (at * 4) as u64, bytemuck::cast_slice(&texels));
    }
}

/// Floats `maps` take in the arena.
fn floats(maps: &ShadowMaps) -> usize {
    maps.maps.iter().map(|m| m.pixels().len()).sum()
}

/// One walker's shadow to draw into `layer` of a frame's shadows.
pub(super) struct ShadowDraw<'a> {
    pub shadow: &'a PoseShadow,
    pub layer: u32,
}

impl Gpu {
    /// Keeps `maps` relit with the coefficients of every condition of the field
    /// (projected for the ground's frame) as `pose`'s shadow: its weights, kept on the
    /// host until a frame draws it (the maps uploaded the first time a frame does).
    pub fn set_shadow(
        &self,
        pose: &mut GpuPose,
        maps: &Arc<ShadowMaps>,
        coefficients: &[Rgb],
    ) -> Result<()> {
        let n = maps.spec.ground.texels;
        if maps
            .maps
            .iter()
            .any(|m| m.size() != (n as usize, n as usize))
        {
            return Err(RenderError::Misuse(format!(
                "shadow maps are not all {n}x{n}"
            )));
        }
        let weights = maps
            .weights(coefficients)
            .iter()
            .map(|w| [w[0], w[1], w[2], 0.0])
            .collect();
        pose.shadow = Some(PoseShadow::Maps {
            maps: maps.clone(),
            weights,
            info: RelitShadowInfo {
                texels: n,
                extent_m: maps.spec.ground.extent_m,
            },
        });
        Ok(())
    }

    /// Keeps a relit shadow computed on the CPU resident with `pose`.
    pub fn upload_shadow(&self, pose: &mut GpuPose, relit: &RelitShadow) -> Result<()> {
        self.scoped("uploading a relit shadow", || {
            use wgpu::util::DeviceExt;
            let n = relit.ground.texels;
            let data: Vec<f32> = relit
                .image
                .pixels()
                .iter()
                .flat_map(|p| [p[0], p[1], p[2], 1.0])
                .collect();
            let texture = self.device.create_texture_with_data(
                &self.queue,
                &wgpu::TextureDescriptor {
                    label: Some("relit shadow"),
                    size: wgpu::Extent3d {
                        width: n,
                        height: n,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: wgpu::TextureFormat::Rgba32Float,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
                    view_formats: &[],
                },
                wgpu::util::TextureDataOrder::LayerMajor,
                bytemuck::cast_slice(&data),
            );
            pose.shadow = Some(PoseShadow::Relit {
                texture,
                info: RelitShadowInfo {
                    texels: n,
                    extent_m: relit.ground.extent_m,
                },
            });
            Ok(())
        })
    }

    /// Records into `encoder` the shadows of `draws` into their layers of `target` (an
    /// RGBA32F array): those of maps in one pass of one dispatch (timed as `shadow`),
    /// those relit on the host copied.
    pub(super) fn record_shadows(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        draws: &[ShadowDraw],
        target: &wgpu::Texture,
    ) -> Result<()> {
        let mut jobs = Vec::new();
        let mut weights: Vec<[f32; 4]> = Vec::new();
        let mut arena = self.shadow.arena.lock().unwrap_or_else(|e| e.into_inner());
        let mut side = 0;
        for d in draws {
            match d.shadow {
                PoseShadow::Maps {
                    maps,
                    weights: w,
                    info,
                } => {
                    let maps_at = arena.place(self, maps)?;
                    jobs.push(GpuShadowJob {
                        maps_at: maps_at as u32,
                        maps: w.len() as u32,
                        texels: info.texels,
                        weights_at: weights.len() as u32,
                        layer: d.layer,
                        pad: [0; 3],
                    });
                    weights.extend_from_slice(w);
                    side = side.max(info.texels);
                }
                PoseShadow::Relit { texture, info } => encoder.copy_texture_to_texture(
                    texture.as_image_copy(),
                    wgpu::TexelCopyTextureInfo {
                        texture: target,
                        mip_level: 0,
                        origin: wgpu::Origin3d {
                            x: 0,
                            y: 0,
                            z: d.layer,
                        },
                        aspect: wgpu::TextureAspect::All,
                    },
                    wgpu::Extent3d {
                        width: info.texels,
                        height: info.texels,
                        depth_or_array_layers: 1,
                    },
                ),
            }
        }
        if jobs.is_empty() {
            return Ok(());
        }
        if weights.is_empty() {
            // Storage bindings may not be empty.
            weights.push([0.0; 4]);
        }
        let buffer = |label: &str, bytes: &[u8]| {
            buffer_with(&self.device, label, bytes, wgpu::BufferUsages::STORAGE)
        };
        let weights = buffer("shadow weights", bytemuck::cast_slice(&weights));
        let job_buffer = buffer("shadow jobs", bytemuck::cast_slice(&jobs));
        let view = target.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let bind = bind_group(
            &self.device,
            "shadow",
            &self.shadow.layout,
            vec![
                arena.buffer.as_entire_binding(),
                weights.as_entire_binding(),
                job_buffer.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view),
            ],
        );
        drop(arena);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("shadow"),
            timestamp_writes: super::timing::compute_pass_writes(
                self.pass_timestamps("shadow", None),
            ),
        });
        pass.set_pipeline(&self.shadow.pipeline);
        self.dispatched("shadow", 1);
        pass.set_bind_group(0, &bind, &[]);
        let groups = side.div_ceil(WORKGROUP);
        pass.dispatch_workgroups(groups, groups, jobs.len() as u32);
        Ok(())
    }

    /// The relit shadow of `pose` (for tests and inspection): drawn by the pass alone
    /// and read back.
    pub fn read_shadow(&self, pose: &GpuPose) -> Result<Option<RgbImage>> {
        let Some(shadow) = &pose.shadow else {
            return Ok(None);
        };
        self.scoped("reading the relit shadow back", || {
            let n = shadow.info().texels;
            let texture = super::bind::rgba32f(
                &self.device,
                "relit shadow",
                (n, n),
                wgpu::TextureUsages::STORAGE_BINDING
                    | wgpu::TextureUsages::COPY_DST
                    | wgpu::TextureUsages::COPY_SRC,
            );
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("shadow readback"),
                });
            let draws = [ShadowDraw { shadow, layer: 0 }];
            self.record_shadows(&mut encoder, &draws, &texture)?;
            let copied = self.copy_rgba(&mut encoder, &texture, (n, n));
            self.submit([encoder.finish()]);
            let img = self.read_rgba(&copied)?;
            Ok(Some(img.map(|p| [p[0], p[1], p[2]])))
        })
    }
}
