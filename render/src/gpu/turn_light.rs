//! A light on the device (`shaders/turn_light.wgsl`; docs/design.md section 4.1, *A light
//! on the device*): the yaw tables of a light's maps held on the GPU, and a relight that
//! gathers one small record (the maps' turns and weights, the suns' maps) where the host
//! path works out and uploads every view's coefficients ([`super::relight`]). The views'
//! coefficients of every pose relit between two submissions are then looked up by their
//! turn in one dispatch (a row of workgroups a batch of views), in a pass of its own ahead
//! of the relighting pass that reads them: each pose's coefficients, and its jobs, the
//! field's conditions and its views' scales, are ranges of a few shared pages
//! ([`super::arena`]). A turning light and a crowd of walkers on curves cost the host a
//! record per relight, whatever the views, and the device one dispatch, whatever the
//! walkers.
//!
//! Twin of the host path: the same entries as `packed_coefficients` of the lighting
//! `PoseSource::relit` works out, to within float rounding (the turn's bracket is found in
//! single precision here).

use std::f64::consts::{PI, TAU};
use std::sync::{Arc, Mutex};

use frf_core::image::luminance;
use frf_reflectance::field::{ConditionRecord, PoseRecord};
use frf_reflectance::floor_light::ground_weight;
use frf_reflectance::hull::VoxelHull;
use frf_reflectance::light_fit::{RATIO_FLOOR, condition_lights};
use frf_reflectance::project::FloorModel;
use frf_reflectance::sun_depth::SunDepth;
use frf_reflectance::sun_light::{
    MAX_SUNS, TRUST_ERROR, cell_width, held_out_weights, shadow_offset_m,
};
use frf_reflectance::yaw_light::{TakenSun, YawLight, YawTerm};
use frf_reflectance::yaw_table::{Part, SAMPLES_PER_TURN, YawTable};
use frf_shaders::types::{GpuTurnJob, GpuTurnParams, GpuTurnRelight};

use super::arena::ArenaRange;
use super::bind::{bind_group, buffer_with, compute_pipeline, kept_buffer, storage, uniform};
use super::pose::GpuPose;
use super::relight::{PoseRelight, TurnState};
use super::timing::compute_pass_writes;
use super::{Gpu, shaders};
use crate::error::{RenderError, Result};
use crate::resident::PoseSource;

/// Workgroup size of the pass (`@workgroup_size(64)`).
const WORKGROUP: u32 = 64;
/// The most maps a light relit on the device has (more: the host relights it).
const MOST_TERMS: usize = 8;

/// The pass, the tables it holds and the look-ups gathered for the next submission.
pub struct TurnLightPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    tables: Mutex<HeldTables>,
    gathered: Mutex<Gathered>,
}

/// The look-ups gathered since the last submission: every light's record, one after the
/// other, and per batch of views relit what it reads and writes; the buffers the records
/// go through, kept between submissions.
#[derive(Default)]
struct Gathered {
    lights: Vec<[f32; 4]>,
    relights: Vec<Option<GatheredRelight>>,
    /// Where each batch's coefficients (the range's page and offset) was gathered last:
    /// a batch relit twice before a submission is looked up once, for its later light.
    at: std::collections::HashMap<(usize, u64), usize>,
    records: Option<wgpu::Buffer>,
    light_buffer: Option<wgpu::Buffer>,
}

/// A batch of views to look a light up for, with the ranges it reads and writes (held
/// until the submission, so that neither is taken by another pose meanwhile), the tables'
/// buffer its light's record points into and the size of their coarse maps.
struct GatheredRelight {
    data: Arc<ArenaRange>,
    coefficients: Arc<ArenaRange>,
    tables: wgpu::Buffer,
    coarse: (u32, u32),
    record: GpuTurnRelight,
    threads: u32,
}

impl GatheredRelight {
    /// The buffers and sizes one dispatch must share.
    fn same_dispatch(&self, other: &Self) -> bool {
        self.data.buffer() == other.data.buffer()
            && self.coefficients.buffer() == other.coefficients.buffer()
            && self.tables == other.tables
            && self.coarse == other.coarse
    }
}

