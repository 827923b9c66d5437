//! What a composited frame of one size, number of walkers and shadow-map size needs
//! besides its inputs, made once and kept ([`Gpu::composite_targets`]): the four RGBA32F
//! targets, the walkers' shadow maps gathered into one array, the uniforms, walker
//! buffer and tile lists (written with `write_buffer` each frame) and the frame's bind
//! group. Its images are read back through staging sets of their own
//! ([`super::readback`]), so that the next frame draws into these targets while the last
//! is mapped.

use std::sync::Arc;

use super::bind::{FLOAT, compute_pipeline, storage, texture_2d, texture_array, uniform};
use super::bind::{rgba32f, storage_texture, uniform_buffer};
use super::kept::Kept;
use super::{Gpu, shaders};
use crate::footprint::TileLists;
use frf_shaders::types::{GpuComposite, GpuFrame, GpuInstance};

/// The pass's layouts and pipeline.
pub struct CompositePass {
    pub(super) frame_layout: wgpu::BindGroupLayout,
    pub(super) image_layout: wgpu::BindGroupLayout,
    pub(super) pipeline: wgpu::ComputePipeline,
}

impl CompositePass {
    /// Builds the pass on `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        let module = shaders::module(device, "composite", shaders::COMPOSITE);
        let c = wgpu::ShaderStages::COMPUTE;
        let target = |binding| storage_texture(binding, wgpu::TextureFormat::Rgba32Float);
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("composite frame"),
            entries: &[
                uniform::<GpuFrame>(0, c),
                uniform::<GpuComposite>(1, c),
                storage::<GpuInstance>(2, true, c),
                storage::<u32>(3, true, c),
                target(4),
                target(5),
                target(6),
                target(7),
            ],
        });
        let image_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("composite images"),
            entries: &[
                texture_array(0, FLOAT),
                texture_2d(1, FLOAT),
                texture_2d(2, FLOAT),
                texture_array(3, FLOAT),
                texture_array(4, FLOAT),
            ],
        });
        let pipeline = compute_pipeline(
            device,
            "composite",
            &[&frame_layout, &image_layout],
            &module,
            "cs_composite",
        );
        Self {
            frame_layout,
            image_layout,
            pipeline,
        }
    }
}

/// Image bind groups kept per set of targets: a shot alternates between few backdrops.
const IMAGE_GROUPS: usize = 2;

/// The key of a set of composite targets: size, walkers, shadow-map texels.
pub(super) type CompositeKey = ((u32, u32), u32, u32);

/// The composite pass's kept targets and buffers for one [`CompositeKey`].
pub(super) struct CompositeTargets {
    /// Names the targets in the keys of bind groups made of them ([`super::kept`]).
    pub(super) id: u64,
    /// Composite, relative irradiance (shadow), backdrop, subjects alone.
    pub(super) targets: [wgpu::Texture; 4],
    /// Per walker (back to front), its relit shadow map.
    pub(super) shadows: wgpu::Texture,
    pub(super) frame: wgpu::Buffer,
    pub(super) params: wgpu::Buffer,
    pub(super) instances: wgpu::Buffer,
    /// The frame's tile lists ([`crate::footprint::TileLists`]).
    pub(super) tiles: wgpu::Buffer,
    pub(super) frame_group: wgpu::BindGroup,
    /// The image bind groups made for these targets, per drawn subjects and backdrop
    /// (their ids).
    pub(super) image_groups: Kept<(u64, u64), wgpu::BindGroup>,
}

impl CompositeTargets {
    fn new(device: &wgpu::Device, pass: &CompositePass, key: CompositeKey) -> Self {
        let (size, walkers, texels) = key;
        // Written by the compute pass; bound as textures by a window's present pass
        // ([`super::present`]).
        let usage = wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::TEXTURE_BINDING;
        let labels = [
            "composite",
            "shadow layer",
            "backdrop layer",
            "subject layer",
        ];
        let targets = labels.map(|label| rgba32f(device, label, size, usage));
        let target_views = targets
            .each_ref()
            .map(|t| t.create_view(&wgpu::TextureViewDescriptor::default()));
        let shadows = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("walker shadows"),
            size: wgpu::Extent3d {
                width: texels,
                height: texels,
                depth_or_array_layers: walkers,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            // Written by the shadow pass, or copied into from a shadow relit on the host.
            usage: wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let frame = uniform_buffer(device, "composite camera", size_of::<GpuFrame>());
        let params = uniform_buffer(device, "composite params", size_of::<GpuComposite>());
        let instances = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("walkers"),
            size: (size_of::<GpuInstance>() * walkers as usize) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let tiles = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("tile lists"),
            size: (4 * TileLists::capacity(size.0, size.1, walkers)) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let frame_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("composite frame"),
            layout: &pass.frame_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: frame.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: instances.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: tiles.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(&target_views[0]),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::TextureView(&target_views[1]),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: wgpu::BindingResource::TextureView(&target_views[2]),
                },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: wgpu::BindingResource::TextureView(&target_views[3]),
                },
            ],
        });
        Self {
            id: super::kept::unique_id(),
            targets,
            shadows,
            frame,
            params,
            instances,
            tiles,
            frame_group,
            image_groups: Kept::new(IMAGE_GROUPS),
        }
    }
}

impl Gpu {
    /// The kept composite targets for `key` (made on first use; the few most recently
    /// used are kept).
    pub(super) fn composite_targets(&self, key: CompositeKey) -> Arc<CompositeTargets> {
        self.composite_targets.get(key, || {
            CompositeTargets::new(&self.device, &self.composite, key)
        })
    }
}
