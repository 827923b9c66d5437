//! Relighting a resident pose on the GPU (`shaders/relight.wgsl`), twin of
//! [`crate::resident::ResidentPose::relight_cpu`].
//!
//! A pose's basis codes are uploaded once into a range of the shared basis pages
//! ([`GpuBasis`], shared by every relit copy of the same views: walkers of other headings,
//! the same walker under a new light). A light is then its new coefficients, written into
//! the copy's range of the coefficients' pages (by the host, or looked up by the device
//! from the light's yaw tables, [`super::turn_light`]), and the copy's jobs, one a view,
//! gathered with every other copy's relit before the next submission
//! ([`super::relights`]): one dispatch sums the basis images of every job, one encodes
//! them into the copies' pre-lit layers with each view's peak as its scale, both written
//! by the GPU into the copies' ranges of the shared pre-lit pages ([`super::prelit`]).
//! Nothing is uploaded again, nothing is read back and nothing waits; the pair runs after
//! the one dispatch that made all their suns' maps ([`super::sun_depth`]), which
//! [`Gpu::submit`] sends just ahead of the next frame.

use std::sync::Arc;

use frf_core::image::Rgb;
use frf_reflectance::hull::VoxelHull;
use frf_reflectance::imagecodec::BasisCodes;
use frf_reflectance::light_fit::{RATIO_FLOOR, group_cone};
use frf_reflectance::sun_light::{MAX_SUNS, NEAREST, SunLight, TRUST_ERROR};
use frf_shaders::types::{GpuRelightJob, GpuTurnRelight};
use wgpu::util::DeviceExt;

use super::arena::ArenaRange;
use super::bind::{compute_pipeline, storage, table_bytes, uniform};
use super::pose_tables::gpu_view;
use super::prelit::PrelitRange;
use super::relights::Gathered;
use super::sun_depth::SunMapsAt;
use super::{Gpu, shaders};
use crate::error::Result;
use crate::resident::PoseSource;

/// Bytes of a page of basis codes (the device's largest storage binding caps it).
pub(super) const BASIS_PAGE_BYTES: u64 = 1 << 30;

/// Most bytes of basis codes one batch of views holds.
const RELIGHT_BATCH_BYTES: usize = 64 << 20;

/// The relighting pipelines and the gamma table they decode codes with.
pub struct RelightPass {
    pub(super) layout: wgpu::BindGroupLayout,
    pub(super) relight: wgpu::ComputePipeline,
    pub(super) encode: wgpu::ComputePipeline,
    pub(super) gamma: wgpu::Buffer,
    /// The suns' maps bound for a pose without a hull (never read: its suns cast no
    /// shadow; a binding is never empty).
    no_depths: wgpu::Buffer,
}

impl RelightPass {
    /// Builds the pass on `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        let module = shaders::module(device, "relight", shaders::RELIGHT);
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("relight"),
            entries: &[
                uniform::<[[f32; 4]; 64]>(0, c),
                storage::<u32>(1, true, c),
                storage::<[f32; 4]>(2, true, c),
                storage::<[f32; 4]>(3, false, c),
                storage::<u32>(4, false, c),
                storage::<u32>(5, false, c),
                storage::<GpuRelightJob>(6, true, c),
                storage::<f32>(7, true, c),
            ],
        });
        let compute = |entry: &str| compute_pipeline(device, entry, &[&layout], &module, entry);
        let gamma = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("gamma"),
            contents: &table_bytes(&[frf_reflectance::imagecodec::gamma_lut()]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let no_depths = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("no sun depths"),
            contents: bytemuck::bytes_of(&f32::MIN),
            usage: wgpu::BufferUsages::STORAGE,
        });
        Self {
            relight: compute("relight"),
            encode: compute("encode"),
            layout,
            gamma,
            no_depths,
        }
    }
}

/// One batch of views' codes and jobs.
struct BasisBatch {
    /// The views (indices into the pose's views), in job order.
    views: Vec<usize>,
    /// Its codes, a range of the shared basis pages.
    codes: ArenaRange,
    /// Its jobs, their offsets counting from the batch's own codes and coefficients, and
    /// no copy's parts (its peaks, scratch and pre-lit range) filled in.
    jobs: Vec<GpuRelightJob>,
    /// Coefficients (`vec4`) the batch's jobs read.
    coefficients: usize,
    /// Per job, where its coefficients start.
    offsets: Vec<u32>,
}