/// Every table the device holds, one after the other in one buffer (made again, larger,
/// when a map is added: a light's maps are few and added once).
#[derive(Default)]
struct HeldTables {
    values: Vec<[f32; 4]>,
    buffer: Option<wgpu::Buffer>,
    held: Vec<(Arc<YawTable>, TableAt)>,
    /// The coarse maps' size (the same for every table).
    coarse: (u32, u32),
}

/// A table as the device holds it: where its parts lie, the buffer of every table, and
/// the coarse maps' size.
type HeldAt = (TableAt, wgpu::Buffer, (u32, u32));

/// Where a table's parts lie in the buffer.
#[derive(Debug, Clone)]
struct TableAt {
    whole: u32,
    /// What its suns leave (none without suns).
    less: Option<u32>,
    coarse: u32,
    /// Per sun (brightest first), where its illuminance and radius are.
    suns: Vec<u32>,
}

impl TurnLightPass {
    /// Builds the pass on `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        let module = shaders::module(device, "turn light", shaders::TURN_LIGHT);
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("turn light"),
            entries: &[
                uniform::<GpuTurnParams>(0, c),
                storage::<GpuTurnRelight>(1, true, c),
                storage::<[f32; 4]>(2, true, c),
                storage::<[f32; 4]>(3, true, c),
                storage::<[f32; 4]>(4, true, c),
                storage::<[f32; 4]>(5, false, c),
            ],
        });
        let pipeline = compute_pipeline(device, "turn light", &[&layout], &module, "turn_light");
        Self {
            layout,
            pipeline,
            tables: Mutex::default(),
            gathered: Mutex::default(),
        }
    }
}

/// A light to relight a pose by on the device, with what of its field it needs.
pub struct TurnedLight<'a> {
    /// The light, turned into the walker's frame.
    pub light: &'a YawLight,
    /// The field's conditions.
    pub conditions: &'a [ConditionRecord],
    /// The pose's record (its views' turntable angles), read when the pose is first relit
    /// on the device.
    pub pose: &'a PoseRecord,
    /// Per condition, whether the pose's plan uses it (`None`: all).
    pub used: Option<&'a [bool]>,
}

/// Per condition, the four entries the pass reads (`turn_light.wgsl`'s `conditions`).
fn condition_table(conditions: &[ConditionRecord]) -> Vec<[f32; 4]> {
    let lights = condition_lights(conditions);
    let directions: Vec<glam::Vec3> = lights.iter().map(|l| l.0).collect();
    let mut out = Vec::with_capacity(4 * conditions.len().max(1));
    for (k, ((d, delivered), c)) in lights.iter().zip(conditions).enumerate() {
        out.push(d.extend(if c.floor { 1.0 } else { 0.0 }).to_array());
        let cell = cell_width(&directions, k);
        out.push([delivered[0], delivered[1], delivered[2], cell]);
        let (mut at, mut by) = ([0.0f32; 4], [0.0f32; 4]);
        let held = held_out_weights(&directions, k);
        for (m, &(j, w)) in held.iter().take(2).enumerate() {
            at[m] = j as f32;
            by[m] = w;
        }
        at[2] = held.len().min(2) as f32;
        at[3] = c.lights.len() as f32;
        out.push(at);
        out.push(by);
    }
    if out.is_empty() {
        out.push([0.0; 4]);
    }
    out
}

impl HeldTables {
    /// Adds `table`'s parts (every sample made first) to the values; where they lie.
    fn add(&mut self, table: &Arc<YawTable>) -> Result<TableAt> {
        let coarse = table.coarse_map().image();
        let size = (coarse.width() as u32, coarse.height() as u32);
        if !self.held.is_empty() && self.coarse != size {
            return Err(RenderError::Misuse(
                "maps of coarse maps of two sizes on the device".into(),
            ));
        }
        self.coarse = size;
        let values = &mut self.values;
        let mut push = |part: &[[f32; 4]]| {
            let at = values.len() as u32;
            values.extend_from_slice(part);
            at
        };
        let rgb = |part: Vec<frf_core::image::Rgb>| -> Vec<[f32; 4]> {
            part.iter().map(|c| [c[0], c[1], c[2], 0.0]).collect()
        };
        let whole = push(&rgb(table.samples(Part::Whole)?.unwrap_or_default()));
        let less = table.samples(Part::LessSuns)?.map(|l| push(&rgb(l)));
        let lum: Vec<[f32; 4]> = (0..coarse.height())
            .flat_map(|y| (0..coarse.width()).map(move |x| (x, y)))
            .map(|(x, y)| [luminance(coarse.get(x, y)), 0.0, 0.0, 0.0])
            .collect();
        let coarse_at = push(&lum);
        // Per sun its illuminance (and its luminance), then its radius.
        let suns = (table.suns()?.iter())
            .map(|s| {
                let e = s.illuminance();
                push(&[
                    [e[0], e[1], e[2], luminance(e)],
                    [s.radius(), 0.0, 0.0, 0.0],
                ])
            })
            .collect();
        let at = TableAt {
            whole,
            less,
            coarse: coarse_at,
            suns,
        };
        self.held.push((table.clone(), at.clone()));
        Ok(at)
    }
}

