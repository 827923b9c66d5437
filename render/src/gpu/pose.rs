//! Making a pose resident on the GPU: its flows as RG8 integer texture arrays (the 8-bit
//! log codes, decoded in the shader), the view and quad tables and the cylinder's column
//! index as storage buffers, and every view relit on the GPU into an RGBA8 texture array
//! (`shaders/relight.wgsl`), one dispatch pair per view: the weighted sum of its basis
//! images, then its encoding with the view's peak. Twin of
//! [`crate::resident::ResidentPose::relight_cpu`].

use std::sync::Arc;

use frf_core::volume::GroundGrid;
use glam::Quat;
use wgpu::util::DeviceExt;

use super::bind::{
    compute_pipeline, copy_to_buffer, storage, storage_texture, table_bytes, uniform,
};
use super::formats::PoseFormats;
use super::types::{GpuQuad, GpuQuadFrame, GpuRelightParams, GpuView};
use super::{Gpu, shaders};
use crate::error::Result;
use crate::geometry::PoseGeometry;
use crate::rectified::gpu_frame;
use crate::resident::{PoseSource, ResidentPose, decode_flow, srgb_lut};

/// Workgroup size of the relighting pass (`@workgroup_size(64)`).
const WORKGROUP: u32 = 64;

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
                storage_texture(6, wgpu::TextureFormat::Rgba8Uint),
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
                    pad: [0; 3],
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

    /// Relights every view into its layer of `prelit`; returns the views' scales.
    fn relight_views(&self, source: &PoseSource, prelit: &wgpu::Texture) -> Result<Vec<f32>> {
        let crop = source.geometry.crop;
        let texels = crop.texels();
        let tiles = source
            .basis
            .iter()
            .map(|b| b.tiles.len())
            .max()
            .unwrap_or(0);
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
            let layer = source.geometry.prelit_layers[i];
            if source.is_blank(i) || layer < 0 {
                // A view not read: it has no layer (it samples as transparent, as the
                // CPU's does), and its peak stays zero (scale 1).
                continue;
            }
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
                base_array_layer: layer as u32,
                array_layer_count: Some(1),
                ..Default::default()
            });
            let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("relight"),
                layout: &self.relight.layout,
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
            for pipeline in [&self.relight.relight, &self.relight.encode] {
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
