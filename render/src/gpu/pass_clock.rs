//! Where a frame's device time goes, pass by pass: once switched on
//! ([`Gpu::clock_passes`]), every pass the renderer records (relights, frame passes, morphs
//! in time, shadows, the composite) writes GPU timestamps at its beginning and end into
//! one query set, and [`Gpu::pass_times`] resolves what the passes recorded since the last
//! call wrote, summed by the pass's name. Adapters without `TIMESTAMP_QUERY` time nothing
//! (the list is empty). Each pass also counts the dispatches (or draws) it records, which
//! is what grows with walkers where the passes do not. This is what `frf bench frame`
//! reports beside its wall times.

use std::sync::Mutex;

use serde::Serialize;

use super::Gpu;
use super::bind::readback_buffer;
use super::timing::Timestamps;
use crate::error::Result;

/// Passes timed between two reads, later ones untimed (and counted as such, so a report
/// can say its times under-count): half of wgpu's most queries in a set (4096). A frame of 100 walkers between poses under a turning light records about
/// 600 (a sun's map, a relight and a shadow for each of its 200 poses, and the frame's).
const CAPACITY: u32 = 2048;

/// The device time of the passes of one name.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct PassTime {
    /// The pass: `relight`, `frame`, `time morph`, `shadow`, `sun depth`, `composite`.
    pub pass: String,
    /// How many passes of that name ran.
    pub passes: usize,
    /// How many dispatches (or draws) they recorded.
    pub dispatches: usize,
    /// Passes of that name past the clock's capacity, not timed (`ms` under-counts them).
    pub untimed: usize,
    /// Their summed GPU time, milliseconds (timestamps at each pass's beginning and end).
    pub ms: f64,
}

/// The query set and the names of the passes that took its queries.
pub(super) struct PassClock {
    set: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// Pass `i` (named here) took queries `2i` and `2i + 1`.
    names: Mutex<Vec<&'static str>>,
    /// Dispatches recorded since the last read, by pass name.
    dispatches: Mutex<Vec<(&'static str, usize)>>,
    /// Passes recorded past the capacity since the last read, by name: not timed.
    untimed: Mutex<Vec<(&'static str, usize)>>,
}

impl PassClock {
    fn new(device: &wgpu::Device) -> Self {
        let count = 2 * CAPACITY;
        let bytes = u64::from(count) * 8;
        Self {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass clock"),
                ty: wgpu::QueryType::Timestamp,
                count,
            }),
            resolved: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass clock resolved"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: readback_buffer(device, "pass clock readback", bytes),
            names: Mutex::new(Vec::new()),
            dispatches: Mutex::new(Vec::new()),
            untimed: Mutex::new(Vec::new()),
        }
    }
}