impl Gathered {
    /// Adds `relight`, in place of one gathered before for the same coefficients.
    fn push(&mut self, relight: GatheredRelight) {
        let key = relight.coefficients.key();
        if let Some(&i) = self.at.get(&key) {
            self.relights[i] = None;
        }
        self.at.insert(key, self.relights.len());
        self.relights.push(Some(relight));
    }

    /// Every batch gathered (in order), in runs that one dispatch takes: the same pages
    /// and tables, and at most a dispatch's rows of workgroups.
    fn dispatches(&mut self) -> Vec<Vec<GatheredRelight>> {
        let mut runs: Vec<Vec<GatheredRelight>> = Vec::new();
        for r in self.relights.drain(..).flatten() {
            match runs
                .iter_mut()
                .find(|run| run.len() < MOST_ROWS && run[0].same_dispatch(&r))
            {
                Some(run) => run.push(r),
                None => runs.push(vec![r]),
            }
        }
        self.at.clear();
        runs
    }
}

/// The most rows of workgroups a dispatch has (wgpu's least limit on a dimension).
const MOST_ROWS: usize = 65_535;

impl Gpu {
    /// Lets go of the look-ups gathered for `relight`'s coefficients (the host writes
    /// them instead).
    pub(super) fn forget_turns(&self, relight: &PoseRelight) {
        let mut gathered = (self.turn_light.gathered.lock()).unwrap_or_else(|e| e.into_inner());
        if gathered.relights.is_empty() {
            return;
        }
        for range in (0..).map_while(|b| relight.coefficient_range(b)) {
            if let Some(i) = gathered.at.remove(&range.key()) {
                gathered.relights[i] = None;
            }
        }
    }

    /// Records the look-ups gathered since the last submission into `encoder` (made when
    /// there is none) as one pass: a dispatch for every run of them on the same pages
    /// (one, unless a crowd's coefficients outgrow a page), a row of workgroups a batch of
    /// views. Their records and lights are uploaded with the submission's small writes.
    pub(super) fn record_turns(
        &self,
        encoder: Option<wgpu::CommandEncoder>,
    ) -> Option<wgpu::CommandEncoder> {
        let mut gathered = (self.turn_light.gathered.lock()).unwrap_or_else(|e| e.into_inner());
        let runs = gathered.dispatches();
        if runs.is_empty() {
            gathered.lights.clear();
            return encoder;
        }
        // Each run's records from a multiple of the binding alignment on, in one buffer.
        let align = (self.device.limits().min_storage_buffer_offset_alignment as usize).max(16);
        let mut records: Vec<u8> = Vec::new();
        let mut placed = Vec::with_capacity(runs.len());
        for run in &runs {
            records.resize(records.len().next_multiple_of(align), 0);
            let at = records.len() as u64;
            for r in run {
                records.extend_from_slice(bytemuck::bytes_of(&r.record));
            }
            placed.push((at, records.len() as u64 - at));
        }
        let lights = std::mem::take(&mut gathered.lights);
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let kept = |slot: &mut Option<wgpu::Buffer>, label: &str, bytes: &[u8]| {
            let buffer = kept_buffer(&self.device, slot, (label, usage), bytes.len() as u64, 4096);
            self.upload(&buffer, 0, bytes);
            buffer
        };
        let record_buffer = kept(&mut gathered.records, "turn records", &records);
        let light_buffer = kept(
            &mut gathered.light_buffer,
            "turn lights",
            bytemuck::cast_slice(&lights),
        );
        drop(gathered);
        let mut encoder = encoder.unwrap_or_else(|| self.pending_encoder());
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("turn light"),
            timestamp_writes: compute_pass_writes(self.pass_timestamps("turn light", None)),
        });
        pass.set_pipeline(&self.turn_light.pipeline);
        self.dispatched("turn light", runs.len());
        for (run, (at, size)) in runs.iter().zip(placed) {
            let first = &run[0];
            let params = GpuTurnParams {
                relights: run.len() as u32,
                samples: SAMPLES_PER_TURN as u32,
                sun_slots: MAX_SUNS as u32,
                coarse_w: first.coarse.0,
                coarse_h: first.coarse.1,
                ratio_floor: RATIO_FLOOR,
                trust_low: TRUST_ERROR[0],
                trust_high: TRUST_ERROR[1],
            };
            let params = buffer_with(
                &self.device,
                "turn params",
                bytemuck::bytes_of(&params),
                wgpu::BufferUsages::UNIFORM,
            );
            let bind = bind_group(
                &self.device,
                "turn light",
                &self.turn_light.layout,
                vec![
                    params.as_entire_binding(),
                    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &record_buffer,
                        offset: at,
                        size: wgpu::BufferSize::new(size),
                    }),
                    first.data.buffer().as_entire_binding(),
                    first.tables.as_entire_binding(),
                    light_buffer.as_entire_binding(),
                    first.coefficients.buffer().as_entire_binding(),
                ],
            );
            let threads = run.iter().map(|r| r.threads).max().unwrap_or(0);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(threads.div_ceil(WORKGROUP).max(1), run.len() as u32, 1);
        }
        drop(pass);
        Some(encoder)
    }
}

