//! The suns' maps of the walkers' hulls made on the GPU (`shaders/sun_depth.wgsl`), twin
//! of [`SunDepth::reach`]: the host sets each map's frame ([`SunDepth::new`], a few
//! products), and one invocation a texel walks the walker's hull and those of the other
//! walkers in the way of its sun ([`frf_reflectance::sun_depth::Occluder`]); the relight
//! pass then reads the map. A light that turns moves the suns, so the maps are made again
//! for every relight.
//!
//! Every map asked for between two submissions is made by **one dispatch**, whatever the
//! number of walkers and occluders: the maps' frames and their occluders go into one list
//! each ([`SunBatch`]), their values into one scratch buffer that the relights recorded
//! with them read at their offsets, and every hull walked into one table of hulls over
//! one array of words ([`HullTable`]), each hull uploaded once while it is kept. The
//! dispatch is submitted ahead of the pending relights ([`Gpu::submit`]); a map is needed
//! only until its relight has run, so the scratch is reused by the next batch.

use std::sync::{Arc, Mutex};

use frf_reflectance::hull::VoxelHull;
use frf_reflectance::sun_depth::SunDepth;
use frf_reflectance::sun_light::MAX_SUNS;
use frf_shaders::types::{GpuHullAt, GpuSunDepthJob, GpuSunMap, GpuSunOccluder};

use super::Gpu;
use super::bind::{bind_group, buffer_with, compute_pipeline, empty_buffer, storage};
use super::timing::compute_pass_writes;

/// Workgroup size of the pass (`@workgroup_size(64)`).
const WORKGROUP: u32 = 64;

/// Hulls the table holds at first (it grows when a batch needs more).
const FIRST_HULLS: usize = 64;

/// Words of the hulls' array at first (4 MiB; it grows when a batch needs more).
const FIRST_WORDS: usize = 1 << 20;

/// Values of the maps' scratch at first (4 MiB; it grows when a batch needs more).
const FIRST_VALUES: usize = 1 << 20;

/// Most maps in one dispatch (rows of workgroups).
const MOST_MAPS: usize = 65_535;

/// The pass's layout and pipeline, and the hulls and maps it holds.
pub struct SunDepthPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
    state: Mutex<(HullTable, SunBatch)>,
}

impl SunDepthPass {
    /// Builds the pass on `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("sun depth"),
            source: wgpu::ShaderSource::Wgsl(frf_shaders::sun_depth_pass().into()),
        });
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sun depth"),
            entries: &[
                storage::<GpuHullAt>(0, true, c),
                storage::<u32>(1, true, c),
                storage::<GpuSunMap>(2, true, c),
                storage::<f32>(3, false, c),
                storage::<GpuSunOccluder>(4, true, c),
            ],
        });
        let pipeline = compute_pipeline(device, "sun depth", &[&layout], &module, "sun_depth");
        let state = Mutex::new((
            HullTable::new(device, FIRST_HULLS, FIRST_WORDS),
            SunBatch::new(device, FIRST_VALUES),
        ));
        Self {
            layout,
            pipeline,
            state,
        }
    }
}

impl SunDepthPass {
    /// The hulls and the maps asked for, locked.
    fn state(&self) -> std::sync::MutexGuard<'_, (HullTable, SunBatch)> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl Gpu {
    /// Starts the suns' maps' buffers again at `values` values of maps and `hulls` hulls
    /// of `words` words in all (for tests: buffers small enough that a few walkers
    /// outgrow them, which the next requests then grow).
    pub fn restart_sun_maps(&self, values: usize, hulls: usize, words: usize) {
        self.flush();
        let mut state = self.sun_depth.state();
        *state = (
            HullTable::new(&self.device, hulls.max(1), words.max(1)),
            SunBatch::new(&self.device, values.max(1)),
        );
    }
}

/// Every hull the maps walk: a table of their grids and one array of their words, each
/// hull uploaded once while kept (keyed by its address, held so that the address stays
/// its own). When a batch needs a hull that does not fit, the table is emptied once the
/// work that reads it is submitted, and grown to hold it.
struct HullTable {
    held: Vec<Arc<VoxelHull>>,
    words_used: usize,
    table: wgpu::Buffer,
    words: wgpu::Buffer,
    capacity: (usize, usize),
}

impl HullTable {
    fn new(device: &wgpu::Device, hulls: usize, words: usize) -> Self {
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        Self {
            held: Vec::new(),
            words_used: 0,
            table: empty_buffer(device, "hull table", hulls * size_of::<GpuHullAt>(), usage),
            words: empty_buffer(device, "hull words", words * 4, usage),
            capacity: (hulls, words),
        }
    }

