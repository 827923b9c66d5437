//! Making a pose resident on the GPU: its flows as RG8 integer texture arrays (the 8-bit
//! log codes, decoded in the shader), the view and quad tables and the cylinder's column
//! index as storage buffers, and every view relit on the GPU into an RGBA8 texture array
//! ([`super::relight`], from basis codes kept resident and shared between the pose's
//! relit copies).

use std::sync::Arc;

use frf_core::volume::GroundGrid;
use frf_reflectance::sun_light::{MAX_SUNS, SunLight};
use glam::Quat;
use wgpu::util::DeviceExt;

use super::Gpu;
use super::bind::{buffer_with, copy_to_buffer, table_bytes};
use super::formats::PoseFormats;
use super::relight::{GpuBasis, PoseRelight};
use crate::error::Result;
use crate::geometry::PoseGeometry;
use crate::rectified::gpu_frame;
use crate::resident::{PoseSource, ResidentPose, decode_flow, srgb_lut};
use crate::shadow::ShadowMaps;
use frf_shaders::types::{GpuQuad, GpuQuadFrame, GpuView};

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
    /// The view table (whose scales the relighting pass sets).
    pub(super) views: wgpu::Buffer,
    /// Its basis codes and relighting buffers; `None` for a pose uploaded already lit.
    pub(super) relight: Option<PoseRelight>,
    /// Grid, crop, cameras, cylinder; [`PoseGeometry::resident_bytes`] is what the pose
    /// holds on the GPU.
    pub geometry: Arc<PoseGeometry>,
    pub(super) quad_count: u32,
    /// The shadow it casts on the ground, when it has shadow maps and a lighting.
    pub(super) shadow: Option<PoseShadow>,
}

/// The shadow a resident pose casts ([`super::shadow`]).
pub enum PoseShadow {
    /// Its shadow maps (shared by the poses made from the same ones) and the weight of
    /// each under its light: relit by the frame that draws it.
    Maps {
        /// The maps, one per condition of their spec.
        maps: Arc<ShadowMaps>,
        /// Per map, the light its condition brings to the ground (rgb).
        weights: Vec<[f32; 4]>,
        /// Their size and patch of ground.
        info: RelitShadowInfo,
    },
    /// Relit on the host (traced).
    Relit {
        /// The relit shadow (rgb, alpha 1).
        texture: wgpu::Texture,
        /// Its size and patch of ground.
        info: RelitShadowInfo,
    },
}

impl PoseShadow {
    /// Its size and patch of ground.
    pub fn info(&self) -> RelitShadowInfo {
        match self {
            PoseShadow::Maps { info, .. } | PoseShadow::Relit { info, .. } => *info,
        }
    }
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

    /// The basis codes it is relit from, shared with the other poses relit from them;
    /// `None` for a pose uploaded already lit.
    pub fn basis(&self) -> Option<&Arc<GpuBasis>> {
        self.relight.as_ref().map(PoseRelight::basis)
    }

    /// Whether a relit shadow is resident.
    pub fn has_shadow(&self) -> bool {
        self.shadow.is_some()
    }

    /// The ground patch of the resident relit shadow.
    pub fn shadow_ground(&self) -> Option<GroundGrid> {
        self.shadow.as_ref().map(|s| s.info()).map(|i| GroundGrid {
            extent_m: i.extent_m,
            texels: i.texels,
        })
    }

    /// Drops the relit shadow.
    pub fn clear_shadow(&mut self) {
        self.shadow = None;
    }
}

impl GpuPose {
    /// Lets go of its basis codes and relighting buffers (its pre-lit views stay, as
    /// lit): for a pose whose light will not change, which then holds what a pre-lit pose
    /// holds. [`Gpu::relight_pose`] uploads them again if it is relit after all. Codes
    /// other poses share stay with them.
    pub fn release_basis(&mut self) {
        self.relight = None;
    }
}

impl Gpu {
    /// Makes pose `source` resident: uploads its basis codes, flows and tables and
    /// relights every view on the GPU.
    pub fn upload_pose(&self, source: &PoseSource) -> Result<GpuPose> {
        self.upload_pose_sharing(source, None)
    }

