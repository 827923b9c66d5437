//! Every pose copy relit between two submissions, relit by one dispatch pair: a crowd under
//! a turning light relights a hundred copies a frame, and a dispatch (with its bind group)
//! each cost the host more than the device's sums. Each copy's batch of views adds its
//! jobs ([`Gathered`], one a view, naming where its codes, coefficients and pre-lit range
//! lie in the shared pages); [`Gpu::submit`] records them after what the pending encoder
//! already holds and after the one dispatch that looks every relight's light up on the
//! device ([`super::turn_light`]): the sums of every job, then their encoding, a pair for
//! every run of jobs on the same pages (one, unless the pages overflow) whose float
//! scratch fits the device's largest storage binding. A copy relit twice before a
//! submission is relit once, for its later light (its coefficients hold it).

use std::collections::HashMap;

use frf_shaders::types::GpuRelightJob;

use super::Gpu;
use super::bind::{bind_group, kept_buffer};
use super::timing::compute_pass_writes;

/// Workgroup size of the relighting pass (`@workgroup_size(64)`).
const WORKGROUP: u32 = 64;

/// One copy's batch of views gathered for the next submission.
pub(super) struct Gathered {
    /// What names the copy's batch: its coefficients' range.
    pub coefficients: (usize, u64),
    /// The pages its jobs read and write: basis codes, coefficients, pre-lit views, the
    /// suns' maps.
    pub pages: [wgpu::Buffer; 4],
    /// Its jobs, their scratch and peak slots still to be filled in.
    pub jobs: Vec<GpuRelightJob>,
}

/// The batches gathered since the last submission, and the buffers the pass keeps.
#[derive(Default)]
pub(super) struct Relights {
    /// In the order gathered; `None` where a later relight of the same copy replaced it.
    gathered: Vec<Option<Gathered>>,
    /// Where each copy's batch is in `gathered`.
    at: HashMap<(usize, u64), usize>,
    jobs: Option<wgpu::Buffer>,
    peaks: Option<wgpu::Buffer>,
    scratch: Option<wgpu::Buffer>,
}

/// One dispatch pair: its pages, where its jobs start in the jobs' buffer (bytes) and
/// how many there are, and the scratch's bytes it uses.
struct Run {
    pages: [wgpu::Buffer; 4],
    at: u64,
    jobs: u32,
    scratch: u64,
    most_texels: u32,
}

/// Splits `gathered` into runs (see the module docs) of at most `most_jobs` jobs and
/// `most_scratch` bytes of scratch each, filling in each job's scratch offset and peak
/// slot; the jobs' bytes, each run's from a multiple of `align` bytes on.
fn runs(
    gathered: Vec<Gathered>,
    (most_jobs, most_scratch, align): (u32, u64, usize),
) -> (Vec<Run>, Vec<u8>) {
    let mut bytes: Vec<u8> = Vec::new();
    let mut runs: Vec<Run> = Vec::new();
    let mut peak = 0u32;
    // The pages in the order first met, each with its batches in the order gathered.
    let mut by_pages: Vec<([wgpu::Buffer; 4], Vec<GpuRelightJob>)> = Vec::new();
    for g in gathered {
        match by_pages.iter_mut().find(|(p, _)| *p == g.pages) {
            Some((_, jobs)) => jobs.extend(g.jobs),
            None => by_pages.push((g.pages, g.jobs)),
        }
    }
    for (pages, jobs) in by_pages {
        let mut open = false;
        for job in jobs {
            let need = u64::from(job.texels) * 16;
            // A run of these pages is open and has room for the job (a first job always
            // starts one, whatever its scratch).
            let fits = open
                && runs
                    .last()
                    .is_some_and(|r: &Run| r.jobs < most_jobs && r.scratch + need <= most_scratch);
            if !fits {
                bytes.resize(bytes.len().next_multiple_of(align), 0);
                runs.push(Run {
                    pages: pages.clone(),
                    at: bytes.len() as u64,
                    jobs: 0,
                    scratch: 0,
                    most_texels: 0,
                });
                open = true;
            }
            let run = runs.last_mut().expect("pushed above");
            let job = GpuRelightJob {
                relit_offset: (run.scratch / 16) as u32,
                peak,
                ..job
            };
            bytes.extend_from_slice(bytemuck::bytes_of(&job));
            run.jobs += 1;
            run.scratch += need;
            run.most_texels = run.most_texels.max(job.texels);
            peak += 1;
        }
    }
    (runs, bytes)
}

impl Gpu {
    /// Adds `batch` to the next submission's relighting pass, in place of the same copy's
    /// batch gathered before.
    pub(super) fn gather(&self, batch: Gathered) {
        let mut relights = self.relights.lock().unwrap_or_else(|e| e.into_inner());
        let i = relights.gathered.len();
        if let Some(before) = relights.at.insert(batch.coefficients, i) {
            relights.gathered[before] = None;
        }
        relights.gathered.push(Some(batch));
    }