/// The basis codes of a pose's views resident on the GPU (see the module docs).
pub struct GpuBasis {
    batches: Vec<BasisBatch>,
    /// The host codes it was made from, kept so that their address names it.
    made_from: Arc<Vec<BasisCodes>>,
    bytes: u64,
}

impl GpuBasis {
    /// Bytes it holds on the GPU.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Per batch of views, the views (indices into the pose's) and where each one's
    /// coefficients start in the batch's.
    pub(super) fn batch_jobs(&self) -> impl Iterator<Item = (&[usize], &[u32])> {
        self.batches
            .iter()
            .map(|b| (b.views.as_slice(), b.offsets.as_slice()))
    }

    /// Whether it holds `codes` (the same host copy).
    pub fn holds(&self, codes: &Arc<Vec<BasisCodes>>) -> bool {
        Arc::ptr_eq(&self.made_from, codes)
    }
}

/// What a relit pose keeps to be relit again: the shared codes and its own coefficients
/// (a range a batch).
pub struct PoseRelight {
    basis: Arc<GpuBasis>,
    /// Its coefficients, a range of the shared pages a batch (the device's look-ups of
    /// every pose relit in a submission write them in one dispatch).
    coefficients: Vec<Arc<ArenaRange>>,
    /// Its hull, whose maps toward the suns the GPU makes at each relight (none without
    /// a hull: its suns cast no shadow).
    hull: Option<Arc<VoxelHull>>,
    /// Where its suns' maps were made at its last relight (read back by tests).
    pub(super) sun_maps: Option<SunMapsAt>,
    /// What relights it on the device ([`super::turn_light`]), made the first time.
    pub(super) turn: Option<TurnState>,
}

/// What a pose keeps to be relit on the device (`super::turn_light`): per batch of views
/// its jobs, the field's conditions, its views' scales and the plan's mask (a range of the
/// shared pages), the record of where they lie (where its light and coefficients lie
/// filled in at each relight), and its threads.
pub struct TurnState {
    pub(super) batches: Vec<(Arc<ArenaRange>, GpuTurnRelight, u32)>,
}

impl PoseRelight {
    /// The shared codes.
    pub fn basis(&self) -> &Arc<GpuBasis> {
        &self.basis
    }

    /// Where its suns' maps were made at its last relight (none without a hull).
    pub(super) fn sun_maps(&self) -> Option<&SunMapsAt> {
        self.sun_maps.as_ref()
    }

    /// The coefficients of its batch `b` (none past its batches).
    pub(super) fn coefficient_range(&self, b: usize) -> Option<&Arc<ArenaRange>> {
        self.coefficients.get(b)
    }
}

/// Coefficients (`vec4`) a job of `tiles` basis images reads: per image its coefficient,
/// where its condition's lights are and the suns' coefficient, then [`MAX_SUNS`] slots of
/// a sun: per image the sun per unit of its light, then the sun's [`SUN_HEAD`].
fn job_coefficients(tiles: usize) -> usize {
    3 * tiles + MAX_SUNS * (tiles + SUN_HEAD)
}

/// Coefficients (`vec4`) view `i`'s job reads: [`job_coefficients`], then, where it holds
/// normals, one a light of each floor condition (its share reweighted by the ground's
/// shape; zero when the light does not reweight it): the same whatever the light, so that
/// a pose relit in place keeps its buffers.
fn job_len(source: &PoseSource, i: usize) -> usize {
    job_coefficients(source.basis[i].scales.len()) + floor_len(source, i)
}

/// The floor conditions' lights of view `i`'s job ([`job_len`]).
fn floor_len(source: &PoseSource, i: usize) -> usize {
    if source.normals.get(i).is_none_or(|n| n.is_empty()) {
        return 0;
    }
    let tiles = source.basis[i].scales.len();
    let lights = source.condition_lights.iter().take(tiles);
    lights
        .zip(source.floor_conditions.iter())
        .filter(|(_, f)| **f)
        .map(|(l, _)| l.len())
        .sum()
}

