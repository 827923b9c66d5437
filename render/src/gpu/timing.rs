//! Timing passes on the GPU: with timestamp queries written at the beginning and end of
//! each pass where the adapter has them (`Features::TIMESTAMP_QUERY`; the time the GPU
//! spent in the pass, nothing of the host), else fenced wall time (submit one pass, wait
//! for the queue to drain). Warm-up passes run first and are not counted.

use std::time::Instant;

use super::Gpu;
use super::bind::readback_buffer;
use crate::error::RenderError;
use crate::error::Result;

/// What a recorded pass is given: the query set and the index of its first timestamp.
pub type Timestamps<'a> = Option<(&'a wgpu::QuerySet, u32)>;

/// The timestamp writes of a render pass timed into `timestamps` (its beginning at the
/// first query, its end at the next).
pub fn render_pass_writes(
    timestamps: Timestamps<'_>,
) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
    timestamps.map(|(q, i)| wgpu::RenderPassTimestampWrites {
        query_set: q,
        beginning_of_pass_write_index: Some(i),
        end_of_pass_write_index: Some(i + 1),
    })
}

/// The timestamp writes of a compute pass timed into `timestamps`, as
/// [`render_pass_writes`].
pub fn compute_pass_writes(
    timestamps: Timestamps<'_>,
) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
    timestamps.map(|(q, i)| wgpu::ComputePassTimestampWrites {
        query_set: q,
        beginning_of_pass_write_index: Some(i),
        end_of_pass_write_index: Some(i + 1),
    })
}

/// How a pass was timed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clock {
    /// GPU timestamps around the pass.
    Timestamps,
    /// Host wall time of a submit and a wait.
    Fenced,
}

impl Clock {
    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Clock::Timestamps => "gpu-timestamps",
            Clock::Fenced => "fenced-wall",
        }
    }
}

impl Gpu {
    /// How [`Gpu::time_passes`] times on this adapter.
    pub fn clock(&self) -> Clock {
        if self.timestamps {
            Clock::Timestamps
        } else {
            Clock::Fenced
        }
    }

    /// Runs `warmup` then `repeats` passes recorded by `record` and returns the time of
    /// each counted one, milliseconds.
    pub fn time_passes(
        &self,
        warmup: u32,
        repeats: u32,
        record: &mut dyn FnMut(&mut wgpu::CommandEncoder, Timestamps),
    ) -> Result<Vec<f64>> {
        self.scoped("timing passes", || {
            let encoder = |label| {
                self.device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) })
            };
            let mut warm = encoder("warm-up");
            for _ in 0..warmup {
                record(&mut warm, None);
            }
            self.submit([warm.finish()]);
            self.wait()?;
            if !self.timestamps {
                let mut times = Vec::with_capacity(repeats as usize);
                for _ in 0..repeats {
                    let mut e = encoder("timed");
                    record(&mut e, None);
                    let start = Instant::now();
                    self.submit([e.finish()]);
                    self.wait()?;
                    times.push(start.elapsed().as_secs_f64() * 1e3);
                }
                return Ok(times);
            }
            let count = 2 * repeats.max(1);
            let queries = self.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count,
            });
            let bytes = u64::from(count) * 8;
            let resolved = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = readback_buffer(&self.device, "timestamps readback", bytes);
            let mut e = encoder("timed");
            for i in 0..repeats {
                record(&mut e, Some((&queries, 2 * i)));
            }
            e.resolve_query_set(&queries, 0..count, &resolved, 0);
            e.copy_buffer_to_buffer(&resolved, 0, &readback, 0, bytes);
            self.submit([e.finish()]);
            let ticks = self.read_buffer(&readback)?;
            let ticks: &[u64] = bytemuck::cast_slice(&ticks);
            let period = f64::from(self.queue.get_timestamp_period());
            let times = (0..repeats as usize)
                .map(|i| ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64 * period / 1e6)
                .collect::<Vec<_>>();
            if times.iter().all(|&t| t == 0.0) {
                return Err(RenderError::Gpu(
                    "the adapter's timestamps did not advance".into(),
                ));
            }
            Ok(times)
        })
    }
}

/// The median and the least of `times`.
pub fn median_min(times: &[f64]) -> (f64, f64) {
    let mut t = times.to_vec();
    t.sort_by(f64::total_cmp);
    let n = t.len();
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let median = if n % 2 == 1 {
        t[n / 2]
    } else {
        0.5 * (t[n / 2 - 1] + t[n / 2])
    };
    (median, t[0])
}
