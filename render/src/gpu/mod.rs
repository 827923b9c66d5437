//! The wgpu renderer: the GPU twin of [`crate::resident::ResidentPose::relight_cpu`] and
//! [`crate::cpu::render_cpu`].
//!
//! - [`Gpu::new`] opens an adapter (on machines without a GPU, Mesa's lavapipe; the
//!   `WGPU_BACKEND` variable chooses a backend) and builds the pipelines of
//!   `shaders/relight.wgsl` and `shaders/rebin.wgsl`.
//! - [`Gpu::upload_pose`] makes a pose resident: flows as RG8 integer texture arrays (the
//!   8-bit log codes, decoded in the shader), the view and quad tables as storage buffers,
//!   and every view relit on the GPU into an RGBA8 texture array, one dispatch pair per
//!   view: the weighted sum of its basis images, then its encoding with the view's peak.
//! - [`Gpu::render`] draws a frame with a full-screen triangle into an RGBA32F target
//!   and reads it back, rows padded to `COPY_BYTES_PER_ROW_ALIGNMENT`.

pub mod scope;
pub mod types;

use std::sync::Arc;

use frf_core::camera::Camera;
use frf_core::image::{Image, Rgba};
use glam::Quat;
use wgpu::util::DeviceExt;

use crate::cpu::FrameStats;
use crate::error::{RenderError, Result};
use crate::geometry::PoseGeometry;
use crate::morph::Variant;
use crate::resident::{PoseSource, srgb_lut};
use types::{GpuFrame, GpuQuad, GpuRelightParams, GpuView};

/// The WGSL sources as compiled: each pass after the shared definitions.
pub mod shaders {
    /// `shaders/common.wgsl`.
    pub const COMMON: &str = include_str!("../../../shaders/common.wgsl");
    /// `shaders/relight.wgsl`, standalone.
    pub const RELIGHT: &str = include_str!("../../../shaders/relight.wgsl");
    /// `shaders/rebin.wgsl`, standalone.
    pub const REBIN: &str = include_str!("../../../shaders/rebin.wgsl");

    /// A pass's full source: the shared definitions, then the pass.
    pub fn composed(pass: &str) -> String {
        format!("{COMMON}\n{pass}")
    }
}

/// Workgroup size of the relighting pass (`@workgroup_size(64)`).
const WORKGROUP: u32 = 64;

fn gpu_err(e: impl std::fmt::Display) -> RenderError {
    RenderError::Gpu(e.to_string())
}

/// An open GPU with the renderer's pipelines.
pub struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    adapter: String,
    uncaptured: scope::Uncaptured,
    relight_layout: wgpu::BindGroupLayout,
    relight: wgpu::ComputePipeline,
    encode: wgpu::ComputePipeline,
    frame_layout: wgpu::BindGroupLayout,
    pose_layout: wgpu::BindGroupLayout,
    rebin: wgpu::RenderPipeline,
}

/// A pose resident on the GPU.
pub struct GpuPose {
    bind_group: wgpu::BindGroup,
    prelit: wgpu::Texture,
    /// Per view: the pre-lit colour scale found by the relighting pass.
    pub scales: Vec<f32>,
    /// Grid, crop, cameras, cylinder; [`PoseGeometry::resident_bytes`] is what the pose
    /// holds on the GPU.
    pub geometry: Arc<PoseGeometry>,
    quad_count: u32,
}

fn storage(
    binding: u32,
    read_only: bool,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn uniform(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn texture_array(binding: u32, sample_type: wgpu::TextureSampleType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        },
        count: None,
    }
}

/// Copies `size = (width, height, layers)` of `texture` into `buffer`, rows `row` bytes
/// apart.
fn copy_to_buffer(
    encoder: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
    buffer: &wgpu::Buffer,
    row: u32,
    size: (u32, u32, u32),
) {
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(size.1),
            },
        },
        wgpu::Extent3d {
            width: size.0,
            height: size.1,
            depth_or_array_layers: size.2,
        },
    );
}

/// Pads `[f32; 256]` as `array<vec4<f32>, 64>`.
fn table_bytes(tables: &[[f32; 256]]) -> Vec<u8> {
    tables
        .iter()
        .flat_map(|t| bytemuck::cast_slice::<f32, u8>(t).to_vec())
        .collect()
}