/// View `i`'s floor conditions' reweighted shares, where it holds normals to relight them.
fn floor_shares(source: &PoseSource, i: usize) -> Option<&Vec<Vec<f32>>> {
    source
        .floor_shares
        .get(i)
        .filter(|_| source.normals.get(i).is_some_and(|n| !n.is_empty()))
}

/// The coefficients (`vec4`) of a sun's slot after its per-image ones.
const SUN_HEAD: usize = 10;
// A slot holds two conditions left out, each predicted from two others.
const _: () = assert!(NEAREST <= 2);

/// Coefficients (`vec4`) the conditions' lights take after a batch's jobs: per condition
/// its cone ([`group_cone`]) and one a light, where the pose's views hold normals (only
/// they are shaded by them).
fn light_coefficients(source: &PoseSource) -> usize {
    if source.normals.iter().any(|n| !n.is_empty()) {
        source.condition_lights.iter().map(|l| l.len() + 1).sum()
    } else {
        0
    }
}

/// The coefficients of `batch`'s jobs for `source` (`shaders/relight.wgsl` says what each
/// holds): per view and basis image, RGB times the image's scale, and whether the
/// condition is used at all; where its condition's lights are; then [`MAX_SUNS`] slots of
/// a sun's terms, the suns first and the rest zero (all zero where the view holds no
/// normals).
fn packed_coefficients(
    batch: &BasisBatch,
    source: &PoseSource,
    maps: Option<&SunMapsAt>,
) -> Vec<[f32; 4]> {
    let mut out = Vec::with_capacity(batch.coefficients.max(1));
    // The conditions' cones and lights follow the jobs: where each condition's start.
    let jobs: usize = batch.views.iter().map(|&i| job_len(source, i)).sum();
    let mut ranges = Vec::with_capacity(source.condition_lights.len());
    let mut start = jobs;
    for lights in source.condition_lights.iter() {
        ranges.push([start as f32, lights.len() as f32, 0.0, 0.0]);
        start += lights.len() + 1;
    }
    for &i in &batch.views {
        let scales = &source.basis[i].scales;
        let sun_coefficients = source.sun_coefficients.get(i);
        let of = |c: Option<&Vec<Rgb>>, k: usize| c.and_then(|c| c.get(k)).copied();
        for (k, &s) in scales.iter().enumerate() {
            let c = of(source.coefficients.get(i), k).unwrap_or([0.0; 3]);
            let d = of(sun_coefficients, k).unwrap_or([0.0; 3]);
            let used = if c.iter().chain(&d).all(|&x| x == 0.0) {
                0.0
            } else {
                1.0
            };
            out.push([c[0] * s, c[1] * s, c[2] * s, used]);
        }
        // Where each floor condition's reweighted shares are (after the sun slots), and
        // the ratio's floor.
        let floor = floor_shares(source, i);
        let mut share_at = out.len() - scales.len() + job_coefficients(scales.len());
        // Each floor condition's room, in order, and what fills it (zeros: not reweighted).
        let mut room: Vec<[f32; 4]> = Vec::with_capacity(floor_len(source, i));
        let with_room = floor_len(source, i) > 0;
        for k in 0..scales.len() {
            let mut range = ranges.get(k).copied().unwrap_or([0.0; 4]);
            let lights = source.condition_lights.get(k).map_or(0, Vec::len);
            if with_room && source.floor_conditions.get(k).copied().unwrap_or(false) {
                match floor.and_then(|f| f.get(k)).filter(|e| e.len() == lights) {
                    Some(e) => {
                        range[2] = share_at as f32;
                        range[3] = RATIO_FLOOR;
                        room.extend(e.iter().map(|&x| [x, 0.0, 0.0, 0.0]));
                    }
                    None => room.extend(std::iter::repeat_n([0.0; 4], lights)),
                }
                share_at += lights;
            }
            out.push(range);
        }
        for (k, &s) in scales.iter().enumerate() {
            let d = of(sun_coefficients, k).unwrap_or([0.0; 3]);
            out.push([d[0] * s, d[1] * s, d[2] * s, 0.0]);
        }
        let suns: &[SunLight] = if sun_coefficients.is_none() {
            &[]
        } else {
            &source.suns[..source.suns.len().min(MAX_SUNS)]
        };
        for (s, sun) in suns.iter().enumerate() {
            let depth_at = maps.and_then(|m| m.starts.get(s).copied().flatten());
            pack_sun(&mut out, sun, (i, scales), depth_at);
        }
        let empty = MAX_SUNS - suns.len();
        out.extend(std::iter::repeat_n(
            [0.0; 4],
            empty * (scales.len() + SUN_HEAD),
        ));
        out.extend(room);
    }
    // Every batch holds the conditions' lights after its jobs, where the views hold
    // normals ([`light_coefficients`]).
    if light_coefficients(source) > 0 {
        for lights in source.condition_lights.iter() {
            // An infinite bound as the largest float (the lights one by one, always).
            let (m, bound) = group_cone(lights);
            out.push(m.extend(bound.min(f32::MAX)).to_array());
            out.extend(lights.iter().map(|(d, share)| d.extend(*share).to_array()));
        }
    }
    if out.is_empty() {
        out.push([0.0; 4]);
    }
    out
}

