//! The relit-shadow pass (`shaders/shadow.wgsl`): once per pose and lighting, the pose's
//! attenuation maps weighted by the light each condition brings to the ground, into an
//! RGBA32F texture of the ground patch that the composite pass samples. Twin of
//! [`crate::shadow::ShadowMaps::relight`].

use frf_core::image::{Rgb, RgbImage};
use wgpu::util::DeviceExt;

use super::bind::{
    bind_group, buffer_with, compute_pipeline, rgba32f, storage, storage_texture, uniform,
};
use super::deferred::{Dispatch, Kind};
use super::pose::{GpuPose, MapRelight, RelitShadowInfo};
use super::{Gpu, shaders};
use crate::error::{RenderError, Result};
use crate::shadow::{RelitShadow, ShadowMaps};
use frf_shaders::types::GpuShadowParams;

/// Workgroup side of the pass (`@workgroup_size(8, 8)`).
const WORKGROUP: u32 = 8;

/// The pass's layout and pipeline.
pub struct ShadowPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl ShadowPass {
    /// Builds the pass on `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        let module = shaders::module(device, "shadow", shaders::SHADOW);
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow"),
            entries: &[
                uniform::<GpuShadowParams>(0, c),
                storage::<f32>(1, true, c),
                storage::<[f32; 4]>(2, true, c),
                storage_texture(3, wgpu::TextureFormat::Rgba32Float),
            ],
        });
        let pipeline = compute_pipeline(device, "shadow", &[&layout], &module, "relight_shadow");
        Self { layout, pipeline }
    }
}

impl Gpu {
    /// Relights `maps` with the coefficients of every condition of the field (projected
    /// for the ground's frame) and keeps the result resident with `pose`. The maps are
    /// uploaded once: relit again (a new light), only the weights are written. Recorded
    /// with the pending work ([`Gpu::submit`]), not submitted.
    pub fn set_shadow(
        &self,
        pose: &mut GpuPose,
        maps: &ShadowMaps,
        coefficients: &[Rgb],
    ) -> Result<()> {
        self.scoped("relighting the shadow maps", || {
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
            let mut weights: Vec<[f32; 4]> = maps
                .weights(coefficients)
                .iter()
                .map(|w| [w[0], w[1], w[2], 0.0])
                .collect();
            // Storage bindings may not be empty.
            if weights.is_empty() {
                weights.push([0.0; 4]);
            }
            let kept = pose
                .shadow_maps
                .take()
                .filter(|k| k.texels == n && k.maps == maps.maps.len() && pose.shadow.is_some());
            let relight = match kept {
                Some(k) => k,
                None => self.map_relight(pose, maps, weights.len())?,
            };
            self.upload(&relight.weights, 0, bytemuck::cast_slice(&weights));
            let groups = n.div_ceil(WORKGROUP);
            self.defer(
                Kind::Shadow,
                [Dispatch {
                    pipeline: self.shadow.pipeline.clone(),
                    bind: relight.bind.clone(),
                    groups: [groups, groups, 1],
                }],
            );
            pose.shadow_maps = Some(relight);
            Ok(())
        })
    }

    /// Uploads `maps` for `pose`: the maps, a weight buffer of `weights` entries and the
    /// relit texture (set as the pose's shadow), bound together.
    fn map_relight(
        &self,
        pose: &mut GpuPose,
        maps: &ShadowMaps,
        weights: usize,
    ) -> Result<MapRelight> {
        let n = maps.spec.ground.texels;
        let mut texels: Vec<f32> = maps
            .maps
            .iter()
            .flat_map(|m| m.pixels().iter().copied())
            .collect();
        if texels.is_empty() {
            texels.push(0.0);
        }
        let buffer =
            |label: &str, contents: &[u8], usage| buffer_with(&self.device, label, contents, usage);
        let params = GpuShadowParams {
            texels: n,
            maps: maps.maps.len() as u32,
            pad: [0; 2],
        };
        let params = buffer(
            "shadow params",
            bytemuck::bytes_of(&params),
            wgpu::BufferUsages::UNIFORM,
        );
        let map_buffer = buffer(
            "shadow maps",
            bytemuck::cast_slice(&texels),
            wgpu::BufferUsages::STORAGE,
        );
        let weight_buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shadow weights"),
            size: (weights * 16) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let relit = rgba32f(
            &self.device,
            "relit shadow",
            (n, n),
            wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        );
        let view = relit.create_view(&wgpu::TextureViewDescriptor::default());
        let bind = bind_group(
            &self.device,
            "shadow",
            &self.shadow.layout,
            vec![
                params.as_entire_binding(),
                map_buffer.as_entire_binding(),
                weight_buffer.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view),
            ],
        );
        pose.shadow = Some((
            relit,
            RelitShadowInfo {
                texels: n,
                extent_m: maps.spec.ground.extent_m,
            },
        ));
        Ok(MapRelight {
            texels: n,
            maps: maps.maps.len(),
            weights: weight_buffer,
            bind,
        })
    }

    /// Keeps a relit shadow computed on the CPU resident with `pose`.
    pub fn upload_shadow(&self, pose: &mut GpuPose, relit: &RelitShadow) -> Result<()> {
        self.scoped("uploading a relit shadow", || {
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
            pose.shadow = Some((
                texture,
                RelitShadowInfo {
                    texels: n,
                    extent_m: relit.ground.extent_m,
                },
            ));
            pose.shadow_maps = None;
            Ok(())
        })
    }

    /// Reads back the relit shadow of `pose` (for tests and inspection).
    pub fn read_shadow(&self, pose: &GpuPose) -> Result<Option<RgbImage>> {
        let Some((texture, info)) = &pose.shadow else {
            return Ok(None);
        };
        self.scoped("reading the relit shadow back", || {
            let size = (info.texels, info.texels);
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("shadow readback"),
                });
            let copied = self.copy_rgba(&mut encoder, texture, size);
            self.submit([encoder.finish()]);
            let img = self.read_rgba(&copied)?;
            Ok(Some(img.map(|p| [p[0], p[1], p[2]])))
        })
    }
}
