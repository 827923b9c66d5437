//! Staging buffers an RGBA32F target of one size is read back through, made once with
//! the frame's other targets and reused every frame (mapping them is what a readback
//! waits on; allocating them per frame is not).

use frf_core::image::{Image, Rgba};

use super::Gpu;
use super::bind::{copy_to_buffer, padded_row, readback_buffer, rgba_pixels};
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
