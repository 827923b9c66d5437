//! GPU time per frame: timestamps written at the beginning of the frame's first pass (the
//! first walker's frame pass) and at the end of its last (the present pass), resolved and
//! read back without waiting: the buffer is mapped when the GPU is done with it, and the
//! figure shown is the latest one read. 32 bytes a frame; no image is read back.
//!
//! The timestamps are the passes' own, not those of empty passes around them: on Mesa's
//! lavapipe, empty passes' timestamps bracket almost none of the work (measured: 45 ms
//! bracketed of a 1.3 s frame), the passes' own bracket all of it.

use std::sync::{Arc, Mutex};

/// Timing of frames on the GPU, when the device has timestamp queries.
pub struct GpuTimer {
    queries: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// Nanoseconds per tick.
    period: f64,
    /// The latest time read, milliseconds, and whether the readback buffer is in use.
    state: Arc<Mutex<(Option<f64>, bool)>>,
    /// Whether this frame's timestamps are copied for reading.
    copied: bool,
}

impl GpuTimer {
    /// A timer on `device`; `None` when it has no timestamp queries.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Option<Self> {
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            return None;
        }
        let queries = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("frame timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: 4,
        });
        let buffer = |label, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 32,
                usage,
                mapped_at_creation: false,
            })
        };
        Some(Self {
            queries,
            resolved: buffer(
                "frame timestamps",
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            ),
            readback: buffer(
                "frame timestamps readback",
                wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            ),
            period: f64::from(queue.get_timestamp_period()),
            state: Arc::new(Mutex::new((None, false))),
            copied: false,
        })
    }

    /// The timestamps of the frame's first pass (its beginning is the frame's).
    pub fn begin_pass(&self) -> (&wgpu::QuerySet, u32) {
        (&self.queries, 0)
    }

    /// The timestamps of the frame's last pass (its end is the frame's).
    pub fn end_pass(&self) -> (&wgpu::QuerySet, u32) {
        (&self.queries, 2)
    }

    /// After the frame's passes: copies their timestamps for reading, unless the last
    /// ones are still being read.
    pub fn end(&mut self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.queries, 0..4, &self.resolved, 0);
        let busy = self.state.lock().map(|s| s.1).unwrap_or(true);
        self.copied = !busy;
        if self.copied {
            encoder.copy_buffer_to_buffer(&self.resolved, 0, &self.readback, 0, 32);
        }
    }

    /// After the frame's submission: asks for its timestamps (read when the GPU is done).
    pub fn submitted(&mut self) {
        if !std::mem::take(&mut self.copied) {
            return;
        }
        if let Ok(mut s) = self.state.lock() {
            s.1 = true;
        }
        let (state, buffer, period) = (self.state.clone(), self.readback.clone(), self.period);
        self.readback
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |result| {
                let ms = result.ok().and_then(|()| {
                    let bytes = buffer.slice(..).get_mapped_range().ok()?.to_vec();
                    let [start, _, _, end] = ticks(&bytes)?;
                    Some(end.saturating_sub(start) as f64 * period / 1e6)
                });
                buffer.unmap();
                if let Ok(mut s) = state.lock() {
                    *s = (ms.or(s.0), false);
                }
            });
    }

    /// The latest frame's GPU time read, milliseconds.
    pub fn latest_ms(&self) -> Option<f64> {
        self.state.lock().ok().and_then(|s| s.0)
    }
}

/// The four timestamps of `bytes` (native-endian `u64`, as the GPU writes them).
fn ticks(bytes: &[u8]) -> Option<[u64; 4]> {
    let word = |k: usize| {
        Some(u64::from_ne_bytes(
            bytes.get(8 * k..8 * k + 8)?.try_into().ok()?,
        ))
    };
    Some([word(0)?, word(1)?, word(2)?, word(3)?])
}