/// One slot of view `i`'s job for `sun` (`shaders/relight.wgsl` says what each holds),
/// its map of the hull, if any, from `depth_at` on in the batch's maps
/// ([`SunMapsAt::reach`]; `None`: no map, no cast shadows).
fn pack_sun(
    out: &mut Vec<[f32; 4]>,
    sun: &SunLight,
    (i, scales): (usize, &[f32]),
    depth_at: Option<usize>,
) {
    out.extend(
        sun.unit
            .iter()
            .zip(scales)
            .map(|(u, &s)| [u[0] * s, u[1] * s, u[2] * s, 0.0]),
    );
    let view = &sun.views[i];
    let (mut nearest, mut weights) = ([0.0f32; 4], [0.0f32; 4]);
    for (j, &(k, w)) in view.nearest.iter().take(3).enumerate() {
        nearest[j] = k as f32;
        weights[j] = w;
    }
    nearest[3] = view.nearest.len().min(3) as f32;
    weights[3] = RATIO_FLOOR;
    out.push(view.direction.extend(1.0).to_array());
    out.push(nearest);
    out.push(weights);
    if let (Some(m), Some(depth_at)) = (&sun.depth, depth_at) {
        out.push(sun.subject.extend(sun.shadow_offset_m).to_array());
        out.push(m.axes[0].extend(m.corner.x).to_array());
        out.push(m.axes[1].extend(m.corner.y).to_array());
        let [w, h] = m.size;
        out.push([m.texel, w as f32, h as f32, depth_at as f32]);
    } else {
        out.push(sun.subject.extend(0.0).to_array());
        out.extend([[0.0; 4]; 3]);
    }
    // Each nearest condition left out: the two that predict it, and their weights.
    let (mut held, mut held_weights) = ([0.0f32; 4], [0.0f32; 4]);
    for (j, others) in view.held_out.iter().take(2).enumerate() {
        for (m, &(k, w)) in others.iter().take(2).enumerate() {
            held[2 * j + m] = k as f32;
            held_weights[2 * j + m] = w;
        }
    }
    out.push(held);
    out.push(held_weights);
    out.push([
        view.compactness,
        sun.luminance,
        TRUST_ERROR[0],
        TRUST_ERROR[1],
    ]);
}

impl Gpu {
    /// Uploads the basis codes of `source`'s views read (with their alpha codes), in
    /// batches of up to [`RELIGHT_BATCH_BYTES`].
    pub fn upload_basis(&self, source: &PoseSource) -> Result<Arc<GpuBasis>> {
        self.scoped("uploading basis codes", || {
            let texels = source.geometry.crop.texels();
            let read: Vec<usize> = (0..source.basis.len())
                .filter(|&i| !source.is_blank(i) && source.geometry.prelit_layers[i] >= 0)
                .collect();
            let mut groups: Vec<Vec<usize>> = Vec::new();
            let mut bytes = 0;
            for &i in &read {
                if groups.is_empty() || bytes >= RELIGHT_BATCH_BYTES {
                    groups.push(Vec::new());
                    bytes = 0;
                }
                groups.last_mut().expect("pushed").push(i);
                bytes += (source.basis[i].tiles.len() * texels + source.surfaces[i].len()) * 4;
            }
            let batches: Vec<BasisBatch> = groups
                .into_iter()
                .map(|views| self.basis_batch(source, views))
                .collect();
            let bytes = batches.iter().map(|b| b.codes.size()).sum();
            Ok(Arc::new(GpuBasis {
                batches,
                made_from: source.basis.clone(),
                bytes,
            }))
        })
    }