    /// [`Gpu::upload_pose`], relit from `basis` when it holds `source`'s codes (another
    /// copy of the same views: a walker of another heading) instead of uploading them.
    pub fn upload_pose_sharing(
        &self,
        source: &PoseSource,
        basis: Option<&Arc<GpuBasis>>,
    ) -> Result<GpuPose> {
        let basis = match basis {
            Some(b) if b.holds(&source.basis) => b.clone(),
            _ => self.upload_basis(source)?,
        };
        self.scoped("making a pose resident", || {
            self.upload_pose_unscoped(source, basis)
        })
    }

    fn upload_pose_unscoped(&self, source: &PoseSource, basis: Arc<GpuBasis>) -> Result<GpuPose> {
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
        // Scales are set by the relighting pass; a view not relit keeps 1.
        let mut pose = self.bind_pose(
            &self.rebin.pose,
            &source.geometry,
            vec![1.0; geometry.views()],
            prelit,
            &flows,
            source.flows.table,
        );
        let hull = pose.geometry.proxy.hull_shared().cloned();
        let mut relight = self.pose_relight(basis, geometry.views(), hull);
        self.record_relight(
            &mut relight,
            source,
            (&pose.prelit_codes_view(), &pose.views),
        );
        pose.relight = Some(relight);
        Ok(pose)
    }

    /// Relights `pose` with `source`'s coefficients (the views and geometry it was made
    /// from): new coefficients and one dispatch pair per batch of views
    /// ([`super::relight`]), recorded with the pending work, not submitted.
    pub fn relight_pose(&self, pose: &mut GpuPose, source: &PoseSource) -> Result<()> {
        if pose.relight.is_none() {
            // Let go of ([`GpuPose::release_basis`]): uploaded again.
            let basis = self.upload_basis(source)?;
            let hull = pose.geometry.proxy.hull_shared().cloned();
            let relight = self.pose_relight(basis, source.geometry.views(), hull);
            pose.relight = Some(relight);
        }
        self.scoped("relighting a resident pose", || {
            let target = pose.prelit_codes_view();
            let relight = pose.relight.as_mut().ok_or_else(|| {
                crate::RenderError::Misuse("relighting a pose of no basis".into())
            })?;
            if !relight.basis().holds(&source.basis) {
                return Err(crate::RenderError::Misuse(
                    "relighting a pose with another pose's views".into(),
                ));
            }
            self.record_relight(relight, source, (&target, &pose.views));
            Ok(())
        })
    }

    /// The views' pre-lit colour scales as the GPU holds them (for tests and inspection).
    pub fn read_scales(&self, pose: &GpuPose) -> Result<Vec<f32>> {
        self.scoped("reading a pose's scales back", || {
            let bytes = self.read_back(&pose.views, "views readback")?;
            let views: &[GpuView] = bytemuck::cast_slice(&bytes);
            Ok(views[..pose.geometry.views()]
                .iter()
                .map(|v| v.scale)
                .collect())
        })
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
            buffer_with(&self.device, label, contents, wgpu::BufferUsages::STORAGE)
        };
        let view_buffer = buffer_with(
            &self.device,
            "views",
            bytemuck::cast_slice(&gpu_views),
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        );
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
            views: view_buffer,
            relight: None,
            geometry: geometry.clone(),
            quad_count: quads.len() as u32,
            shadow: None,
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
        self.submit([encoder.finish()]);
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

impl Gpu {
    /// The suns' maps of `pose` as the GPU made them at its last relight (per sun of
    /// `suns`, its map's values; for tests and inspection, before other poses are
    /// relit): none without a hull.
    pub fn read_sun_maps(&self, pose: &GpuPose, suns: &[SunLight]) -> Result<Vec<Vec<f32>>> {
        let Some(maps) = pose.relight.as_ref().and_then(|r| r.sun_maps()) else {
            return Ok(Vec::new());
        };
        self.scoped("reading the suns' maps back", || {
            let bytes = self.read_back(&maps.reach, "sun depths readback")?;
            let all: &[f32] = bytemuck::cast_slice(&bytes);
            Ok(suns
                .iter()
                .take(MAX_SUNS)
                .enumerate()
                .filter_map(|(s, sun)| {
                    let n = sun.depth.as_ref()?.texels();
                    let start = maps.starts.get(s).copied().flatten()?;
                    Some(all[start..start + n].to_vec())
                })
                .collect())
        })
    }
}
