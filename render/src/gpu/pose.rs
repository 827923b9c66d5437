//! Making a pose resident on the GPU: its flows as RG8 integer texture arrays (the 8-bit
//! log codes, decoded in the shader) and its tables, shared by every relit copy of its
//! views ([`super::pose_tables`]), and every view relit on the GPU into the pose's range
//! of the shared pages of pre-lit views ([`super::prelit`]; [`super::relight`], from
//! basis codes kept resident and shared between the pose's relit copies).

use std::sync::Arc;

use frf_core::volume::GroundGrid;
use frf_reflectance::sun_light::{MAX_SUNS, SunLight};
use wgpu::util::DeviceExt;

use super::Gpu;
use super::bind::copy_to_buffer;
use super::formats::PoseFormats;
use super::pose_tables::{Flows, PoseTables};
use super::prelit::PrelitRange;
use super::relight::{GpuBasis, PoseRelight};
use crate::error::Result;
use crate::geometry::PoseGeometry;
use crate::resident::{PoseSource, ResidentPose, decode_flow};
use crate::shadow::ShadowMaps;

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
    /// What names its bind group: renders of poses of one key are drawn in one dispatch.
    pub(super) group_key: (u64, usize, usize),
    /// Its views' heads and pre-lit codes, a range of the shared pages
    /// ([`super::prelit`]).
    pub(super) prelit: PrelitRange,
    /// Its pre-lit texels when a texture holds them (the benchmark's sRGB8 storage,
    /// [`super::formats`]); `None`: they are in `prelit`.
    texels: Option<wgpu::Texture>,
    /// Its flows: a range of the shared pages, or (decoded, the benchmark's) a texture.
    flows: Flows,
    /// Its cameras and geometry, shared with the other copies of the pose
    /// ([`super::pose_tables`]).
    pub(super) tables: Arc<PoseTables>,
    /// Its basis codes and relighting buffers; `None` for a pose uploaded already lit.
    pub(super) relight: Option<PoseRelight>,
    /// Grid, crop, cameras, cylinder; [`PoseGeometry::resident_bytes`] is what the pose
    /// holds on the GPU.
    pub geometry: Arc<PoseGeometry>,
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
    /// Its pre-lit views' range of the shared pages, where the relighting pass writes
    /// them (none where a texture holds its texels).
    pub(super) fn prelit_range(&self) -> Option<&PrelitRange> {
        self.texels.is_none().then_some(&self.prelit)
    }

    /// Where its heads, pre-lit codes and flows lie in the shared pages (`prelit` of the
    /// frame pass's record).
    pub(super) fn prelit_words(&self) -> [u32; 4] {
        let [heads, codes] = self.prelit.words();
        let flows = match &self.flows {
            Flows::Shared(r) => r.word(),
            Flows::Texture(_) => 0,
        };
        [heads, codes, flows, 0]
    }

    /// Whether the frame pass draws its renders and `other`'s in one dispatch: relit
    /// copies of one pose's views (its tables shared) whose pre-lit views lie in one page.
    pub fn draws_with(&self, other: &GpuPose) -> bool {
        self.group_key == other.group_key
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
        let pass = &self.rebin.pose;
        let tables = self.pose_tables(true, geometry, &source.flows);
        // Scales are set by the relighting pass; a view not relit keeps 1.
        let range = self.take_prelit(geometry);
        let flows = Flows::Shared(self.flow_range(geometry, &source.flows));
        let mut pose = self.resident_pose(pass, tables, (range, flows, None), geometry);
        let hull = pose.geometry.proxy.hull_shared().cloned();
        let mut relight = self.pose_relight(basis, hull);
        self.record_relight(&mut relight, source, &pose.prelit);
        pose.relight = Some(relight);
        Ok(pose)
    }

    /// A pose of `geometry` drawn from `tables`, its `prelit` range, its `flows` and its
    /// pre-lit `texels` where a texture holds them, by `pass`.
    fn resident_pose(
        &self,
        pass: &PoseBinding,
        tables: Arc<PoseTables>,
        (prelit, flows, texels): (PrelitRange, Flows, Option<wgpu::Texture>),
        geometry: &Arc<PoseGeometry>,
    ) -> GpuPose {
        let (bind_group, group_key) = self.pose_group(
            (&pass.layout, &pass.sampler),
            &tables,
            (&prelit, &flows, texels.as_ref()),
        );
        GpuPose {
            bind_group,
            group_key,
            prelit,
            texels,
            flows,
            tables,
            relight: None,
            geometry: geometry.clone(),
            shadow: None,
        }
    }

    /// A texture array of `geometry`'s crop, a layer a stored flow (one at least), of
    /// `format`, holding `bytes` (zero flow where there are none).
    fn flows_texture(
        &self,
        geometry: &PoseGeometry,
        format: wgpu::TextureFormat,
        bytes: Vec<u8>,
    ) -> wgpu::Texture {
        self.crop_texture(
            geometry,
            ("flows", format),
            geometry.flow_layer_count,
            &bytes,
        )
    }

    /// A texture array of `geometry`'s crop, `layers` layers (one at least) of `format`
    /// holding `bytes`, layer after layer (zeros where it is empty).
    fn crop_texture(
        &self,
        geometry: &PoseGeometry,
        (label, format): (&str, wgpu::TextureFormat),
        layers: usize,
        bytes: &[u8],
    ) -> wgpu::Texture {
        let crop = geometry.crop;
        let layers = layers.max(1);
        let zeros;
        let bytes = if bytes.is_empty() {
            let texel = format.block_copy_size(None).unwrap_or(4) as usize;
            zeros = vec![0u8; crop.texels() * layers * texel];
            &zeros
        } else {
            bytes
        };
        self.device.create_texture_with_data(
            &self.queue,
            &wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: crop.width,
                    height: crop.height,
                    depth_or_array_layers: layers as u32,
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
    }

    /// Relights `pose` with `source`'s coefficients (the views and geometry it was made
    /// from): new coefficients and one dispatch pair per batch of views
    /// ([`super::relight`]), recorded with the pending work, not submitted.
    pub fn relight_pose(&self, pose: &mut GpuPose, source: &PoseSource) -> Result<()> {
        if pose.texels.is_some() {
            return Err(crate::RenderError::Misuse(
                "relighting a pose whose pre-lit views are a texture".into(),
            ));
        }
        let mut relight = match pose.relight.take() {
            Some(r) => r,
            None => {
                // Let go of ([`GpuPose::release_basis`]): uploaded again.
                let basis = self.upload_basis(source)?;
                let hull = pose.geometry.proxy.hull_shared().cloned();
                self.pose_relight(basis, hull)
            }
        };
        let done = self.scoped("relighting a resident pose", || {
            if !relight.basis().holds(&source.basis) {
                return Err(crate::RenderError::Misuse(
                    "relighting a pose with another pose's views".into(),
                ));
            }
            self.record_relight(&mut relight, source, &pose.prelit);
            Ok(())
        });
        pose.relight = Some(relight);
        done
    }

    /// The views' pre-lit colour scales as the GPU holds them (for tests and inspection).
    pub fn read_scales(&self, pose: &GpuPose) -> Result<Vec<f32>> {
        self.scoped("reading a pose's scales back", || {
            Ok(self.read_prelit_range(&pose.prelit)?.0)
        })
    }

    /// Makes a pose relit on the CPU resident with the storage `pass` reads
    /// ([`super::formats`]): its pre-lit codes and flows uploaded in those formats (the
    /// benchmark's way to compare them, and the motion views'; the renderer relights on
    /// the GPU).
    pub fn upload_resident(&self, resident: &ResidentPose, pass: &PoseBinding) -> Result<GpuPose> {
        self.scoped("making a CPU-relit pose resident", || {
            let geometry = &resident.geometry;
            let texels = geometry.crop.texels();
            // The held views' texels, layer by layer (a held view without texels: zero).
            let mut prelit_bytes: Vec<u8> =
                Vec::with_capacity(geometry.prelit_layer_count * texels * 4);
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
            let flows = if pass.formats.flow.in_texture() {
                let stored = resident.flows.codes.iter().flat_map(|f| f.iter().flatten());
                let q = &resident.flows.quantizer;
                let decoded: Vec<[f32; 2]> = stored
                    .flat_map(|codes| codes.iter().map(|&c| decode_flow(c, q).to_array()))
                    .collect();
                let bytes = pass.formats.flow.encode(&decoded).unwrap_or_default();
                let format = pass.formats.flow.texture();
                Flows::Texture(self.flows_texture(geometry, format, bytes))
            } else {
                Flows::Shared(self.flow_range(geometry, &resident.flows))
            };
            let renderers = std::ptr::eq(pass, &self.rebin.pose);
            let tables = self.pose_tables(renderers, geometry, &resident.flows);
            let parts = if pass.formats.image.in_texture() {
                let format = pass.formats.image.texture();
                let layers = geometry.prelit_layer_count;
                let texture =
                    self.crop_texture(geometry, ("prelit", format), layers, &prelit_bytes);
                let heads = self.prelit_with(geometry, &resident.scales, &[]);
                (heads, flows, Some(texture))
            } else {
                let range = self.prelit_with(geometry, &resident.scales, &prelit_bytes);
                (range, flows, None)
            };
            Ok(self.resident_pose(pass, tables, parts, geometry))
        })
    }

    /// Makes a pose of motion views ([`crate::motion::pose_motion`]) resident as the
    /// renderer's frame pass reads poses.
    pub fn upload_motion(&self, motion: &ResidentPose) -> Result<GpuPose> {
        self.upload_resident(motion, &self.rebin.pose)
    }

    /// Reads back the pre-lit texels of every view (for tests and inspection; a view not
    /// held reads as no texels).
    pub fn read_prelit(&self, pose: &GpuPose) -> Result<Vec<Vec<[u8; 4]>>> {
        self.scoped("reading pre-lit views back", || {
            let layers = match &pose.texels {
                None => self.read_prelit_range(&pose.prelit)?.1,
                Some(texture) => self.read_texture_layers(texture)?,
            };
            Ok(pose
                .geometry
                .prelit_layers
                .iter()
                .map(|&l| usize::try_from(l).map_or(Vec::new(), |l| layers[l].clone()))
                .collect())
        })
    }

    /// Every layer's texels of a texture array of 4-byte texels.
    fn read_texture_layers(&self, texture: &wgpu::Texture) -> Result<Vec<Vec<[u8; 4]>>> {
        let (w, h, layers) = (
            texture.width(),
            texture.height(),
            texture.depth_or_array_layers(),
        );
        let row = (w * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("prelit readback"),
            size: u64::from(row * h * layers),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("prelit readback"),
            });
        copy_to_buffer(&mut encoder, texture, &buffer, row, (w, h, layers));
        self.submit([encoder.finish()]);
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
