//! Staging buffers an RGBA32F target of one size is read back through, and the ring of
//! them a sequence of frames is read back through: each frame submitted with its copies
//! into a staging set of its own ([`Gpu::submit_drawn`]) and read when its submission is
//! done ([`Gpu::finish_drawn`]), so that frame N+1 is drawn while N is mapped. Sets are
//! kept and reused (mapping them is what a readback waits on; allocating them per frame
//! is not).

use std::sync::mpsc::{Receiver, channel};

use frf_core::image::{Image, Rgba};

use super::bind::{copy_to_buffer, padded_row, readback_buffer, rgba_pixels};
use super::{Gpu, wgpu_err};
use crate::error::Result;

/// A staging buffer sized for one RGBA32F image.
pub(super) struct Readback {
    buffer: wgpu::Buffer,
    row: u32,
    size: (u32, u32),
}

impl Readback {
    /// A staging buffer for RGBA32F images of `size`.
    pub(super) fn new(device: &wgpu::Device, label: &str, size: (u32, u32)) -> Self {
        let row = padded_row(size.0 * 16);
        Self {
            buffer: readback_buffer(device, label, (row * size.1) as u64),
            row,
            size,
        }
    }

    /// Records the copy of (layer 0 of) `texture` into it.
    pub(super) fn copy(&self, encoder: &mut wgpu::CommandEncoder, texture: &wgpu::Texture) {
        copy_to_buffer(
            encoder,
            texture,
            &self.buffer,
            self.row,
            (self.size.0, self.size.1, 1),
        );
    }

    /// The image in it, mapped; it is unmapped.
    fn mapped_image(&self) -> Result<Image<Rgba>> {
        let bytes = mapped_bytes(&self.buffer)?;
        Ok(Image::from_vec(
            self.size.0 as usize,
            self.size.1 as usize,
            rgba_pixels(&bytes, self.size, self.row),
        )?)
    }
}

impl Gpu {
    /// The image last copied into `readback` (after the copy's submission).
    pub(super) fn read_rgba(&self, readback: &Readback) -> Result<Image<Rgba>> {
        let bytes = self.read_buffer(&readback.buffer)?;
        Ok(Image::from_vec(
            readback.size.0 as usize,
            readback.size.1 as usize,
            rgba_pixels(&bytes, readback.size, readback.row),
        )?)
    }
}

/// Frames' staging sets kept for reuse: one frame read back while the next is drawn holds
/// two; a third is spare.
const STAGING_KEPT: usize = 3;

/// Where one frame is read back to: a buffer per target (composite, relative irradiance,
/// backdrop, subjects alone, in the order of the composite's targets) and the pixel-class
/// counters. A frame in flight owns its set, so the next frame is drawn into the same
/// targets while this one is still being mapped.
pub(super) struct FrameStaging {
    size: (u32, u32),
    images: [Readback; 4],
    stats: wgpu::Buffer,
}

impl FrameStaging {
    fn new(device: &wgpu::Device, size: (u32, u32)) -> Self {
        Self {
            size,
            images: [
                "composite",
                "shadow layer",
                "backdrop layer",
                "subject layer",
            ]
            .map(|label| Readback::new(device, label, size)),
            stats: readback_buffer(device, "stats readback", 16),
        }
    }

    /// Records the copies of `targets` (those of `read`, indices into both) into it.
    pub(super) fn copy(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &[wgpu::Texture; 4],
        read: &[usize],
    ) {
        for &k in read {
            self.images[k].copy(encoder, &targets[k]);
        }
    }

    /// The buffer the counters are copied into.
    pub(super) fn stats(&self) -> &wgpu::Buffer {
        &self.stats
    }
}

/// A frame submitted with its copies into a staging set of its own, whose buffers are
/// being mapped; [`Gpu::read_pending`] waits for its submission alone (not for frames
/// submitted after it) and reads it.
pub struct PendingFrame {
    staging: FrameStaging,
    /// The targets copied (indices into the staging set's images), in the order read.
    read: &'static [usize],
    /// Pixels outside the walkers' bounds (missed, not counted on the GPU).
    outside: usize,
    submission: wgpu::SubmissionIndex,
    /// One message per buffer mapped.
    mapped: Receiver<std::result::Result<(), wgpu::BufferAsyncError>>,
}

impl PendingFrame {
    /// Asks for `staging`'s buffers of `read` and its counters mapped, once
    /// `submission` (which copied into them) is done.
    pub(super) fn mapping(
        staging: FrameStaging,
        read: &'static [usize],
        outside: usize,
        submission: wgpu::SubmissionIndex,
    ) -> Self {
        let (tx, mapped) = channel();
        let buffers = read
            .iter()
            .map(|&k| &staging.images[k].buffer)
            .chain([&staging.stats]);
        for buffer in buffers {
            let tx = tx.clone();
            buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
                let _ = tx.send(r);
            });
        }
        Self {
            staging,
            read,
            outside,
            submission,
            mapped,
        }
    }
}

impl Gpu {
    /// Waits for `frame`'s submission and returns what it read back: the images in the
    /// order copied, the counters' bytes, and the pixels outside the walkers' bounds. Its
    /// staging set is kept for a later frame.
    pub(super) fn read_pending(
        &self,
        frame: PendingFrame,
    ) -> Result<(Vec<Image<Rgba>>, Vec<u8>, usize)> {
        self.waiting(|| {
            self.device.poll(wgpu::PollType::Wait {
                submission_index: Some(frame.submission.clone()),
                timeout: None,
            })
        })
        .map_err(wgpu_err("waiting on a frame"))?;
        for _ in 0..=frame.read.len() {
            frame
                .mapped
                .recv()
                .map_err(wgpu_err("mapping a frame's staging"))?
                .map_err(wgpu_err("mapping a frame's staging"))?;
        }
        let s = &frame.staging;
        let images = frame
            .read
            .iter()
            .map(|&k| s.images[k].mapped_image())
            .collect::<Result<Vec<_>>>()?;
        let counts = mapped_bytes(&s.stats)?;
        self.keep_staging(frame.staging);
        Ok((images, counts, frame.outside))
    }

    /// A staging set for frames of `size`: a kept one, or a new one.
    pub(super) fn staging_for(&self, size: (u32, u32)) -> FrameStaging {
        let mut kept = self.staging.lock().unwrap_or_else(|e| e.into_inner());
        match kept.iter().position(|s| s.size == size) {
            Some(k) => kept.swap_remove(k),
            None => FrameStaging::new(&self.device, size),
        }
    }

    /// Keeps `staging` (unmapped) for a later frame; the oldest beyond [`STAGING_KEPT`]
    /// goes.
    fn keep_staging(&self, staging: FrameStaging) {
        let mut kept = self.staging.lock().unwrap_or_else(|e| e.into_inner());
        kept.push(staging);
        if kept.len() > STAGING_KEPT {
            kept.remove(0);
        }
    }
}

/// The bytes of a mapped buffer, which is unmapped.
fn mapped_bytes(buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    let bytes = buffer
        .slice(..)
        .get_mapped_range()
        .map_err(wgpu_err("reading a mapped buffer"))?
        .to_vec();
    buffer.unmap();
    Ok(bytes)
}