/// Tables the device holds before those no light holds any more are let go of (a scene
/// whose sun moves makes a table of it at each new place).
const MOST_TABLES: usize = 16;

impl Gpu {
    /// Where `table`'s parts lie on the device, uploading them the first time, and the
    /// buffer that holds every table now. Past [`MOST_TABLES`], the tables nothing else
    /// holds are let go of first (the others move: a light's relights ask again).
    fn held_table(&self, table: &Arc<YawTable>) -> Result<HeldAt> {
        let mut held = self
            .turn_light
            .tables
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        let found = (held.held.iter())
            .find(|(t, _)| Arc::ptr_eq(t, table))
            .map(|(_, at)| at.clone());
        let at = match found {
            Some(at) => at,
            None => {
                if held.held.len() >= MOST_TABLES {
                    let kept: Vec<Arc<YawTable>> = (held.held.drain(..))
                        .map(|(t, _)| t)
                        .filter(|t| Arc::strong_count(t) > 1)
                        .collect();
                    held.values.clear();
                    for t in &kept {
                        held.add(t)?;
                    }
                }
                let at = held.add(table)?;
                held.buffer = Some(buffer_with(
                    &self.device,
                    "yaw tables",
                    bytemuck::cast_slice(&held.values),
                    wgpu::BufferUsages::STORAGE,
                ));
                at
            }
        };
        let buffer = held.buffer.clone().expect("made with the first table");
        Ok((at, buffer, held.coarse))
    }

    /// Tables the device holds now (for tests and inspection).
    pub fn tables_held(&self) -> usize {
        (self.turn_light.tables.lock())
            .unwrap_or_else(|e| e.into_inner())
            .held
            .len()
    }

