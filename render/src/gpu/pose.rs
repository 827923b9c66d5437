//! Making a pose resident on the GPU: its flows as RG8 integer texture arrays (the 8-bit
//! log codes, decoded in the shader), the view and quad tables and the cylinder's column
//! index as storage buffers, and every view relit on the GPU into an RGBA8 texture array
//! (`shaders/relight.wgsl`), one dispatch pair per batch of views: the weighted sum of
//! each view's basis images, then its encoding with the view's peak. Twin of
//! [`crate::resident::ResidentPose::relight_cpu`].

use std::sync::Arc;

use frf_core::volume::GroundGrid;
use glam::Quat;
use wgpu::util::DeviceExt;

use super::bind::{
    bind_group, compute_pipeline, copy_to_buffer, storage, storage_texture_array, table_bytes,
    uniform,
};
use super::formats::PoseFormats;
use super::{Gpu, shaders};
use crate::error::Result;
use crate::geometry::PoseGeometry;
use crate::rectified::gpu_frame;
use crate::resident::{PoseSource, ResidentPose, decode_flow, srgb_lut};
use frf_shaders::types::{GpuQuad, GpuQuadFrame, GpuRelightJob, GpuRelightParams, GpuView};

/// Workgroup size of the relighting pass (`@workgroup_size(64)`).
const WORKGROUP: u32 = 64;

/// Most bytes of basis codes the relighting records into one batch.
const RELIGHT_BATCH_BYTES: usize = 64 << 20;

/// The relighting pipelines.
pub struct RelightPass {
    layout: wgpu::BindGroupLayout,
    relight: wgpu::ComputePipeline,
    encode: wgpu::ComputePipeline,
}

impl RelightPass {
    /// Builds the pass on `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        let relight_module = shaders::module(device, "relight", shaders::RELIGHT);
        let c = wgpu::ShaderStages::COMPUTE;
        let relight_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("relight"),
            entries: &[
                uniform::<GpuRelightParams>(0, c),
                storage::<u32>(1, true, c),
                storage::<[f32; 4]>(2, true, c),
                storage::<[[f32; 4]; 64]>(3, true, c),
                storage::<[f32; 4]>(4, false, c),
                storage::<u32>(5, false, c),
                storage_texture_array(6, wgpu::TextureFormat::Rgba8Uint),
                storage::<GpuRelightJob>(7, true, c),
            ],
        });
        let compute = |entry: &str| {
            compute_pipeline(device, entry, &[&relight_layout], &relight_module, entry)
        };
        let (relight, encode) = (compute("relight"), compute("encode"));

        Self {
            layout: relight_layout,
            relight,
            encode,
        }
    }
}

/// How the frame pass binds a resident pose (made by [`super::rebin::RebinPass`]): the
/// storage it reads ([`super::formats`]), the layout of bind group 1 and the sampler in it.
pub struct PoseBinding {
    /// The storage of the pre-lit views and flows.
    pub formats: PoseFormats,
    pub(super) layout: wgpu::BindGroupLayout,
    pub(super) sampler: wgpu::Sampler,
}

/// A pose resident on the GPU.
pub struct GpuPose {
    pub(super) bind_group: wgpu::BindGroup,
    prelit: wgpu::Texture,
    /// Per view: the pre-lit colour scale found by the relighting pass.
    pub scales: Vec<f32>,
    /// Grid, crop, cameras, cylinder; [`PoseGeometry::resident_bytes`] is what the pose
    /// holds on the GPU.
    pub geometry: Arc<PoseGeometry>,
    pub(super) quad_count: u32,
    /// The relit shadow of the ground, when the pose has shadow maps and a lighting.
    pub(super) shadow: Option<(wgpu::Texture, RelitShadowInfo)>,
}

/// What the composite pass needs to know of a relit shadow texture.
#[derive(Debug, Clone, Copy)]
pub struct RelitShadowInfo {
    /// Texels per side.
    pub texels: u32,
    /// Side of the ground patch, metres.
    pub extent_m: f32,
}