    /// One batch of `views` of `source`: codes packed RGBA8 (tile 0's alpha byte holding
    /// the view's alpha code, tiles 1 and 2's its normal's codes), then the view's texels'
    /// points on the hull where it has them, in a range of the basis pages; its jobs.
    fn basis_batch(&self, source: &PoseSource, views: Vec<usize>) -> BasisBatch {
        let crop = source.geometry.crop;
        let texels = crop.texels();
        let mut codes: Vec<u32> = Vec::new();
        let mut jobs = Vec::with_capacity(views.len());
        let mut coefficients = 0;
        let mut offsets = Vec::with_capacity(views.len());
        for (j, &i) in views.iter().enumerate() {
            let basis = &source.basis[i];
            jobs.push(GpuRelightJob {
                basis_offset: codes.len() as u32,
                coefficient_offset: coefficients as u32,
                tiles: basis.tiles.len() as u32,
                view: i as u32,
                layer: source.geometry.prelit_layers[i] as u32,
                surface: u32::from(!source.surfaces[i].is_empty()),
                texels: texels as u32,
                width: crop.width,
                x0: crop.x0,
                y0: crop.y0,
                sun_slots: MAX_SUNS as u32,
                camera: gpu_view(&source.geometry.cameras[i]),
                ..bytemuck::Zeroable::zeroed()
            });
            offsets.push(coefficients as u32);
            coefficients += job_len(source, i);
            if j + 1 == views.len() {
                coefficients += light_coefficients(source);
            }
            let normals = &source.normals[i];
            for (k, tile) in basis.tiles.iter().enumerate() {
                codes.extend(tile.iter().enumerate().map(|(p, c)| {
                    // The alpha bytes: tile 0's, the alpha code; tiles 1 and 2's, the
                    // normal's codes.
                    let fourth = match k {
                        0 => source.alpha[i][p],
                        1 | 2 => normals.get(p).map_or(0, |n| n[k - 1]),
                        _ => 0,
                    } as u32;
                    c[0] as u32 | (c[1] as u32) << 8 | (c[2] as u32) << 16 | fourth << 24
                }));
            }
            codes.extend(source.surfaces[i].iter().map(|t| t.to_bits()));
        }
        if codes.is_empty() {
            codes.push(0);
        }
        // A new range (a range given back is taken again only after a submission): the
        // write lands ahead of any work that reads it.
        let range = self.basis.take(&self.device, (codes.len() * 4) as u64);
        self.queue
            .write_buffer(range.buffer(), range.offset(), bytemuck::cast_slice(&codes));
        BasisBatch {
            codes: range,
            jobs,
            views,
            coefficients,
            offsets,
        }
    }

    /// A pose's own relighting buffers over the shared `basis`, with its hull (`None`:
    /// none), whose suns' maps each relight makes.
    pub(super) fn pose_relight(
        &self,
        basis: Arc<GpuBasis>,
        hull: Option<Arc<VoxelHull>>,
    ) -> PoseRelight {
        PoseRelight {
            coefficients: basis
                .batches
                .iter()
                .map(|b| {
                    let bytes = (b.coefficients.max(1) * 16) as u64;
                    Arc::new(self.coefficients.take(&self.device, bytes))
                })
                .collect(),
            basis,
            hull,
            sun_maps: None,
            turn: None,
        }
    }

