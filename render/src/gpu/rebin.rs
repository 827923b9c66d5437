//! The frame pass (`shaders/rebin.wgsl`): for every pixel of the virtual camera, a
//! full-screen triangle re-bins the ray through the cylinder of camera centres and morphs
//! the quad's pre-lit views there, into an RGBA32F target (premultiplied linear RGBA);
//! pixel classes (inside, clamped above or below, missed) are counted. Twin of
//! [`crate::cpu::render_cpu`].

use std::sync::Arc;

use frf_core::camera::Camera;
use frf_core::image::{Image, Rgba};

use super::Gpu;
use super::bind::{
    cleared, compute_pipeline, full_screen_pipeline, readback_buffer, sampler, storage,
    storage_min, storage_texture, texture_array, uniform, uniform_buffer,
};
use super::formats::PoseFormats;
use super::pose::{GpuPose, PoseBinding};
use super::readback::Readback;
use super::types::{GpuColumnIndex, GpuFrame, GpuProxy, GpuQuad, GpuQuadFrame, GpuView};
use crate::cpu::FrameStats;
use crate::error::Result;
use crate::footprint::PixelBox;
use crate::morph::Variant;

/// Whether a pass runs as a full-screen triangle or as a compute dispatch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PassKind {
    /// Fragment shader into a colour attachment.
    Fragment,
    /// Compute shader (8 x 8 workgroups) into a storage texture.
    Compute,
}

impl PassKind {
    /// Both.
    pub const ALL: [PassKind; 2] = [PassKind::Fragment, PassKind::Compute];

    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            PassKind::Fragment => "fragment",
            PassKind::Compute => "compute",
        }
    }
}

/// Workgroups of 8 x 8 covering `size`.
pub(super) fn workgroups(size: (u32, u32)) -> (u32, u32) {
    (size.0.div_ceil(8), size.1.div_ceil(8))
}

/// The frame pass's layouts and pipelines for one [`PoseFormats`].
pub struct RebinPass {
    /// How a pose is bound for these pipelines: the storage they read, the layout and
    /// sampler of bind group 1.
    pub pose: PoseBinding,
    pub(super) frame_layout: wgpu::BindGroupLayout,
    pub(super) compute_layout: wgpu::BindGroupLayout,
    pub(super) classes_layout: wgpu::BindGroupLayout,
    pub(super) fragment: wgpu::RenderPipeline,
    pub(super) compute: wgpu::ComputePipeline,
    pub(super) classes: wgpu::ComputePipeline,
}

impl RebinPass {
    /// Builds the pass on `device` for poses stored as `formats`.
    pub fn new(device: &wgpu::Device, formats: PoseFormats) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("rebin"),
            source: wgpu::ShaderSource::Wgsl(formats.rebin_source().into()),
        });
        let both = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let layout = |label: &str, entries: &[wgpu::BindGroupLayoutEntry]| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries,
            })
        };
        let frame_layout = layout("frame", &[uniform::<GpuFrame>(0, both)]);
        let compute_layout = layout(
            "frame (compute)",
            &[
                uniform::<GpuFrame>(0, both),
                storage::<[u32; 4]>(1, false, wgpu::ShaderStages::COMPUTE),
                storage_texture(2, wgpu::TextureFormat::Rgba32Float),
            ],
        );
        let classes_layout = layout(
            "frame (classes)",
            &[
                uniform::<GpuFrame>(0, both),
                storage::<[u32; 4]>(1, false, wgpu::ShaderStages::COMPUTE),
            ],
        );
        let pose_layout = layout(
            "pose",
            &[
                texture_array(0, formats.image.sample_type()),
                texture_array(1, formats.flow.sample_type()),
                storage::<GpuView>(2, true, both),
                storage::<GpuQuad>(3, true, both),
                storage::<[[f32; 256]; 2]>(4, true, both),
                storage::<GpuProxy>(5, true, both),
                storage::<u32>(6, true, both),
                // The column index's header and at least one span's range.
                storage_min(7, true, both, (size_of::<GpuColumnIndex>() + 8) as u64),
                sampler(8, both),
                storage::<GpuQuadFrame>(9, true, both),
            ],
        );
        let fragment = full_screen_pipeline(
            device,
            "rebin",
            &[&frame_layout, &pose_layout],
            &module,
            "fs_main",
            1,
        );
        let compute = compute_pipeline(
            device,
            "rebin",
            &[&compute_layout, &pose_layout],
            &module,
            "cs_main",
        );
        let classes = compute_pipeline(
            device,
            "classes",
            &[&classes_layout, &pose_layout],
            &module,
            "cs_classes",
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("bilinear"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Self {
            pose: PoseBinding {
                formats,
                layout: pose_layout,
                sampler,
            },
            frame_layout,
            compute_layout,
            classes_layout,
            fragment,
            compute,
            classes,
        }
    }
}