/// Adds `n` to `name`'s count in `counts`.
fn count(counts: &Mutex<Vec<(&'static str, usize)>>, name: &'static str, n: usize) {
    let mut counts = counts.lock().unwrap_or_else(|e| e.into_inner());
    match counts.iter_mut().find(|(k, _)| *k == name) {
        Some((_, c)) => *c += n,
        None => counts.push((name, n)),
    }
}

impl Gpu {
    /// Times every pass recorded from now on ([`Gpu::pass_times`]); nothing on an
    /// adapter without timestamp queries. Returns whether passes are timed.
    pub fn clock_passes(&self) -> bool {
        if self.timestamps {
            let _ = self.pass_clock.get_or_init(|| PassClock::new(&self.device));
        }
        self.pass_clock.get().is_some()
    }

    /// The timestamps a pass named `name` writes: `given` when the caller times it itself,
    /// else the pass clock's next pair when it is on and not full.
    pub(super) fn pass_timestamps<'a>(
        &'a self,
        name: &'static str,
        given: Timestamps<'a>,
    ) -> Timestamps<'a> {
        if given.is_some() {
            return given;
        }
        let clock = self.pass_clock.get()?;
        let mut names = clock.names.lock().unwrap_or_else(|e| e.into_inner());
        let i = names.len() as u32;
        if i >= CAPACITY {
            count(&clock.untimed, name, 1);
            return None;
        }
        names.push(name);
        Some((&clock.set, 2 * i))
    }

    /// Counts `n` dispatches (or draws) recorded in a pass named `name`, when passes are
    /// timed.
    pub(super) fn dispatched(&self, name: &'static str, n: usize) {
        let Some(clock) = self.pass_clock.get() else {
            return;
        };
        count(&clock.dispatches, name, n);
    }

    /// The device time of every pass timed since the last call (their work submitted),
    /// summed by name in the order first recorded; waits for the device. Empty when
    /// passes are not timed.
    pub fn pass_times(&self) -> Result<Vec<PassTime>> {
        let Some(clock) = self.pass_clock.get() else {
            return Ok(Vec::new());
        };
        let names = std::mem::take(&mut *clock.names.lock().unwrap_or_else(|e| e.into_inner()));
        let take = |m: &Mutex<Vec<(&'static str, usize)>>| {
            std::mem::take(&mut *m.lock().unwrap_or_else(|e| e.into_inner()))
        };
        let (dispatches, untimed) = (take(&clock.dispatches), take(&clock.untimed));
        let of = |counts: &[(&'static str, usize)], name: &str| {
            (counts.iter())
                .find(|(k, _)| *k == name)
                .map_or(0, |(_, n)| *n)
        };
        let dispatched = |name: &str| of(&dispatches, name);
        if names.is_empty() {
            return Ok(Vec::new());
        }
        let count = 2 * names.len() as u32;
        let bytes = u64::from(count) * 8;
        let ticks = self.scoped("reading the pass clock", || {
            let mut e = self
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("pass clock"),
                });
            e.resolve_query_set(&clock.set, 0..count, &clock.resolved, 0);
            e.copy_buffer_to_buffer(&clock.resolved, 0, &clock.readback, 0, bytes);
            self.submit([e.finish()]);
            self.read_buffer(&clock.readback)
        })?;
        let ticks: &[u64] = bytemuck::cast_slice(&ticks[..bytes as usize]);
        let period_ms = f64::from(self.queue.get_timestamp_period()) / 1e6;
        let mut times: Vec<PassTime> = Vec::new();
        for (i, name) in names.iter().enumerate() {
            let ms = ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64 * period_ms;
            match times.iter_mut().find(|t| t.pass == *name) {
                Some(t) => {
                    t.passes += 1;
                    t.ms += ms;
                }
                None => times.push(PassTime {
                    pass: (*name).to_string(),
                    passes: 1,
                    dispatches: dispatched(name),
                    untimed: of(&untimed, name),
                    ms,
                }),
            }
        }
        // Passes of a name only past the capacity: there, with no time.
        for &(name, n) in &untimed {
            if !times.iter().any(|t| t.pass == name) {
                times.push(PassTime {
                    pass: name.to_string(),
                    passes: 0,
                    dispatches: dispatched(name),
                    untimed: n,
                    ms: 0.0,
                });
            }
        }
        Ok(times)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::timing::compute_pass_writes;

    /// Passes past the clock's capacity are counted as untimed, by name (they were
    /// dropped without a word: a crowd of 682 walkers under a turning light under-counted).
    #[test]
    fn passes_past_the_capacity_are_counted_untimed() {
        let Some(gpu) = crate::gpu::Gpu::for_tests() else {
            return;
        };
        if !gpu.clock_passes() {
            eprintln!("skipped: the adapter has no timestamp queries");
            return;
        }
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        for _ in 0..CAPACITY + 3 {
            let _pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("test"),
                timestamp_writes: compute_pass_writes(gpu.pass_timestamps("test", None)),
            });
        }
        gpu.submit([encoder.finish()]);
        let times = gpu.pass_times().unwrap();
        let t = times.iter().find(|t| t.pass == "test").unwrap();
        assert_eq!((t.passes, t.untimed), (CAPACITY as usize, 3));
        // Read once: the next read starts afresh.
        assert!(gpu.pass_times().unwrap().is_empty());
    }
}