impl Gpu {
    /// Opens the default adapter and builds the pipelines.
    pub fn new() -> Result<Self> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
            .map_err(|e| {
                RenderError::Gpu(format!(
                    "no GPU adapter ({e}); on Debian `apt-get install mesa-vulkan-drivers libvulkan1` provides a software one (lavapipe), or render with --cpu"
                ))
            })?;
        let info = adapter.get_info();
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("frf"),
            required_features: wgpu::Features::empty(),
            required_limits: limits,
            ..Default::default()
        }))
        .map_err(gpu_err)?;
        let uncaptured = scope::Uncaptured::default();
        uncaptured.install(&device);
        let adapter = format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type);
        scope::scoped(&device, &uncaptured, "building the pipelines", || {
            Ok(Self::build(
                device.clone(),
                queue,
                adapter,
                uncaptured.clone(),
            ))
        })
    }

    /// The pipelines and layouts of the renderer on `device`.
    fn build(
        device: wgpu::Device,
        queue: wgpu::Queue,
        adapter: String,
        uncaptured: scope::Uncaptured,
    ) -> Self {
        let relight_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("relight"),
            source: wgpu::ShaderSource::Wgsl(shaders::composed(shaders::RELIGHT).into()),
        });
        let rebin_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("rebin"),
            source: wgpu::ShaderSource::Wgsl(shaders::composed(shaders::REBIN).into()),
        });
        let c = wgpu::ShaderStages::COMPUTE;
        let relight_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("relight"),
            entries: &[
                uniform(0, c),
                storage(1, true, c),
                storage(2, true, c),
                storage(3, true, c),
                storage(4, false, c),
                storage(5, false, c),
                wgpu::BindGroupLayoutEntry {
                    binding: 6,
                    visibility: c,
                    ty: wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: wgpu::TextureFormat::Rgba8Uint,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                    count: None,
                },
            ],
        });
        let relight_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("relight"),
                bind_group_layouts: &[Some(&relight_layout)],
                immediate_size: 0,
            });
        let compute = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&relight_pipeline_layout),
                module: &relight_module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let (relight, encode) = (compute("relight"), compute("encode"));

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
            ],
        });
        let rebin_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("rebin"),
            bind_group_layouts: &[Some(&frame_layout), Some(&pose_layout)],
            immediate_size: 0,
        });
        let rebin = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("rebin"),
            layout: Some(&rebin_layout),
            vertex: wgpu::VertexState {
                module: &rebin_module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &rebin_module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: wgpu::TextureFormat::Rgba32Float,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        Self {
            device,
            queue,
            adapter,
            uncaptured,
            relight_layout,
            relight,
            encode,
            frame_layout,
            pose_layout,
            rebin,
        }
    }

    /// Runs `f` inside error scopes ([`scope::scoped`]).
    fn scoped<T>(&self, operation: &'static str, f: impl FnOnce() -> Result<T>) -> Result<T> {
        scope::scoped(&self.device, &self.uncaptured, operation, f)
    }

    /// The largest texture side the device takes, pixels.
    pub fn max_texture_side(&self) -> u32 {
        self.device.limits().max_texture_dimension_2d
    }

    /// The adapter, in words.
    pub fn adapter(&self) -> &str {
        &self.adapter
    }

    fn wait(&self) -> Result<()> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(gpu_err)?;
        Ok(())
    }

    fn read_buffer(&self, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
        let slice = buffer.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.wait()?;
        rx.recv().map_err(gpu_err)?.map_err(gpu_err)?;
        let bytes = slice.get_mapped_range().map_err(gpu_err)?.to_vec();
        buffer.unmap();
        Ok(bytes)
    }

    /// Makes pose `source` resident: uploads its flows and tables and relights every view
    /// on the GPU.
    pub fn upload_pose(&self, source: &PoseSource) -> Result<GpuPose> {
        self.scoped("making a pose resident", || {
            self.upload_pose_unscoped(source)
        })
    }

    fn upload_pose_unscoped(&self, source: &PoseSource) -> Result<GpuPose> {
        let geometry = &source.geometry;
        let crop = geometry.crop;
        let views = geometry.views();
        let texels = crop.texels();
        let extent = |layers: u32| wgpu::Extent3d {
            width: crop.width,
            height: crop.height,
            depth_or_array_layers: layers.max(1),
        };
        // Flows: one layer per stored flow, in the order of the geometry's flow layers.
        let mut flow_data: Vec<u8> = Vec::with_capacity(geometry.flow_layer_count * texels * 2);
        for f in &source.flows.codes {
            for codes in f.iter().flatten() {
                flow_data.extend(codes.iter().flat_map(|c| [c[0] as u8, c[1] as u8]));
            }
        }
        if flow_data.is_empty() {
            flow_data = vec![128u8; texels * 2];
        }
        let flows = self.device.create_texture_with_data(
            &self.queue,
            &wgpu::TextureDescriptor {
                label: Some("flows"),
                size: extent(geometry.flow_layer_count as u32),
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rg8Sint,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            &flow_data,
        );
        let prelit = self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("prelit"),
            size: extent(views as u32),
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Uint,
            usage: wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let scales = self.relight_views(source, &prelit)?;

        let gpu_views: Vec<GpuView> = geometry
            .cameras
            .iter()
            .zip(&scales)
            .zip(&geometry.flow_layers)
            .map(|((cam, &scale), l)| {
                let q = Quat::from_mat3(&cam.world_from_camera.rotation);
                let k = &cam.intrinsics;
                GpuView {
                    rotation: q.to_array(),
                    centre: cam.centre().to_array(),
                    scale,
                    intrinsics: [k.fx, k.fy, k.cx, k.cy],
                    flow_layers: *l,
                }
            })
            .collect();
        let quads: Vec<GpuQuad> = geometry
            .cylinder
            .quads()
            .iter()
            .map(|q| GpuQuad {
                p00: q.p00.to_array(),
                u: q.u,
                e1: q.e1.to_array(),
                v: q.v,
                e2: q.e2.to_array(),
                wall: q.wall,
                e3: q.e3.to_array(),
                wall_gamma: q.wall_gamma,
                normal: q.normal.to_array(),
                pad: 0.0,
            })
            .collect();
        let buffer = |label: &str, contents: &[u8]| {
            self.device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: wgpu::BufferUsages::STORAGE,
                })
        };
        let view_buffer = buffer("views", bytemuck::cast_slice(&gpu_views));
        let quad_buffer = buffer("quads", bytemuck::cast_slice(&quads));
        let tables = buffer("tables", &table_bytes(&[srgb_lut(), source.flows.table]));
        let view_of = |t: &wgpu::Texture| {
            t.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        let bind_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pose"),
            layout: &self.pose_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view_of(&prelit)),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&view_of(&flows)),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: view_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: quad_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: tables.as_entire_binding(),
                },
            ],
        });
        Ok(GpuPose {
            bind_group,
            prelit,
            scales,
            geometry: geometry.clone(),
            quad_count: quads.len() as u32,
        })
    }

    /// Relights every view into its layer of `prelit`; returns the views' scales.
    fn relight_views(&self, source: &PoseSource, prelit: &wgpu::Texture) -> Result<Vec<f32>> {
        let crop = source.geometry.crop;
        let texels = crop.texels();
        let tiles = source.basis.first().map_or(0, |b| b.tiles.len());
        let views = source.basis.len();
        let basis_buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("basis"),
            size: (tiles.max(1) * texels * 4) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let coefficient_buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("coefficients"),
            size: (tiles.max(1) * 16) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let params = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("relight params"),
            size: std::mem::size_of::<GpuRelightParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let gamma = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("gamma"),
                contents: &table_bytes(&[frf_reflectance::imagecodec::gamma_lut()]),
                usage: wgpu::BufferUsages::STORAGE,
            });
        let relit = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("relit"),
            size: (texels * 16) as u64,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let peaks = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("peaks"),
                contents: &vec![0u8; views.max(1) * 4],
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            });
        let readback = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("peaks readback"),
            size: (views.max(1) * 4) as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let groups = (texels as u32).div_ceil(WORKGROUP);
        for (i, basis) in source.basis.iter().enumerate() {
            let mut packed = Vec::with_capacity(tiles * texels);
            for (k, tile) in basis.tiles.iter().enumerate() {
                packed.extend(tile.iter().zip(&source.alpha[i]).map(|(p, &a)| {
                    let alpha = if k == 0 { a as u32 } else { 0 };
                    p[0] as u32 | (p[1] as u32) << 8 | (p[2] as u32) << 16 | alpha << 24
                }));
            }
            let coefficients: Vec<[f32; 4]> = source.coefficients[i]
                .iter()
                .zip(&basis.scales)
                .map(|(c, &s)| {
                    let used = if c.iter().all(|&x| x == 0.0) {
                        0.0
                    } else {
                        1.0
                    };
                    [c[0] * s, c[1] * s, c[2] * s, used]
                })
                .collect();
            self.queue
                .write_buffer(&basis_buffer, 0, bytemuck::cast_slice(&packed));
            self.queue
                .write_buffer(&coefficient_buffer, 0, bytemuck::cast_slice(&coefficients));
            self.queue.write_buffer(
                &params,
                0,
                bytemuck::bytes_of(&GpuRelightParams {
                    texels: texels as u32,
                    tiles: tiles as u32,
                    width: crop.width,
                    view: i as u32,
                }),
            );
            let layer = prelit.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: i as u32,
                array_layer_count: Some(1),
                ..Default::default()
            });
            let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("relight"),
                layout: &self.relight_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: params.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: basis_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: coefficient_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: gamma.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: relit.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: peaks.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 6,
                        resource: wgpu::BindingResource::TextureView(&layer),
                    },
                ],
            });
            let mut encoder = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("relight"),
                });
            for pipeline in [&self.relight, &self.encode] {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("relight"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &bind, &[]);
                pass.dispatch_workgroups(groups, 1, 1);
            }
            // Each view's uploads must land before its dispatches and after the last ones.
            self.queue.submit([encoder.finish()]);
        }
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("peaks"),
            });
        encoder.copy_buffer_to_buffer(&peaks, 0, &readback, 0, (views.max(1) * 4) as u64);
        self.queue.submit([encoder.finish()]);
        let bytes = self.read_buffer(&readback)?;
        Ok(bytemuck::cast_slice::<u8, u32>(&bytes)[..views]
            .iter()
            .map(|&b| {
                let p = f32::from_bits(b);
                if p > 0.0 { p } else { 1.0 }
            })
            .collect())
    }

    /// Reads back the pre-lit texels of every view (for tests and inspection).
    pub fn read_prelit(&self, pose: &GpuPose) -> Result<Vec<Vec<[u8; 4]>>> {
        self.scoped("reading pre-lit views back", || {
            self.read_prelit_unscoped(pose)
        })
    }

    fn read_prelit_unscoped(&self, pose: &GpuPose) -> Result<Vec<Vec<[u8; 4]>>> {
        let (w, h) = (pose.geometry.crop.width, pose.geometry.crop.height);
        let layers = pose.scales.len() as u32;
        let row = (w * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("prelit readback"),
            size: (row * h * layers) as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("prelit readback"),
            });
        copy_to_buffer(&mut encoder, &pose.prelit, &buffer, row, (w, h, layers));
        self.queue.submit([encoder.finish()]);
        let bytes = self.read_buffer(&buffer)?;
        Ok((0..layers as usize)
            .map(|l| {
                (0..h as usize)
                    .flat_map(|y| {
                        let start = (l * h as usize + y) * row as usize;
                        bytes[start..start + w as usize * 4]
                            .chunks_exact(4)
                            .map(|c| [c[0], c[1], c[2], c[3]])
                            .collect::<Vec<_>>()
                    })
                    .collect()
            })
            .collect())
    }

    /// Renders a frame of `camera` (subject frame) with `variant`.
    pub fn render(
        &self,
        pose: &GpuPose,
        camera: &Camera,
        variant: Variant,
    ) -> Result<(Image<Rgba>, FrameStats)> {
        self.scoped("rendering a frame", || {
            self.render_unscoped(pose, camera, variant)
        })
    }

    fn render_unscoped(
        &self,
        pose: &GpuPose,
        camera: &Camera,
        variant: Variant,
    ) -> Result<(Image<Rgba>, FrameStats)> {
        let (w, h) = (camera.width, camera.height);
        let r = camera.world_from_camera.rotation;
        let k = &camera.intrinsics;
        let frame = GpuFrame {
            axis_x: r.x_axis.extend(0.0).to_array(),
            axis_y: r.y_axis.extend(0.0).to_array(),
            axis_z: r.z_axis.extend(0.0).to_array(),
            centre: camera.centre().extend(1.0).to_array(),
            intrinsics: [k.fx, k.fy, k.cx, k.cy],
            size: [w, h],
            variant: variant.index(),
            quad_count: pose.quad_count,
            columns: pose.geometry.columns as u32,
            rows: pose.geometry.rows as u32,
            crop_origin: [pose.geometry.crop.x0, pose.geometry.crop.y0],
            crop_size: [pose.geometry.crop.width, pose.geometry.crop.height],
            pad: [0; 2],
        };
        let frame_buffer = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("frame"),
                contents: bytemuck::bytes_of(&frame),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let stats = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("stats"),
                contents: &[0u8; 16],
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            });
        let frame_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("frame"),
            layout: &self.frame_layout,
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
        let target = self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("frame"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let row = (w * 16).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let readback = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame readback"),
            size: (row * h) as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let stats_readback = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("stats readback"),
            size: 16,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let view = target.create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("frame"),
            });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("rebin"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.rebin);
            pass.set_bind_group(0, &frame_group, &[]);
            pass.set_bind_group(1, &pose.bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        copy_to_buffer(&mut encoder, &target, &readback, row, (w, h, 1));
        encoder.copy_buffer_to_buffer(&stats, 0, &stats_readback, 0, 16);
        self.queue.submit([encoder.finish()]);
        let bytes = self.read_buffer(&readback)?;
        let counts = self.read_buffer(&stats_readback)?;
        let counts: &[u32] = bytemuck::cast_slice(&counts);
        let mut pixels = Vec::with_capacity((w * h) as usize);
        for y in 0..h as usize {
            let start = y * row as usize;
            let floats: &[f32] = bytemuck::cast_slice(&bytes[start..start + w as usize * 16]);
            pixels.extend(floats.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]));
        }
        let stats = FrameStats {
            inside: counts[0] as usize,
            clamped_above: counts[1] as usize,
            clamped_below: counts[2] as usize,
            missed: counts[3] as usize,
        };
        Ok((Image::from_vec(w as usize, h as usize, pixels)?, stats))
    }
}