    /// The entry of `hull`, when held.
    fn entry(&self, hull: &Arc<VoxelHull>) -> Option<u32> {
        let at = self.held.iter().position(|h| Arc::ptr_eq(h, hull))?;
        Some(at as u32)
    }

    /// Adds `hull` (its grid and words written into the buffers), when it fits.
    fn add(&mut self, queue: &wgpu::Queue, hull: &Arc<VoxelHull>) -> Option<u32> {
        let (proxy, words) = crate::proxy::Proxy::shared(Some(hull.clone())).gpu();
        let (hulls, most_words) = self.capacity;
        if self.held.len() >= hulls || self.words_used + words.len() > most_words {
            return None;
        }
        let entry = GpuHullAt {
            proxy,
            at: [self.words_used as u32, 0, 0, 0],
        };
        let k = self.held.len();
        queue.write_buffer(
            &self.table,
            (k * size_of::<GpuHullAt>()) as u64,
            bytemuck::bytes_of(&entry),
        );
        queue.write_buffer(
            &self.words,
            (self.words_used * 4) as u64,
            bytemuck::cast_slice(&words),
        );
        self.words_used += words.len();
        self.held.push(hull.clone());
        Some(k as u32)
    }
}

/// The maps asked for since the last submission: their jobs, their occluders, and the
/// scratch their values go into (one after the other).
struct SunBatch {
    maps: Vec<GpuSunMap>,
    occluders: Vec<GpuSunOccluder>,
    used: usize,
    most_texels: usize,
    reach: wgpu::Buffer,
    capacity: usize,
    /// Whether a request did not fit: the next batch's scratch is twice as large.
    outgrown: bool,
}

impl SunBatch {
    fn new(device: &wgpu::Device, values: usize) -> Self {
        Self {
            maps: Vec::new(),
            occluders: Vec::new(),
            used: 0,
            most_texels: 0,
            reach: empty_buffer(
                device,
                "sun depths",
                values * 4,
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            ),
            capacity: values,
            outgrown: false,
        }
    }
}

/// The job of `map` whose values start at `start`.
fn job(map: &SunDepth, start: usize) -> GpuSunDepthJob {
    GpuSunDepthJob {
        toward: map.toward.extend(map.far).to_array(),
        axis_x: map.axes[0].extend(map.corner.x).to_array(),
        axis_y: map.axes[1].extend(map.corner.y).to_array(),
        size: [map.size[0], map.size[1], start as u32, 1],
        texel: [map.texel, 0.0, 0.0, 0.0],
    }
}

/// Where each sun's map of a relight lies in the scratch ([`Gpu::ask_sun_maps`]).
pub(super) struct SunMapsAt {
    /// Per sun slot (of the first [`MAX_SUNS`]), where its values start; `None` for a
    /// sun without a map.
    pub starts: Vec<Option<usize>>,
    /// The scratch buffer they are in.
    pub reach: wgpu::Buffer,
}

/// Why a request had to wait for the work before it to be submitted.
enum Full {
    /// The batch's scratch or list of maps.
    Batch,
    /// The table of hulls.
    Hulls,
}

impl Gpu {
    /// Asks for the maps of `suns` (those with one, of the first [`MAX_SUNS`]) of the
    /// walker whose hull is `own`: added to the batch that the next submission makes in
    /// one dispatch ahead of the relights recorded after this call. When the batch or
    /// the table of hulls is full, the work pending is submitted first (and the table
    /// grown or the scratch grown as the request needs).
    pub(super) fn ask_sun_maps(
        &self,
        own: &Arc<VoxelHull>,
        suns: &[Option<&SunDepth>],
    ) -> SunMapsAt {
        let suns = &suns[..suns.len().min(MAX_SUNS)];
        loop {
            match self.try_sun_maps(own, suns) {
                Ok(at) => return at,
                Err(_) => self.flush(),
            }
        }
    }