    /// Asks for its suns' maps ([`super::sun_depth`], made with every other walker's in
    /// one dispatch ahead of the relights), writes `source`'s coefficients into
    /// `relight`'s buffers and gathers the jobs that relight its views into the pose's
    /// pre-lit range `target` ([`Gpu::relight_pose`]); keeps where the maps are.
    pub(super) fn record_relight(
        &self,
        relight: &mut PoseRelight,
        source: &PoseSource,
        target: &PrelitRange,
    ) {
        relight.sun_maps = relight.hull.as_ref().map(|hull| {
            let maps: Vec<_> = source.suns.iter().map(|s| s.depth.as_ref()).collect();
            self.ask_sun_maps(hull, &maps)
        });
        let maps = relight.sun_maps.as_ref();
        // A look-up of its light gathered before would overwrite these.
        self.forget_turns(relight);
        for (batch, range) in relight.basis.batches.iter().zip(&relight.coefficients) {
            let packed = packed_coefficients(batch, source, maps);
            self.upload(
                range.buffer(),
                range.offset(),
                bytemuck::cast_slice(&packed),
            );
        }
        self.gather_relight(relight, target);
    }

    /// Gathers the jobs that relight `relight`'s views from its coefficients into the
    /// pose's pre-lit range `target` (codes and scales), a batch of views at a time, for
    /// the next submission's relighting pass ([`super::relights`]; after the look-ups of
    /// every light on the device gathered for the submission, [`super::turn_light`],
    /// which write the coefficients).
    pub(super) fn gather_relight(&self, relight: &PoseRelight, target: &PrelitRange) {
        let depths = relight
            .sun_maps
            .as_ref()
            .map_or(&self.relight.no_depths, |m| &m.reach);
        let [heads_at, codes_at] = target.words();
        for (batch, coefficients) in relight.basis.batches.iter().zip(&relight.coefficients) {
            let basis_at = (batch.codes.offset() / 4) as u32;
            let jobs = batch
                .jobs
                .iter()
                .map(|job| GpuRelightJob {
                    basis_offset: basis_at + job.basis_offset,
                    coefficients_at: coefficients.vec4_offset(),
                    heads_at,
                    codes_at,
                    ..*job
                })
                .collect();
            self.gather(Gathered {
                coefficients: coefficients.key(),
                pages: [
                    batch.codes.buffer().clone(),
                    coefficients.buffer().clone(),
                    target.page().clone(),
                    depths.clone(),
                ],
                jobs,
            });
        }
    }

    /// Runs `f` on the pending encoder (made when there is none): work recorded between
    /// frames (relights, shadows) that [`Gpu::submit`] sends ahead of the next.
    pub(super) fn with_pending<T>(&self, f: impl FnOnce(&mut wgpu::CommandEncoder) -> T) -> T {
        let mut pending = self.pending.lock().unwrap_or_else(|e| e.into_inner());
        let encoder = pending.get_or_insert_with(|| self.pending_encoder());
        f(encoder)
    }

    /// A new encoder for the work recorded between frames.
    pub(super) fn pending_encoder(&self) -> wgpu::CommandEncoder {
        self.device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("pending"),
            })
    }

    /// Submits `buffers`, after the pending work (in a submission of its own, so that a
    /// frame the device refuses does not take the relights recorded before it along).
    /// Submitting is the host's work (wgpu validates and hands the buffers over): its
    /// time is not counted as waiting on the device ([`Gpu::waited`]).
    pub fn submit(
        &self,
        buffers: impl IntoIterator<Item = wgpu::CommandBuffer>,
    ) -> wgpu::SubmissionIndex {
        let pending = self
            .pending
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take();
        // The lights looked up on the device, then the relights gathered, a pass each,
        // after the pending clears.
        let pending = self.record_turns(pending);
        let pending = self.record_relights(pending).map(|p| p.finish());
        let buffers: Vec<wgpu::CommandBuffer> = buffers.into_iter().collect();
        // The small writes every later piece reads, then the suns' maps the pending
        // relights read.
        self.submit_uploads();
        self.submit_sun_maps();
        if let Some(p) = pending {
            self.submit_counted([p]);
        }
        let index = self.submit_counted(buffers);
        // Ranges of the shared pages let go of before now are free again: what read them
        // is in the queue ahead of any later write.
        self.coefficients.recycle();
        self.turn_data.recycle();
        index
    }

    /// Submits the pending work (before a caller submits its own encoder).
    pub fn flush(&self) {
        self.submit([]);
    }
}