/// A frame's subjects, drawn and still on the GPU: one layer per instance of the
/// targets' texture, in drawing order (back to front), premultiplied RGBA32F, and the
/// pixel-class counters summed over the instances.
pub(super) struct Subjects {
    targets: Arc<SubjectTargets>,
    /// Pixels outside the walkers' bounds, summed over the walkers: not shaded, missed.
    outside: usize,
}

impl Subjects {
    /// The texture array of the subjects.
    pub fn texture(&self) -> &wgpu::Texture {
        self.targets.texture()
    }

    /// The id of the targets they are drawn into ([`SubjectTargets::id`]).
    pub fn id(&self) -> u64 {
        self.targets.id
    }

    /// The view of walker `layer`'s layer.
    pub(super) fn layer_view(&self, layer: usize) -> &wgpu::TextureView {
        self.targets.layer_view(layer)
    }
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
        bounds: PixelBox::whole(camera.width, camera.height).to_array(),
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

/// A frame's targets and per-frame buffers for one size and number of walkers, made once
/// and kept ([`Gpu::subject_targets`]): the subjects' texture array, its layer views, the
/// pixel-class counters, staging buffers to read them back through, and per layer a frame uniform (written with `write_buffer`)
/// with the bind groups of the fragment, compute and class passes.
pub(super) struct SubjectTargets {
    /// Names these targets in the keys of bind groups made of them ([`super::kept`]).
    pub(super) id: u64,
    texture: wgpu::Texture,
    layers: Vec<LayerTargets>,
    stats: wgpu::Buffer,
    /// Staging buffers of the counters and of layer 0.
    stats_readback: wgpu::Buffer,
    readback: Readback,
}

struct LayerTargets {
    view: wgpu::TextureView,
    uniform: wgpu::Buffer,
    fragment: wgpu::BindGroup,
    compute: wgpu::BindGroup,
    classes: wgpu::BindGroup,
}

impl SubjectTargets {
    pub(super) fn new(
        device: &wgpu::Device,
        pass: &RebinPass,
        size: (u32, u32),
        layers: u32,
    ) -> Self {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("subjects"),
            size: wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: layers,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST
                | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let stats = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("stats"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = |label, layout, entries: &[wgpu::BindGroupEntry]| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout,
                entries,
            })
        };
        let layers = (0..layers)
            .map(|layer| {
                let view = texture.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                });
                let uniform = uniform_buffer(device, "frame", std::mem::size_of::<GpuFrame>());
                let frame = wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                };
                LayerTargets {
                    fragment: group("frame", &pass.frame_layout, std::slice::from_ref(&frame)),
                    compute: group(
                        "frame (compute)",
                        &pass.compute_layout,
                        &[
                            frame.clone(),
                            wgpu::BindGroupEntry {
                                binding: 1,
                                resource: stats.as_entire_binding(),
                            },
                            wgpu::BindGroupEntry {
                                binding: 2,
                                resource: wgpu::BindingResource::TextureView(&view),
                            },
                        ],
                    ),
                    classes: group(
                        "frame (classes)",
                        &pass.classes_layout,
                        &[
                            frame.clone(),
                            wgpu::BindGroupEntry {
                                binding: 1,
                                resource: stats.as_entire_binding(),
                            },
                        ],
                    ),
                    view,
                    uniform,
                }
            })
            .collect();
        Self {
            id: super::kept::unique_id(),
            texture,
            layers,
            stats,
            stats_readback: readback_buffer(device, "stats readback", 16),
            readback: Readback::new(device, "subject readback", size),
        }
    }
}

impl SubjectTargets {
    /// The texture array of the subjects.
    pub(super) fn texture(&self) -> &wgpu::Texture {
        &self.texture
    }

    /// The frame uniform of `layer`.
    pub(super) fn uniform(&self, layer: usize) -> &wgpu::Buffer {
        &self.layers[layer].uniform
    }

    /// The view of `layer`.
    pub(super) fn layer_view(&self, layer: usize) -> &wgpu::TextureView {
        &self.layers[layer].view
    }

    /// The fragment pass's frame bind group of `layer`.
    pub(super) fn fragment_group(&self, layer: usize) -> &wgpu::BindGroup {
        &self.layers[layer].fragment
    }

    /// The compute pass's frame bind group of `layer`.
    pub(super) fn compute_group(&self, layer: usize) -> &wgpu::BindGroup {
        &self.layers[layer].compute
    }
}

