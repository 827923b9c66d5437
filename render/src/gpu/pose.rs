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
use super::formats::{ImageFormat, PoseFormats};
use super::pose_tables::{PoseTables, PrelitAt};
use super::prelit::PrelitRange;
use super::relight::{GpuBasis, PoseRelight};
use crate::error::Result;
use crate::geometry::PoseGeometry;
use crate::resident::{PoseSource, ResidentPose, decode_flow};
use crate::shadow::ShadowMaps;
use frf_shaders::types::GpuView;

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
    pub(super) group_key: (u64, usize),
    pub(super) prelit: Prelit,
    /// Its flows and tables, shared with the other copies of its views
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

/// Where a resident pose's pre-lit views are.
pub(super) enum Prelit {
    /// A range of the shared pages ([`super::prelit`]): the renderer's, relit on the GPU.
    Shared(PrelitRange),
    /// A texture array of its own, its scales in its view table (the benchmark's sRGB8
    /// storage, [`super::formats`]).
    Texture(wgpu::Texture),
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
    /// Its pre-lit views' range of the shared pages (none for a texture-stored pose).
    pub(super) fn prelit_range(&self) -> Option<&PrelitRange> {
        match &self.prelit {
            Prelit::Shared(range) => Some(range),
            Prelit::Texture(_) => None,
        }
    }

    /// Where its pre-lit views lie in the shared pages (`prelit` of the frame pass's
    /// record; zero for a texture).
    pub(super) fn prelit_words(&self) -> [u32; 4] {
        self.prelit_range().map_or([0; 4], PrelitRange::words)
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
        let tables = self.pose_tables(
            std::ptr::eq(pass, &self.rebin.pose),
            (geometry, &source.flows),
            None,
            || {
                // One layer per stored flow, in the order of the geometry's flow layers.
                let codes = source.flows.codes.iter().flat_map(|f| f.iter().flatten());
                let mut bytes: Vec<u8> = codes
                    .flat_map(|c| c.iter().flat_map(|c| [c[0] as u8, c[1] as u8]))
                    .collect();
                if bytes.is_empty() {
                    // Unknown: no displacement.
                    bytes = vec![128u8; geometry.crop.texels() * 2];
                }
                self.flows_texture(geometry, wgpu::TextureFormat::Rg8Sint, bytes)
            },
        );
        // Scales are set by the relighting pass; a view not relit keeps 1.
        let range = self.take_prelit(
            geometry.views(),
            geometry.prelit_layer_count,
            geometry.crop.texels(),
        );
        let mut pose = self.resident_pose(pass, tables, Prelit::Shared(range), geometry);
        let hull = pose.geometry.proxy.hull_shared().cloned();
        let mut relight = self.pose_relight(basis, geometry.views(), hull);
        if let Some(target) = pose.prelit_range() {
            self.record_relight(&mut relight, source, (target, &pose.tables.views));
        }
        pose.relight = Some(relight);
        Ok(pose)
    }

    /// A pose of `geometry` drawn from `tables` and `prelit` by `pass`.
    fn resident_pose(
        &self,
        pass: &PoseBinding,
        tables: Arc<PoseTables>,
        prelit: Prelit,
        geometry: &Arc<PoseGeometry>,
    ) -> GpuPose {
        let at = match &prelit {
            Prelit::Shared(range) => PrelitAt::Shared(range),
            Prelit::Texture(texture) => PrelitAt::Texture(texture),
        };
        let (bind_group, group_key) = self.pose_group((&pass.layout, &pass.sampler), &tables, at);
        GpuPose {
            bind_group,
            group_key,
            prelit,
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
        let Prelit::Shared(target) = &pose.prelit else {
            return Err(crate::RenderError::Misuse(
                "relighting a pose whose pre-lit views are a texture".into(),
            ));
        };
        let mut relight = match pose.relight.take() {
            Some(r) => r,
            None => {
                // Let go of ([`GpuPose::release_basis`]): uploaded again.
                let basis = self.upload_basis(source)?;
                let hull = pose.geometry.proxy.hull_shared().cloned();
                self.pose_relight(basis, source.geometry.views(), hull)
            }
        };
        let done = self.scoped("relighting a resident pose", || {
            if !relight.basis().holds(&source.basis) {
                return Err(crate::RenderError::Misuse(
                    "relighting a pose with another pose's views".into(),
                ));
            }
            self.record_relight(&mut relight, source, (target, &pose.tables.views));
            Ok(())
        });
        pose.relight = Some(relight);
        done
    }

    /// The views' pre-lit colour scales as the GPU holds them (for tests and inspection).
    pub fn read_scales(&self, pose: &GpuPose) -> Result<Vec<f32>> {
        self.scoped("reading a pose's scales back", || match &pose.prelit {
            Prelit::Shared(range) => Ok(self.read_prelit_range(range)?.0),
            Prelit::Texture(_) => {
                let bytes = self.read_back(&pose.tables.views, "views readback")?;
                let views: &[GpuView] = bytemuck::cast_slice(&bytes);
                Ok(views[..pose.geometry.views()]
                    .iter()
                    .map(|v| v.scale)
                    .collect())
            }
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
            let flows = || {
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
                self.flows_texture(geometry, pass.formats.flow.texture(), bytes)
            };
            let source = (geometry, &resident.flows);
            let layers = geometry.prelit_layer_count;
            let (tables, prelit) = match pass.formats.image {
                ImageFormat::Codes => (
                    self.pose_tables(std::ptr::eq(pass, &self.rebin.pose), source, None, flows),
                    Prelit::Shared(self.prelit_with(&resident.scales, layers, &prelit_bytes)),
                ),
                ImageFormat::Srgb8 => {
                    let format = pass.formats.image.texture();
                    let texture =
                        self.crop_texture(geometry, ("prelit", format), layers, &prelit_bytes);
                    let tables = self.pose_tables(
                        std::ptr::eq(pass, &self.rebin.pose),
                        source,
                        Some(&resident.scales),
                        flows,
                    );
                    (tables, Prelit::Texture(texture))
                }
            };
            Ok(self.resident_pose(pass, tables, prelit, geometry))
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
            let layers = match &pose.prelit {
                Prelit::Shared(range) => self.read_prelit_range(range)?.1,
                Prelit::Texture(texture) => self.read_texture_layers(texture)?,
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
