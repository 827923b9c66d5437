//! The frame pass (`shaders/rebin.wgsl`): for every pixel of the virtual camera, a
//! full-screen triangle re-bins the ray through the cylinder of camera centres and morphs
//! the quad's pre-lit views there, into an RGBA32F target (premultiplied linear RGBA);
//! pixel classes (inside, clamped above or below, missed) are counted. Twin of
//! [`crate::cpu::render_cpu`].

use frf_core::camera::Camera;
use frf_core::image::{Image, Rgba};
use wgpu::util::DeviceExt;

use super::bind::{
    cleared, copy_to_buffer, full_screen_pipeline, padded_row, readback_buffer, rgba_pixels,
    storage, texture_array, uniform,
};
use super::pose::GpuPose;
use super::types::GpuFrame;
use super::{Gpu, shaders};
use crate::cpu::FrameStats;
use crate::error::Result;
use crate::morph::Variant;

/// The frame pass's layouts and pipeline.
pub struct RebinPass {
    pub(super) frame_layout: wgpu::BindGroupLayout,
    pub(super) pose_layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

impl RebinPass {
    /// Builds the pass on `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        let rebin_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("rebin"),
            source: wgpu::ShaderSource::Wgsl(shaders::composed(shaders::REBIN).into()),
        });
        let f = wgpu::ShaderStages::FRAGMENT;
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame"),
            entries: &[uniform(0, f), storage(1, false, f)],
        });
        let pose_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pose"),
            entries: &[
                texture_array(0, wgpu::TextureSampleType::Uint),
                texture_array(1, wgpu::TextureSampleType::Sint),
                storage(2, true, f),
                storage(3, true, f),
                storage(4, true, f),
                storage(5, true, f),
                storage(6, true, f),
                storage(7, true, f),
            ],
        });
        let pipeline = full_screen_pipeline(
            device,
            "rebin",
            &[&frame_layout, &pose_layout],
            &rebin_module,
            "fs_main",
            1,
        );
        Self {
            frame_layout,
            pose_layout,
            pipeline,
        }
    }
}

/// A frame's subjects, drawn and still on the GPU.
pub(super) struct Subjects {
    /// Pixel-class counters, summed over the instances.
    pub stats: wgpu::Buffer,
    /// One layer per instance, in drawing order (back to front): premultiplied RGBA32F.
    pub texture: wgpu::Texture,
}

/// The frame uniform of `camera` for `pose` (`pose` `None`: the camera alone, for passes
/// that do not read a pose).
pub(super) fn frame_uniform(pose: Option<&GpuPose>, camera: &Camera, variant: Variant) -> GpuFrame {
    let r = camera.world_from_camera.rotation;
    let k = &camera.intrinsics;
    let mut f = GpuFrame {
        axis_x: r.x_axis.extend(0.0).to_array(),
        axis_y: r.y_axis.extend(0.0).to_array(),
        axis_z: r.z_axis.extend(0.0).to_array(),
        centre: camera.centre().extend(1.0).to_array(),
        intrinsics: [k.fx, k.fy, k.cx, k.cy],
        size: [camera.width, camera.height],
        variant: variant.index(),
        quad_count: 0,
        columns: 1,
        rows: 1,
        crop_origin: [0, 0],
        crop_size: [1, 1],
        flags: variant.flags(),
        pad: 0,
    };
    if let Some(pose) = pose {
        f.quad_count = pose.quad_count;
        f.columns = pose.geometry.columns as u32;
        f.rows = pose.geometry.rows as u32;
        f.crop_origin = [pose.geometry.crop.x0, pose.geometry.crop.y0];
        f.crop_size = [pose.geometry.crop.width, pose.geometry.crop.height];
    }
    f
}

impl Gpu {
    /// Records the frame pass of every instance into `encoder`: each pose drawn by its
    /// camera (in its subject frame) into its own layer of one texture array of `size`,
    /// in the order given (back to front; the composite pass puts each over the ones
    /// before it).
    pub(super) fn draw_subjects(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        instances: &[(&GpuPose, Camera)],
        size: (u32, u32),
        variant: Variant,
    ) -> Subjects {
        let stats = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("stats"),
                contents: &[0u8; 16],
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            });
        let texture = self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("subjects"),
            size: wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: instances.len().max(1) as u32,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        for (layer, (pose, camera)) in instances.iter().enumerate() {
            let frame_buffer = self
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("frame"),
                    contents: bytemuck::bytes_of(&frame_uniform(Some(pose), camera, variant)),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
            let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("frame"),
                layout: &self.rebin.frame_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: frame_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: stats.as_entire_binding(),
                    },
                ],
            });
            let view = texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: layer as u32,
                array_layer_count: Some(1),
                ..Default::default()
            });
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("rebin"),
                color_attachments: &[cleared(&view)],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.rebin.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.set_bind_group(1, &pose.bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        Subjects { stats, texture }
    }

    /// Copies the pixel-class counters of a drawn frame for readback.
    pub(super) fn copy_stats(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        subject: &Subjects,
    ) -> wgpu::Buffer {
        let readback = readback_buffer(&self.device, "stats readback", 16);
        encoder.copy_buffer_to_buffer(&subject.stats, 0, &readback, 0, 16);
        readback
    }

    /// The counters read back.
    pub(super) fn read_stats(&self, readback: &wgpu::Buffer) -> Result<FrameStats> {
        let counts = self.read_buffer(readback)?;
        let counts: &[u32] = bytemuck::cast_slice(&counts);
        Ok(FrameStats {
            inside: counts[0] as usize,
            clamped_above: counts[1] as usize,
            clamped_below: counts[2] as usize,
            missed: counts[3] as usize,
        })
    }

    /// Copies an RGBA32F texture of `size` into a new readback buffer; returns it and its
    /// padded row length.
    pub(super) fn copy_rgba(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        size: (u32, u32),
    ) -> (wgpu::Buffer, u32) {
        let row = padded_row(size.0 * 16);
        let buffer = readback_buffer(&self.device, "readback", (row * size.1) as u64);
        copy_to_buffer(encoder, texture, &buffer, row, (size.0, size.1, 1));
        (buffer, row)
    }

    /// Reads back what [`Gpu::copy_rgba`] copied.
    pub(super) fn read_rgba(
        &self,
        (buffer, row): &(wgpu::Buffer, u32),
        size: (u32, u32),
    ) -> Result<Image<Rgba>> {
        let bytes = self.read_buffer(buffer)?;
        Ok(Image::from_vec(
            size.0 as usize,
            size.1 as usize,
            rgba_pixels(&bytes, size, *row),
        )?)
    }

    /// Renders the subject of a frame of `camera` (subject frame) with `variant`:
    /// premultiplied linear RGBA, and what happened to its pixels.
    pub fn render(
        &self,
        pose: &GpuPose,
        camera: &Camera,
        variant: Variant,
    ) -> Result<(Image<Rgba>, FrameStats)> {
        self.scoped("rendering a frame", || {
            let size = (camera.width, camera.height);
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("frame"),
                });
            let subject = self.draw_subjects(&mut encoder, &[(pose, *camera)], size, variant);
            let image = self.copy_rgba(&mut encoder, &subject.texture, size);
            let stats = self.copy_stats(&mut encoder, &subject);
            self.queue.submit([encoder.finish()]);
            Ok((self.read_rgba(&image, size)?, self.read_stats(&stats)?))
        })
    }
}