    /// One try of [`Gpu::ask_sun_maps`]: `Err` when the work pending must be submitted
    /// first (then the table or the scratch is ready for the next try).
    fn try_sun_maps(
        &self,
        own: &Arc<VoxelHull>,
        suns: &[Option<&SunDepth>],
    ) -> std::result::Result<SunMapsAt, Full> {
        let mut state = self.sun_depth.state();
        let (hulls, batch) = &mut *state;
        let maps: Vec<(usize, &SunDepth)> = suns
            .iter()
            .enumerate()
            .filter_map(|(s, map)| Some((s, (*map)?)))
            .collect();
        let values: usize = maps.iter().map(|(_, m)| m.texels()).sum();
        let busy = !batch.maps.is_empty();
        if batch.used + values > batch.capacity || batch.maps.len() + maps.len() > MOST_MAPS {
            if busy {
                batch.outgrown = true;
                return Err(Full::Batch);
            }
            let capacity = values.next_power_of_two().max(batch.capacity);
            *batch = SunBatch::new(&self.device, capacity);
        }
        // Every hull the request walks, in the table.
        let wanted: Vec<&Arc<VoxelHull>> = std::iter::once(own)
            .chain(
                maps.iter()
                    .flat_map(|(_, m)| m.occluders.iter().map(|o| &o.hull)),
            )
            .collect();
        let mut entries = Vec::with_capacity(wanted.len());
        for hull in &wanted {
            match hulls.entry(hull).or_else(|| hulls.add(&self.queue, hull)) {
                Some(e) => entries.push(e),
                None if busy => return Err(Full::Hulls),
                None => {
                    // Nothing in flight reads the table: start it again, large enough.
                    let words: usize = wanted.iter().map(|h| h.word_count() + 1).sum();
                    let (n, w) = hulls.capacity;
                    *hulls = HullTable::new(
                        &self.device,
                        (2 * n).max(wanted.len().next_power_of_two()),
                        (2 * w).max(words.next_power_of_two()),
                    );
                    return Err(Full::Hulls);
                }
            }
        }
        let mut starts = vec![None; suns.len()];
        let mut occluder_entries = entries[1..].iter();
        for (s, map) in maps {
            let first = batch.occluders.len();
            for o in &map.occluders {
                let there = o.here_from_there.inverse();
                let r = there.rotation;
                let hull = *occluder_entries.next().expect("an entry per occluder");
                batch.occluders.push(GpuSunOccluder {
                    hull: [hull, 0, 0, 0],
                    there_x: r.x_axis.extend(0.0).to_array(),
                    there_y: r.y_axis.extend(0.0).to_array(),
                    there_z: r.z_axis.extend(0.0).to_array(),
                    there_t: there.translation.extend(0.0).to_array(),
                });
            }
            batch.maps.push(GpuSunMap {
                map: job(map, batch.used),
                hulls: [entries[0], first as u32, map.occluders.len() as u32, 0],
            });
            starts[s] = Some(batch.used);
            batch.used += map.texels();
            batch.most_texels = batch.most_texels.max(map.texels());
        }
        Ok(SunMapsAt {
            starts,
            reach: batch.reach.clone(),
        })
    }

    /// Submits the dispatch that makes every map asked for since the last call (none:
    /// nothing), and empties the batch; [`Gpu::submit`] calls it ahead of the relights
    /// that read the maps.
    pub(super) fn submit_sun_maps(&self) {
        let mut state = self.sun_depth.state();
        let (hulls, batch) = &mut *state;
        if batch.maps.is_empty() {
            return;
        }
        let storage = wgpu::BufferUsages::STORAGE;
        let maps = buffer_with(
            &self.device,
            "sun maps",
            bytemuck::cast_slice(&batch.maps),
            storage,
        );
        // A binding is never empty.
        if batch.occluders.is_empty() {
            batch.occluders.push(bytemuck::Zeroable::zeroed());
        }
        let occluders = buffer_with(
            &self.device,
            "sun occluders",
            bytemuck::cast_slice(&batch.occluders),
            storage,
        );
        let bind = bind_group(
            &self.device,
            "sun depth",
            &self.sun_depth.layout,
            vec![
                hulls.table.as_entire_binding(),
                hulls.words.as_entire_binding(),
                maps.as_entire_binding(),
                batch.reach.as_entire_binding(),
                occluders.as_entire_binding(),
            ],
        );
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("sun depth"),
            });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("sun depth"),
                timestamp_writes: compute_pass_writes(self.pass_timestamps("sun depth", None)),
            });
            pass.set_pipeline(&self.sun_depth.pipeline);
            self.dispatched("sun depth", 1);
            pass.set_bind_group(0, &bind, &[]);
            let groups = (batch.most_texels as u32).div_ceil(WORKGROUP);
            pass.dispatch_workgroups(groups, batch.maps.len() as u32, 1);
        }
        self.submit_counted([encoder.finish()]);
        if batch.outgrown {
            // The next frame's maps fit in one batch (the buffer in flight is kept by
            // the submission that reads it).
            *batch = SunBatch::new(&self.device, 2 * batch.capacity);
        } else {
            batch.maps.clear();
            batch.occluders.clear();
            batch.used = 0;
            batch.most_texels = 0;
        }
    }
}
