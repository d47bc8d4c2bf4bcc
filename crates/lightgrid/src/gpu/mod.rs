//! Adapter and device selection, GPU timing and readback.

mod context;
mod timing;

pub use context::{list_adapters, AdapterSummary, GpuContext};
pub use timing::{PassTimer, PassTiming};

use crate::error::{Error, Result};

/// Run `f` inside a validation + out-of-memory error scope and turn a captured error into
/// [`Error::Gpu`], so bad input becomes an error message instead of wgpu's default panic.
pub fn scoped<T>(device: &wgpu::Device, stage: &str, f: impl FnOnce() -> T) -> Result<T> {
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let value = f();
    let v = pollster::block_on(validation.pop());
    let o = pollster::block_on(oom.pop());
    match v.or(o) {
        Some(e) => Err(Error::Gpu {
            stage: stage.to_string(),
            message: e.to_string(),
        }),
        None => Ok(value),
    }
}

/// Block until all submitted work is done.
pub fn wait_idle(device: &wgpu::Device) -> Result<()> {
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| Error::Gpu {
            stage: "device poll".into(),
            message: e.to_string(),
        })
}

/// Map a MAP_READ buffer, copy its bytes out and unmap it.
pub fn read_buffer(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    wait_idle(device)?;
    let gpu_err = |message: String| Error::Gpu {
        stage: "readback".into(),
        message,
    };
    rx.recv()
        .map_err(|e| gpu_err(e.to_string()))?
        .map_err(|e| gpu_err(e.to_string()))?;
    let bytes = buffer
        .get_mapped_range(..)
        .map_err(|e| gpu_err(e.to_string()))?
        .to_vec();
    buffer.unmap();
    Ok(bytes)
}
