//! Photographs under single lights relit by their per-texel light fit on the GPU
//! (`shaders/light_fit.wgsl`): the twin of
//! [`frf_reflectance::light_fit::LightFit::relight`], tested against it. The photographs
//! and the fit are uploaded once ([`Gpu::upload_light_fit`]); each new light is one
//! dispatch and a readback ([`Gpu::relight_fit`]).

use frf_core::image::{Image, RgbImage};
use frf_reflectance::light_fit::{LightFit, RATIO_FLOOR, nearest_weights};
use frf_shaders::types::GpuLightFitParams;
use glam::Vec3;

use super::bind::{bind_group, buffer_with, compute_pipeline, readback_buffer, storage, uniform};
use super::{Gpu, shaders};
use crate::error::{RenderError, Result};

/// The most nearest lights a relight weighs.
pub const MOST_NEAREST: usize = 4;

/// Photographs and their fit resident on the GPU, with the pass that relights them.
pub struct GpuLightFit {
    pipeline: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    params: wgpu::Buffer,
    relit: wgpu::Buffer,
    size: (usize, usize),
    directions: Vec<Vec3>,
    /// Toward the camera and the glossy lobe's roughness (0: none).
    view: [f32; 4],
}

impl Gpu {
    /// Uploads `images` (one per light of `directions`) and `fit`, made from them.
    pub fn upload_light_fit(
        &self,
        fit: &LightFit,
        images: &[&RgbImage],
        directions: &[Vec3],
    ) -> Result<GpuLightFit> {
        let size = fit.size();
        if images.len() != directions.len()
            || images.is_empty()
            || images.iter().any(|i| i.size() != size)
        {
            return Err(RenderError::Misuse(
                "a light fit's photographs: one per light, each of the fit's size".into(),
            ));
        }
        self.scoped("uploading a light fit", || {
            let texels = size.0 * size.1;
            let storage_usage = wgpu::BufferUsages::STORAGE;
            let photos: Vec<[f32; 4]> = images
                .iter()
                .flat_map(|img| img.pixels().iter().map(|p| [p[0], p[1], p[2], 1.0]))
                .collect();
            let dirs: Vec<[f32; 4]> = directions
                .iter()
                .map(|d| d.extend(0.0).to_array())
                .collect();
            let (mut normals, mut albedo) =
                (Vec::with_capacity(texels), Vec::with_capacity(texels));
            // The glossy lobe's strength in the albedo's fourth.
            let strength = |i: usize| fit.gloss().map_or(0.0, |g| g.strength[i]);
            for i in 0..texels {
                match fit.texel(i) {
                    Some((n, a)) => {
                        normals.push(n.extend(1.0).to_array());
                        albedo.push([a[0], a[1], a[2], strength(i)]);
                    }
                    None => {
                        normals.push([0.0; 4]);
                        albedo.push([0.0; 4]);
                    }
                }
            }
            let c = wgpu::ShaderStages::COMPUTE;
            let layout = self
                .device
                .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("light fit"),
                    entries: &[
                        uniform::<GpuLightFitParams>(0, c),
                        storage::<[f32; 4]>(1, true, c),
                        storage::<[f32; 4]>(2, true, c),
                        storage::<[f32; 4]>(3, true, c),
                        storage::<[f32; 4]>(4, true, c),
                        storage::<[f32; 4]>(5, false, c),
                    ],
                });
            let module = shaders::module(&self.device, "light fit", shaders::LIGHT_FIT);
            let pipeline = compute_pipeline(
                &self.device,
                "light fit",
                &[&layout],
                &module,
                "relight_fit",
            );
            let params = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("light fit params"),
                size: size_of::<GpuLightFitParams>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let relit = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("relit"),
                size: (texels * 16) as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let buffers = [
                buffer_with(
                    &self.device,
                    "photos",
                    bytemuck::cast_slice(&photos),
                    storage_usage,
                ),
                buffer_with(
                    &self.device,
                    "light directions",
                    bytemuck::cast_slice(&dirs),
                    storage_usage,
                ),
                buffer_with(
                    &self.device,
                    "normals",
                    bytemuck::cast_slice(&normals),
                    storage_usage,
                ),
                buffer_with(
                    &self.device,
                    "albedo",
                    bytemuck::cast_slice(&albedo),
                    storage_usage,
                ),
            ];
            let mut resources = vec![params.as_entire_binding()];
            resources.extend(buffers.iter().map(|b| b.as_entire_binding()));
            resources.push(relit.as_entire_binding());
            let group = bind_group(&self.device, "light fit", &layout, resources);
            Ok(GpuLightFit {
                pipeline,
                group,
                params,
                relit,
                size,
                directions: directions.to_vec(),
                view: fit
                    .gloss()
                    .map_or([0.0; 4], |g| g.view.extend(g.roughness).to_array()),
            })
        })
    }

    /// The photographs of `fit` relit under a unit light from `l`, weighing the
    /// `nearest` nearest lights (at most [`MOST_NEAREST`]), as
    /// [`LightFit::relight`] does.
    pub fn relight_fit(&self, fit: &GpuLightFit, l: Vec3, nearest: usize) -> Result<RgbImage> {
        let weights = nearest_weights(&fit.directions, l, nearest.min(MOST_NEAREST));
        let (mut indices, mut w) = ([0u32; 4], [0.0f32; 4]);
        for (j, &(k, wk)) in weights.iter().enumerate() {
            indices[j] = k as u32;
            w[j] = wk;
        }
        let texels = fit.size.0 * fit.size.1;
        let params = GpuLightFitParams {
            texels: texels as u32,
            lights: fit.directions.len() as u32,
            nearest: weights.len() as u32,
            pad0: 0,
            light: l.normalize_or_zero().extend(RATIO_FLOOR).to_array(),
            indices,
            weights: w,
            view: fit.view,
        };
        self.scoped("relighting by a light fit", || {
            self.queue
                .write_buffer(&fit.params, 0, bytemuck::bytes_of(&params));
            let readback = readback_buffer(&self.device, "relit readback", (texels * 16) as u64);
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("light fit"),
                });
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("light fit"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&fit.pipeline);
                pass.set_bind_group(0, &fit.group, &[]);
                pass.dispatch_workgroups((texels as u32).div_ceil(64), 1, 1);
            }
            encoder.copy_buffer_to_buffer(&fit.relit, 0, &readback, 0, (texels * 16) as u64);
            self.submit([encoder.finish()]);
            let bytes = self.read_buffer(&readback)?;
            let pixels: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
            Ok(Image::from_vec(
                fit.size.0,
                fit.size.1,
                pixels.iter().map(|p| [p[0], p[1], p[2]]).collect(),
            )?)
        })
    }
}