impl GpuPose {
    /// A view of the pre-lit texture array.
    pub(super) fn prelit_codes_view(&self) -> wgpu::TextureView {
        self.prelit.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        })
    }

    /// Whether a relit shadow is resident.
    pub fn has_shadow(&self) -> bool {
        self.shadow.is_some()
    }

    /// The ground patch of the resident relit shadow.
    pub fn shadow_ground(&self) -> Option<GroundGrid> {
        self.shadow.as_ref().map(|(_, i)| GroundGrid {
            extent_m: i.extent_m,
            texels: i.texels,
        })
    }

    /// Drops the relit shadow.
    pub fn clear_shadow(&mut self) {
        self.shadow = None;
    }
}

impl Gpu {
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
            size: extent(geometry.prelit_layer_count as u32),
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
        Ok(self.bind_pose(
            &self.rebin.pose,
            &source.geometry,
            scales,
            prelit,
            &flows,
            source.flows.table,
        ))
    }

    /// Makes a pose relit on the CPU resident with the storage `pass` reads
    /// ([`super::formats`]): its pre-lit codes and flows uploaded in those formats (the
    /// benchmark's way to compare them; the renderer relights on the GPU).
    pub fn upload_resident(&self, resident: &ResidentPose, pass: &PoseBinding) -> Result<GpuPose> {
        self.scoped("making a CPU-relit pose resident", || {
            let geometry = &resident.geometry;
            let crop = geometry.crop;
            let texels = crop.texels();
            let texture = |label, format, layers: usize, bytes: &[u8]| {
                self.device.create_texture_with_data(
                    &self.queue,
                    &wgpu::TextureDescriptor {
                        label: Some(label),
                        size: wgpu::Extent3d {
                            width: crop.width,
                            height: crop.height,
                            depth_or_array_layers: layers.max(1) as u32,
                        },
                        mip_level_count: 1,
                        sample_count: 1,
                        dimension: wgpu::TextureDimension::D2,
                        format,
                        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                        view_formats: &[],
                    },
                    wgpu::util::TextureDataOrder::LayerMajor,
                    bytes,
                )
            };
            // The held views' texels, layer by layer (a held view without texels: zero).
            let mut prelit_bytes: Vec<u8> =
                Vec::with_capacity(geometry.prelit_layer_count.max(1) * texels * 4);
            for (i, view) in resident.prelit.iter().enumerate() {
                if !geometry.holds(i) {
                    continue;
                }
                if view.is_empty() {
                    prelit_bytes.resize(prelit_bytes.len() + texels * 4, 0);
                } else {
                    prelit_bytes.extend(view.iter().flatten());
                }
            }
            if prelit_bytes.is_empty() {
                prelit_bytes = vec![0; texels * 4];
            }
            let prelit = texture(
                "prelit",
                pass.formats.image.texture(),
                geometry.prelit_layer_count,
                &prelit_bytes,
            );
            let stored = resident.flows.codes.iter().flat_map(|f| f.iter().flatten());
            let q = &resident.flows.quantizer;
            let decoded: Vec<[f32; 2]> = stored
                .clone()
                .flat_map(|codes| codes.iter().map(|&c| decode_flow(c, q).to_array()))
                .collect();
            let mut bytes = match pass.formats.flow.encode(&decoded) {
                Some(b) => b,
                None => stored
                    .flat_map(|codes| codes.iter().flat_map(|c| [c[0] as u8, c[1] as u8]))
                    .collect(),
            };
            if bytes.is_empty() {
                bytes = match pass.formats.flow.encode(&vec![[0.0; 2]; texels]) {
                    Some(b) => b,
                    None => vec![128u8; texels * 2],
                };
            }
            let flows = texture(
                "flows",
                pass.formats.flow.texture(),
                geometry.flow_layer_count,
                &bytes,
            );
            Ok(self.bind_pose(
                pass,
                geometry,
                resident.scales.clone(),
                prelit,
                &flows,
                resident.flows.table,
            ))
        })
    }

    /// Makes a pose of motion views ([`crate::motion::pose_motion`]) resident as the
    /// renderer's frame pass reads poses.
    pub fn upload_motion(&self, motion: &ResidentPose) -> Result<GpuPose> {
        self.upload_resident(motion, &self.rebin.pose)
    }

    /// The pose's tables uploaded and bound with its textures for `pass`.
    fn bind_pose(
        &self,
        pass: &PoseBinding,
        geometry: &Arc<PoseGeometry>,
        scales: Vec<f32>,
        prelit: wgpu::Texture,
        flows: &wgpu::Texture,
        flow_table: [f32; 256],
    ) -> GpuPose {
        let gpu_views: Vec<GpuView> = geometry
            .cameras
            .iter()
            .zip(&scales)
            .zip(&geometry.flow_layers)
            .zip(&geometry.prelit_layers)
            .map(|(((cam, &scale), l), &prelit_layer)| {
                let q = Quat::from_mat3(&cam.world_from_camera.rotation);
                let k = &cam.intrinsics;
                GpuView {
                    rotation: q.to_array(),
                    centre: cam.centre().to_array(),
                    scale,
                    intrinsics: [k.fx, k.fy, k.cx, k.cy],
                    flow_layers: *l,
                    prelit_layer,
                    pad0: 0,
                    pad1: 0,
                    pad2: 0,
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
        let tables = buffer("tables", &table_bytes(&[srgb_lut(), flow_table]));
        let (index, ranges) = geometry.cylinder.column_index_gpu();
        let mut index_bytes = bytemuck::bytes_of(&index).to_vec();
        index_bytes.extend_from_slice(bytemuck::cast_slice(&ranges));
        let index_buffer = buffer("column index", &index_bytes);
        let (proxy, hull_words) = geometry.proxy.gpu();
        let proxy_buffer = buffer("proxy", bytemuck::bytes_of(&proxy));
        let hull_buffer = buffer("hull", bytemuck::cast_slice(&hull_words));
        let frames: Vec<GpuQuadFrame> = geometry
            .frames
            .iter()
            .map(|f| gpu_frame(f.as_ref()))
            .collect();
        let frame_buffer = buffer("quad frames", bytemuck::cast_slice(&frames));
        let view_of = |t: &wgpu::Texture| {
            t.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        let bind_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pose"),
            layout: &pass.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view_of(&prelit)),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&view_of(flows)),
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
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: proxy_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: hull_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: index_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 8,
                    resource: wgpu::BindingResource::Sampler(&pass.sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 9,
                    resource: frame_buffer.as_entire_binding(),
                },
            ],
        });
        GpuPose {
            bind_group,
            prelit,
            scales,
            geometry: geometry.clone(),
            quad_count: quads.len() as u32,
            shadow: None,
        }
    }

    /// Relights every view into its layer of `prelit`; returns the views' scales. Views
    /// are relit in batches (one dispatch pair each) of up to [`RELIGHT_BATCH_BYTES`] of
    /// basis codes.
    fn relight_views(&self, source: &PoseSource, prelit: &wgpu::Texture) -> Result<Vec<f32>> {
        let views = source.basis.len();
        let storage = wgpu::BufferUsages::STORAGE;
        let gamma = self.init_buffer(
            "gamma",
            &table_bytes(&[frf_reflectance::imagecodec::gamma_lut()]),
            storage,
        );
        let peaks = self.init_buffer(
            "peaks",
            &vec![0u8; views.max(1) * 4],
            storage | wgpu::BufferUsages::COPY_SRC,
        );
        let target = prelit.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("relight"),
            });
        // The views read (a view not read has no layer: it samples as transparent, as
        // the CPU's does, and its peak stays zero, scale 1), in batches.
        let texels = source.geometry.crop.texels();
        let read: Vec<usize> = (0..views)
            .filter(|&i| !source.is_blank(i) && source.geometry.prelit_layers[i] >= 0)
            .collect();
        let mut batch: Vec<usize> = Vec::new();
        let mut bytes = 0;
        for (k, &i) in read.iter().enumerate() {
            batch.push(i);
            bytes += source.basis[i].tiles.len() * texels * 4;
            if bytes >= RELIGHT_BATCH_BYTES || k + 1 == read.len() {
                self.record_relight(&mut encoder, source, &batch, [&gamma, &peaks], &target);
                batch.clear();
                bytes = 0;
            }
        }
        let readback = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("peaks readback"),
            size: (views.max(1) * 4) as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
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

    /// A buffer holding `contents`.
    fn init_buffer(&self, label: &str, contents: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
        self.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
    }

    /// Records the relighting of views `batch` of `source` into `encoder`: their codes,
    /// coefficients and jobs uploaded, then the two passes over every view at once,
    /// writing the views' peaks into `gamma_peaks[1]` and their texels into `target`.
    fn record_relight(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        source: &PoseSource,
        batch: &[usize],
        [gamma, peaks]: [&wgpu::Buffer; 2],
        target: &wgpu::TextureView,
    ) {
        let crop = source.geometry.crop;
        let texels = crop.texels();
        let mut codes: Vec<u32> = Vec::new();
        let mut coefficients: Vec<[f32; 4]> = Vec::new();
        let mut jobs = Vec::with_capacity(batch.len());
        for (j, &i) in batch.iter().enumerate() {
            let basis = &source.basis[i];
            jobs.push(GpuRelightJob {
                basis_offset: codes.len() as u32,
                coefficient_offset: coefficients.len() as u32,
                tiles: basis.tiles.len() as u32,
                view: i as u32,
                layer: source.geometry.prelit_layers[i] as u32,
                relit_offset: (j * texels) as u32,
                pad0: 0,
                pad1: 0,
            });
            for (k, tile) in basis.tiles.iter().enumerate() {
                codes.extend(tile.iter().zip(&source.alpha[i]).map(|(p, &a)| {
                    let alpha = if k == 0 { a as u32 } else { 0 };
                    p[0] as u32 | (p[1] as u32) << 8 | (p[2] as u32) << 16 | alpha << 24
                }));
            }
            coefficients.extend(
                source.coefficients[i]
                    .iter()
                    .zip(&basis.scales)
                    .map(|(c, &s)| {
                        let used = if c.iter().all(|&x| x == 0.0) {
                            0.0
                        } else {
                            1.0
                        };
                        [c[0] * s, c[1] * s, c[2] * s, used]
                    }),
            );
        }
        if codes.is_empty() {
            codes.push(0);
        }
        if coefficients.is_empty() {
            coefficients.push([0.0; 4]);
        }
        let params = GpuRelightParams {
            texels: texels as u32,
            width: crop.width,
            jobs: batch.len() as u32,
            pad: 0,
        };
        let storage = wgpu::BufferUsages::STORAGE;
        let relit = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("relit"),
            size: (texels * batch.len().max(1) * 16) as u64,
            usage: storage,
            mapped_at_creation: false,
        });
        let buffers = [
            self.init_buffer(
                "relight params",
                bytemuck::bytes_of(&params),
                wgpu::BufferUsages::UNIFORM,
            ),
            self.init_buffer("basis", bytemuck::cast_slice(&codes), storage),
            self.init_buffer("coefficients", bytemuck::cast_slice(&coefficients), storage),
            self.init_buffer("jobs", bytemuck::cast_slice(&jobs), storage),
        ];
        let bind = bind_group(
            &self.device,
            "relight",
            &self.relight.layout,
            vec![
                buffers[0].as_entire_binding(),
                buffers[1].as_entire_binding(),
                buffers[2].as_entire_binding(),
                gamma.as_entire_binding(),
                relit.as_entire_binding(),
                peaks.as_entire_binding(),
                wgpu::BindingResource::TextureView(target),
                buffers[3].as_entire_binding(),
            ],
        );
        let groups = (texels as u32).div_ceil(WORKGROUP);
        for pipeline in [&self.relight.relight, &self.relight.encode] {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("relight"),
                timestamp_writes: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(groups, batch.len() as u32, 1);
        }
    }

    /// Reads back the pre-lit texels of every view (for tests and inspection; a view not
    /// held reads as no texels).
    pub fn read_prelit(&self, pose: &GpuPose) -> Result<Vec<Vec<[u8; 4]>>> {
        self.scoped("reading pre-lit views back", || {
            self.read_prelit_unscoped(pose)
        })
    }

    fn read_prelit_unscoped(&self, pose: &GpuPose) -> Result<Vec<Vec<[u8; 4]>>> {
        let (w, h) = (pose.geometry.crop.width, pose.geometry.crop.height);
        let g = &pose.geometry;
        let layers = g.prelit_layer_count.max(1) as u32;
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
        Ok(g.prelit_layers
            .iter()
            .map(|&l| {
                if l < 0 {
                    return Vec::new();
                }
                let l = l as usize;
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
}
