//! Small writes gathered between two submissions and sent as one. A relight writes a few
//! hundred bytes into buffers of its pose (its light's record, its shadow's weights);
//! `Queue::write_buffer` makes a staging buffer for each, and under a turning light a
//! crowd makes hundreds a frame, each allocated and freed by the device's allocator.
//! Gathered here instead, they are written into one kept buffer with one
//! `write_buffer` and copied to their places by one encoder, which [`Gpu::submit`] sends
//! ahead of the work that reads them. A destination written twice before a submission
//! ends with the later bytes, as with `write_buffer`.

use super::Gpu;
use super::bind::kept_buffer;

/// Bytes the kept buffer holds at first (it grows to what a submission needs).
const FIRST_BYTES: u64 = 64 << 10;

/// The writes gathered since the last submission and the buffer they go through.
#[derive(Default)]
pub(super) struct Uploads {
    /// Every write's bytes, one after the other (each a multiple of 4 bytes).
    bytes: Vec<u8>,
    /// Per write: its destination, where in it, and where its bytes start and how many.
    copies: Vec<(wgpu::Buffer, u64, u64, u64)>,
    /// The kept buffer the bytes are written into (`COPY_SRC | COPY_DST`).
    buffer: Option<wgpu::Buffer>,
}

impl Gpu {
    /// Writes `bytes` into `dest` at `offset` ahead of the next submission's work, as
    /// `Queue::write_buffer` does (`dest` a `COPY_DST` buffer; sizes and offsets
    /// multiples of 4).
    pub(super) fn upload(&self, dest: &wgpu::Buffer, offset: u64, bytes: &[u8]) {
        debug_assert!(bytes.len().is_multiple_of(4) && offset.is_multiple_of(4));
        if bytes.is_empty() {
            return;
        }
        let mut uploads = self.uploads.lock().unwrap_or_else(|e| e.into_inner());
        let start = uploads.bytes.len() as u64;
        uploads.bytes.extend_from_slice(bytes);
        let len = bytes.len() as u64;
        uploads.copies.push((dest.clone(), offset, start, len));
    }

    /// Sends the writes gathered (one `write_buffer`, one encoder of copies), ahead of
    /// whatever is submitted next.
    pub(super) fn submit_uploads(&self) {
        let mut uploads = self.uploads.lock().unwrap_or_else(|e| e.into_inner());
        if uploads.copies.is_empty() {
            return;
        }
        let needed = uploads.bytes.len() as u64;
        let usage = wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let buffer = kept_buffer(
            &self.device,
            &mut uploads.buffer,
            ("uploads", usage),
            needed,
            FIRST_BYTES,
        );
        self.queue.write_buffer(&buffer, 0, &uploads.bytes);
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("uploads"),
            });
        for (dest, offset, start, len) in uploads.copies.drain(..) {
            encoder.copy_buffer_to_buffer(&buffer, start, &dest, offset, len);
        }
        uploads.bytes.clear();
        drop(uploads);
        self.submit_counted([encoder.finish()]);
    }
}

#[cfg(test)]
mod tests {
    /// Writes gathered land where they were aimed when the next submission goes, the
    /// later of two to the same place wins, the kept buffer grows past its first size,
    /// and what was sent is not sent again.
    #[test]
    fn writes_land_in_order_in_one_submission() {
        let Some(gpu) = crate::gpu::Gpu::for_tests() else {
            return;
        };
        let usage = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC;
        let make = |label: &str, words: usize| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (words * 4) as u64,
                usage,
                mapped_at_creation: false,
            })
        };
        let words = |bytes: Vec<u8>| -> Vec<u32> { bytemuck::cast_slice(&bytes).to_vec() };
        let (a, b) = (make("a", 4), make("b", 1 << 15));
        gpu.upload(&a, 0, bytemuck::cast_slice(&[1u32, 2, 3, 4]));
        gpu.upload(&a, 8, bytemuck::cast_slice(&[7u32]));
        let big: Vec<u32> = (0..1 << 15).collect();
        gpu.upload(&b, 0, bytemuck::cast_slice(&big));
        gpu.upload(&a, 4, bytemuck::cast_slice(&[5u32, 6]));
        assert_eq!(gpu.uploads.lock().unwrap().copies.len(), 4);
        // `read_back` submits: the writes go first.
        assert_eq!(words(gpu.read_back(&a, "a").unwrap()), [1, 5, 6, 4]);
        assert_eq!(words(gpu.read_back(&b, "b").unwrap()), big);
        assert!(gpu.uploads.lock().unwrap().copies.is_empty());
        // Nothing gathered is sent twice: a buffer written directly keeps what it got.
        gpu.queue
            .write_buffer(&a, 0, bytemuck::cast_slice(&[9u32, 9, 9, 9]));
        assert_eq!(words(gpu.read_back(&a, "a").unwrap()), [9, 9, 9, 9]);
    }
}