    /// Records the relights gathered (one pass: a dispatch pair a run) into `encoder`,
    /// made when there is none; none gathered: `encoder` as it was.
    pub(super) fn record_relights(
        &self,
        encoder: Option<wgpu::CommandEncoder>,
    ) -> Option<wgpu::CommandEncoder> {
        let mut relights = self.relights.lock().unwrap_or_else(|e| e.into_inner());
        relights.at.clear();
        let gathered: Vec<Gathered> = relights.gathered.drain(..).flatten().collect();
        if gathered.is_empty() {
            return encoder;
        }
        let limits = self.device.limits();
        let align = (limits.min_storage_buffer_offset_alignment as usize).max(16);
        let most = (
            limits.max_compute_workgroups_per_dimension,
            limits.max_storage_buffer_binding_size,
            align,
        );
        let (runs, bytes) = runs(gathered, most);
        let jobs: u64 = runs.iter().map(|r| u64::from(r.jobs)).sum();
        let scratch = runs.iter().map(|r| r.scratch).max().unwrap_or(16);
        let copy = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let relights = &mut *relights;
        let job_buffer = kept_buffer(
            &self.device,
            &mut relights.jobs,
            ("relight jobs", copy),
            bytes.len() as u64,
            4096,
        );
        self.upload(&job_buffer, 0, &bytes);
        let peaks = kept_buffer(
            &self.device,
            &mut relights.peaks,
            ("relight peaks", copy),
            jobs * 4,
            4096,
        );
        let scratch = kept_buffer(
            &self.device,
            &mut relights.scratch,
            ("relit", wgpu::BufferUsages::STORAGE),
            scratch,
            1 << 20,
        );
        let mut encoder = encoder.unwrap_or_else(|| self.pending_encoder());
        encoder.clear_buffer(&peaks, 0, Some(jobs * 4));
        let pass = &self.relight;
        let binds: Vec<wgpu::BindGroup> = runs
            .iter()
            .map(|run| {
                let [basis, coefficients, prelit, depths] = &run.pages;
                let jobs = wgpu::BufferBinding {
                    buffer: &job_buffer,
                    offset: run.at,
                    size: wgpu::BufferSize::new(
                        u64::from(run.jobs) * size_of::<GpuRelightJob>() as u64,
                    ),
                };
                bind_group(
                    &self.device,
                    "relight",
                    &pass.layout,
                    vec![
                        pass.gamma.as_entire_binding(),
                        basis.as_entire_binding(),
                        coefficients.as_entire_binding(),
                        scratch.as_entire_binding(),
                        peaks.as_entire_binding(),
                        prelit.as_entire_binding(),
                        wgpu::BindingResource::Buffer(jobs),
                        depths.as_entire_binding(),
                    ],
                )
            })
            .collect();
        self.dispatched("relight", 2 * runs.len());
        let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("relight"),
            timestamp_writes: compute_pass_writes(self.pass_timestamps("relight", None)),
        });
        for (run, bind) in runs.iter().zip(&binds) {
            // The sums, then their encoding (wgpu orders the two dispatches' use of the
            // scratch and the peaks, and the next run's of the scratch).
            for pipeline in [&pass.relight, &pass.encode] {
                compute.set_pipeline(pipeline);
                compute.set_bind_group(0, bind, &[]);
                compute.dispatch_workgroups(run.most_texels.div_ceil(WORKGROUP), run.jobs, 1);
            }
        }
        drop(compute);
        Some(encoder)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Jobs on the same pages share runs whatever order they were gathered in, a run
    /// never holds more jobs or scratch than asked, each job's scratch is its own within
    /// its run, peaks are one a job, and each run's jobs start aligned; a copy gathered
    /// twice is relit once.
    #[test]
    fn jobs_are_split_into_runs_that_fit() {
        let Some(gpu) = Gpu::for_tests() else {
            return;
        };
        let buffer = |label: &str| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 16,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        };
        let (a, b, c) = (buffer("a"), buffer("b"), buffer("c"));
        let on = |first: &wgpu::Buffer, texels: &[u32]| Gathered {
            coefficients: (0, 0),
            pages: [first.clone(), c.clone(), c.clone(), c.clone()],
            jobs: texels
                .iter()
                .map(|&t| GpuRelightJob {
                    texels: t,
                    ..bytemuck::Zeroable::zeroed()
                })
                .collect(),
        };
        let gathered = vec![on(&a, &[10, 20]), on(&b, &[5]), on(&a, &[30, 40, 1])];
        // At most 3 jobs and 60 texels' scratch (16 bytes each) a run.
        let (runs, bytes) = runs(gathered, (3, 60 * 16, 256));
        let shape: Vec<(bool, u32, u64)> = runs
            .iter()
            .map(|r| (r.pages[0] == a, r.jobs, r.scratch / 16))
            .collect();
        // a: 10+20+30 = 60 (full), then 40+1; b: 5.
        assert_eq!(shape, [(true, 3, 60), (true, 2, 41), (false, 1, 5)]);
        let jobs: Vec<GpuRelightJob> = runs
            .iter()
            .flat_map(|r| {
                assert_eq!(r.at % 256, 0, "a run's jobs start aligned");
                let n = r.jobs as usize * size_of::<GpuRelightJob>();
                bytemuck::cast_slice::<u8, GpuRelightJob>(&bytes[r.at as usize..][..n]).to_vec()
            })
            .collect();
        let of = |f: fn(&GpuRelightJob) -> u32| jobs.iter().map(f).collect::<Vec<u32>>();
        assert_eq!(of(|j| j.texels), [10, 20, 30, 40, 1, 5]);
        assert_eq!(of(|j| j.relit_offset), [0, 10, 30, 0, 40, 0]);
        assert_eq!(of(|j| j.peak), [0, 1, 2, 3, 4, 5]);
        // A copy gathered twice before a submission is relit once, for its later light;
        // another copy's batch stays.
        let copy = |key: u64, texels: u32| Gathered {
            coefficients: (1, key),
            jobs: vec![GpuRelightJob {
                texels,
                ..bytemuck::Zeroable::zeroed()
            }],
            ..on(&a, &[])
        };
        for (key, texels) in [(7, 1), (8, 2), (7, 3)] {
            gpu.gather(copy(key, texels));
        }
        let kept: Vec<u32> = (gpu.relights.lock().unwrap().gathered.iter())
            .flatten()
            .map(|g| g.jobs[0].texels)
            .collect();
        assert_eq!(kept, [2, 3]);
    }
}