    /// What `relight`'s batches need to be relit on the device (see [`TurnState`]): per
    /// batch its jobs (two `vec4`s each), the field's conditions (four each) and its words
    /// (its views' scales, then the plan's mask, four a `vec4`) in a range of the shared
    /// pages, uploaded once.
    fn turn_state(
        &self,
        relight: &PoseRelight,
        source: &PoseSource,
        light: &TurnedLight,
    ) -> TurnState {
        let turntables = light.pose.turntables();
        let conditions = condition_table(light.conditions);
        let batches = relight
            .basis()
            .batch_jobs()
            .map(|(views, offsets)| {
                let mut words: Vec<f32> = Vec::new();
                let jobs: Vec<GpuTurnJob> = views
                    .iter()
                    .zip(offsets)
                    .map(|(&i, &offset)| {
                        let scales = &source.basis[i].scales;
                        let job = GpuTurnJob {
                            coefficient_offset: offset,
                            tiles: scales.len() as u32,
                            turn: (turntables.get(i).copied().unwrap_or(0.0) as f64 / TAU) as f32,
                            normals: u32::from(
                                source.normals.get(i).is_some_and(|n| !n.is_empty()),
                            ),
                            scales: words.len() as u32,
                            ..bytemuck::Zeroable::zeroed()
                        };
                        words.extend(scales);
                        job
                    })
                    .collect();
                let mask = words.len() as u32;
                let items = jobs.iter().map(|j| j.tiles).max().unwrap_or(0) + MAX_SUNS as u32;
                words.extend((0..light.conditions.len()).map(|k| {
                    let used = light.used.is_none_or(|u| u.get(k).copied().unwrap_or(true));
                    if used { 1.0 } else { 0.0 }
                }));
                words.resize(words.len().next_multiple_of(4), 0.0);
                let mut data: Vec<[f32; 4]> = bytemuck::cast_slice(&jobs).to_vec();
                let conditions_at = data.len() as u32;
                data.extend_from_slice(&conditions);
                let words_at = data.len() as u32;
                data.extend(words.chunks_exact(4).map(|w| [w[0], w[1], w[2], w[3]]));
                let range = self.turn_data.take(&self.device, (data.len() * 16) as u64);
                self.upload(range.buffer(), range.offset(), bytemuck::cast_slice(&data));
                let base = range.vec4_offset();
                let record = GpuTurnRelight {
                    jobs_at: base,
                    jobs: jobs.len() as u32,
                    items,
                    conditions_at: base + conditions_at,
                    conditions: light.conditions.len() as u32,
                    words_at: base + words_at,
                    mask,
                    ..bytemuck::Zeroable::zeroed()
                };
                (Arc::new(range), record, jobs.len() as u32 * items)
            })
            .collect();
        TurnState { batches }
    }

    /// Relights `pose` (made resident from `source`, its views) under `light` on the
    /// device: its suns' maps asked for, its light's record written, and per batch of
    /// views the lookup of their coefficients and their relighting recorded with the
    /// pending work. `Ok(false)`, nothing done, where the pose holds no relighting
    /// buffers to look them up into (its basis let go of) or the light has more maps
    /// than a record holds: the host path relights it then.
    pub fn relight_turned(
        &self,
        pose: &mut GpuPose,
        source: &PoseSource,
        light: &TurnedLight,
    ) -> Result<bool> {
        let terms = light.light.terms();
        if pose.relight.is_none() || terms.len() > MOST_TERMS {
            return Ok(false);
        }
        self.scoped("relighting a pose on the device", || {
            // Every map's table where it lies, asked again when one asked last made room by
            // moving those asked before it.
            let mut tables = Vec::with_capacity(terms.len());
            for _ in 0..2 {
                tables.clear();
                for t in terms {
                    tables.push(self.held_table(&t.table)?);
                }
                if tables.windows(2).all(|w| w[0].1 == w[1].1) {
                    break;
                }
            }
            let Some((_, arena, coarse)) = tables.last().cloned() else {
                return Ok(false);
            };
            let normals = source.holds_normals();
            let (parts, taken) = light.light.suns_taken(normals)?;
            let taken = &taken[..taken.len().min(MAX_SUNS)];
            let environment = terms
                .iter()
                .all(|t| t.table.floor() == FloorModel::Environment);
            let ground = if normals && environment {
                ground_weight(light.light.ground_share())
            } else {
                0.0
            };
            let geometry = &pose.geometry;
            let hull = geometry.proxy.hull_shared().cloned();
            let occluders = light.light.occluders();
            let depths: Vec<Option<SunDepth>> = taken
                .iter()
                .map(|(_, _, sun)| {
                    let h = hull.as_ref()?;
                    let map = SunDepth::new(h, sun.direction(), geometry.level);
                    Some(if occluders.is_empty() {
                        map
                    } else {
                        map.with_occluders(occluders)
                    })
                })
                .collect();
            let relight = pose.relight.as_mut().expect("checked above");
            relight.sun_maps = hull.as_ref().map(|h| {
                let maps: Vec<Option<&SunDepth>> = depths.iter().map(Option::as_ref).collect();
                self.ask_sun_maps(h, &maps)
            });
            let starts: Vec<Option<usize>> = (0..taken.len())
                .map(|k| {
                    (relight.sun_maps.as_ref()).and_then(|m| m.starts.get(k).copied().flatten())
                })
                .collect();
            let record = light_record(
                (terms, &parts, &tables),
                (taken, &depths, &starts),
                ground,
                hull.as_deref(),
            );
            if relight.turn.is_none() {
                relight.turn = Some(self.turn_state(relight, source, light));
            }
            let relight = pose.relight.as_ref().expect("checked above");
            let state = relight.turn.as_ref().expect("made above");
            let mut gathered = (self.turn_light.gathered.lock()).unwrap_or_else(|e| e.into_inner());
            let light_at = gathered.lights.len() as u32;
            gathered.lights.extend(record);
            for (b, (data, record, threads)) in state.batches.iter().enumerate() {
                let Some(coefficients) = relight.coefficient_range(b) else {
                    continue;
                };
                gathered.push(GatheredRelight {
                    data: data.clone(),
                    coefficients: coefficients.clone(),
                    tables: arena.clone(),
                    coarse,
                    record: GpuTurnRelight {
                        light_at,
                        coefficients_at: coefficients.vec4_offset(),
                        ..*record
                    },
                    threads: *threads,
                });
            }
            drop(gathered);
            if let Some(target) = pose.prelit_range() {
                self.gather_relight(relight, target);
            }
            Ok(true)
        })
    }

