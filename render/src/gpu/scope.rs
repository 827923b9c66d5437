//! GPU errors returned, not printed: every request to the device runs inside wgpu error
//! scopes (validation and out-of-memory), and what they catch becomes a typed
//! [`RenderError`] naming the operation. Errors raised outside any scope (which the
//! renderer should never cause) are kept too, and reported by the next scoped operation.

use std::sync::{Arc, Mutex};

use crate::error::{RenderError, Result};

/// Errors the device raised outside any scope, kept for the next scoped operation.
#[derive(Clone, Default)]
pub struct Uncaptured(Arc<Mutex<Option<String>>>);

impl Uncaptured {
    /// Installs itself as the device's handler of uncaptured errors.
    pub fn install(&self, device: &wgpu::Device) {
        let slot = self.0.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            let mut slot = slot.lock().unwrap_or_else(|p| p.into_inner());
            slot.get_or_insert_with(|| e.to_string());
        }));
    }

    fn take(&self) -> Option<String> {
        self.0.lock().unwrap_or_else(|p| p.into_inner()).take()
    }
}

/// Runs `f` inside validation and out-of-memory error scopes of `device`; an error they
/// catch (or one raised outside any scope since the last call) is returned in place of
/// `f`'s result, as it is the cause of whatever `f` saw.
pub fn scoped<T>(
    device: &wgpu::Device,
    uncaptured: &Uncaptured,
    operation: &'static str,
    f: impl FnOnce() -> Result<T>,
) -> Result<T> {
    let out_of_memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let result = f();
    // Scopes pop in the reverse order of their pushes.
    let validation = pollster::block_on(validation.pop());
    let out_of_memory = pollster::block_on(out_of_memory.pop());
    if let Some(e) = out_of_memory {
        return Err(RenderError::GpuOutOfMemory {
            operation,
            message: e.to_string(),
        });
    }
    if let Some(e) = validation {
        return Err(RenderError::GpuValidation {
            operation,
            message: e.to_string(),
        });
    }
    if let Some(message) = uncaptured.take() {
        return Err(RenderError::GpuValidation {
            operation: "an earlier request",
            message,
        });
    }
    result
}