impl RebinPass {
    /// Records pose `pose` drawn by the frame uniform already written to `layer`'s buffer
    /// (whose bounds are `within`), into `layer` of `targets`, by `stage`, with the pass's
    /// timestamps when given: the pixels `within` are shaded; the rest of the layer is
    /// left as it was by a compute pass (nothing reads a layer outside its walker's box:
    /// the composite and the morph in time read within it) and cleared by a fragment
    /// pass. Its pixel classes (of the pixels within) are counted into the targets'
    /// counters by the compute pass itself, and after a fragment pass by a pass of their
    /// own when `classes`.
    #[allow(clippy::too_many_arguments)] // one pass's every input, named at the call
    pub(super) fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &SubjectTargets,
        layer: usize,
        pose_group: &wgpu::BindGroup,
        stage: PassKind,
        within: PixelBox,
        timestamps: Option<(&wgpu::QuerySet, u32)>,
        classes: bool,
    ) {
        let t = &targets.layers[layer];
        let size = within.size();
        match stage {
            PassKind::Fragment => {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("rebin"),
                    color_attachments: &[cleared(&t.view)],
                    depth_stencil_attachment: None,
                    timestamp_writes: super::timing::render_pass_writes(timestamps),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                if within.pixels() > 0 {
                    pass.set_scissor_rect(within.x0, within.y0, size.0, size.1);
                    pass.set_pipeline(&self.fragment);
                    pass.set_bind_group(0, &t.fragment, &[]);
                    pass.set_bind_group(1, pose_group, &[]);
                    pass.draw(0..3, 0..1);
                }
            }
            PassKind::Compute => {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("rebin"),
                    timestamp_writes: super::timing::compute_pass_writes(timestamps),
                });
                pass.set_pipeline(&self.compute);
                pass.set_bind_group(0, &t.compute, &[]);
                pass.set_bind_group(1, pose_group, &[]);
                let (x, y) = workgroups(size);
                if x * y > 0 {
                    pass.dispatch_workgroups(x, y, 1);
                }
            }
        }
        // The compute pass counts as it shades; a fragment pass needs its own.
        if classes && stage == PassKind::Fragment && within.pixels() > 0 {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("classes"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.classes);
            pass.set_bind_group(0, &t.classes, &[]);
            pass.set_bind_group(1, pose_group, &[]);
            let (x, y) = workgroups(size);
            pass.dispatch_workgroups(x, y, 1);
        }
    }
}

impl Gpu {
    /// The kept targets of frames of `size` with `layers` walkers (made on first use;
    /// the few most recently used are kept).
    pub(super) fn subject_targets(&self, size: (u32, u32), layers: u32) -> Arc<SubjectTargets> {
        self.targets.get((size, layers), || {
            SubjectTargets::new(&self.device, &self.rebin, size, layers)
        })
    }

    /// Records the frame pass of every instance into `encoder`: each pose drawn by its
    /// camera (in its subject frame) within its pixel box into its own layer of one
    /// texture array of `size`, in the order given (back to front; the composite pass
    /// puts each over the ones before it), and their pixel classes counted (the pixels
    /// outside a box as missed).
    pub(super) fn draw_subjects(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        instances: &[(&GpuPose, Camera, PixelBox)],
        size: (u32, u32),
        variant: Variant,
        timestamps: Option<(&wgpu::QuerySet, u32)>,
    ) -> Subjects {
        let targets = self.subject_targets(size, instances.len().max(1) as u32);
        encoder.clear_buffer(&targets.stats, 0, None);
        let mut outside = 0;
        for (layer, &(pose, camera, within)) in instances.iter().enumerate() {
            let mut frame = frame_uniform(Some(pose), &camera, variant);
            frame.bounds = within.to_array();
            outside += size.0 as usize * size.1 as usize - within.pixels();
            self.queue.write_buffer(
                &targets.layers[layer].uniform,
                0,
                bytemuck::bytes_of(&frame),
            );
            self.rebin.record(
                encoder,
                &targets,
                layer,
                &pose.bind_group,
                self.stage,
                within,
                timestamps.filter(|_| layer == 0),
                true,
            );
        }
        Subjects { targets, outside }
    }

    /// Copies the pixel-class counters of a drawn frame into its staging buffer.
    pub(super) fn copy_stats(&self, encoder: &mut wgpu::CommandEncoder, subject: &Subjects) {
        let t = &subject.targets;
        encoder.copy_buffer_to_buffer(&t.stats, 0, &t.stats_readback, 0, 16);
    }

    /// The counters [`Gpu::copy_stats`] copied (after its submission).
    pub(super) fn read_stats(&self, subject: &Subjects) -> Result<FrameStats> {
        let counts = self.read_buffer(&subject.targets.stats_readback)?;
        let counts: &[u32] = bytemuck::cast_slice(&counts);
        Ok(FrameStats {
            inside: counts[0] as usize,
            clamped_above: counts[1] as usize,
            clamped_below: counts[2] as usize,
            missed: counts[3] as usize + subject.outside,
        })
    }

    /// Copies (layer 0 of) an RGBA32F texture of `size` into a new staging buffer, for
    /// one-off reads; frames read back through their targets' own.
    pub(super) fn copy_rgba(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        size: (u32, u32),
    ) -> Readback {
        let readback = Readback::new(&self.device, "readback", size);
        readback.copy(encoder, texture);
        readback
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
            let whole = PixelBox::whole(size.0, size.1);
            let subject =
                self.draw_subjects(&mut encoder, &[(pose, *camera, whole)], size, variant, None);
            let t = &subject.targets;
            t.readback.copy(&mut encoder, &t.texture);
            self.copy_stats(&mut encoder, &subject);
            self.queue.submit([encoder.finish()]);
            Ok((self.read_rgba(&t.readback)?, self.read_stats(&subject)?))
        })
    }
}