    /// The coefficients `pose`'s last relight wrote, per batch of its views (for tests
    /// and inspection: the device's lookup against the host's); none for a pose uploaded
    /// already lit.
    pub fn read_coefficients(&self, pose: &GpuPose) -> Result<Vec<Vec<[f32; 4]>>> {
        let Some(relight) = pose.relight.as_ref() else {
            return Ok(Vec::new());
        };
        self.scoped("reading a pose's coefficients back", || {
            (0..)
                .map_while(|b| relight.coefficient_range(b))
                .map(|range| {
                    let at = (range.offset(), range.size());
                    let bytes = self.read_back_range(range.buffer(), at, "coefficients")?;
                    Ok(bytemuck::cast_slice(&bytes).to_vec())
                })
                .collect()
        })
    }
}

/// The record of a light (`turn_light.wgsl`'s `light`): per map of `terms` (its part, its
/// table) its turn and weight; per sun taken its table's entry, its direction and, where
/// it has a map of `hull` (at `starts` in the maps' scratch), the map.
fn light_record(
    (terms, parts, tables): (&[YawTerm], &[Part], &[HeldAt]),
    (taken, depths, starts): (&[TakenSun], &[Option<SunDepth>], &[Option<usize>]),
    ground: f32,
    hull: Option<&VoxelHull>,
) -> Vec<[f32; 4]> {
    let mut record: Vec<[f32; 4]> = vec![[terms.len() as f32, taken.len() as f32, ground, 0.0]];
    for ((t, part), (at, _, _)) in terms.iter().zip(parts).zip(tables) {
        let less = match (part, at.less) {
            (Part::LessSuns, Some(l)) => l as f32,
            _ => -1.0,
        };
        record.push([at.whole as f32, less, at.coarse as f32, t.weight]);
        let base = ((3.0 * PI + t.yaw as f64) / TAU).rem_euclid(1.0);
        record.push([base as f32, t.yaw, 0.0, 0.0]);
    }
    for (((term, j, sun), depth), start) in taken.iter().zip(depths).zip(starts) {
        let at = tables[*term].0.suns[*j];
        record.push([at as f32, 0.0, terms[*term].weight, 0.0]);
        let subject = sun.direction();
        match (depth, start, hull) {
            (Some(m), Some(start), Some(h)) => {
                record.push(subject.extend(shadow_offset_m(h)).to_array());
                record.push(m.axes[0].extend(m.corner.x).to_array());
                record.push(m.axes[1].extend(m.corner.y).to_array());
                let [w, h] = m.size;
                record.push([m.texel, w as f32, h as f32, *start as f32]);
            }
            _ => {
                record.push(subject.extend(0.0).to_array());
                record.extend([[0.0; 4]; 3]);
            }
        }
    }
    record
}
