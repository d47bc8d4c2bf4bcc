//! Adapter and device selection, GPU timing and readback.

mod context;
mod counters;
mod timing;

pub use context::{list_adapters, AdapterSummary, DeviceLimits, GpuContext};
pub use counters::COUNTER_BYTES;
pub(crate) use counters::{CounterValues, FrameCounters, FrameReadback, FrameTag};
pub(crate) use timing::TimedPass;
pub use timing::{PassTimer, PassTiming};

use crate::error::{Error, Result};

/// Does `auto` assign lights on the CPU on this adapter: a CPU-emulated one (lavapipe,
/// SwiftShader, where `cpu` was measured fastest), never on a page (its readback would wait)?
/// The renderer's and a caller's `LightCuller` alike.
pub(crate) fn auto_assigns_on_cpu(info: &wgpu::AdapterInfo) -> bool {
    info.device_type == wgpu::DeviceType::Cpu && cfg!(not(target_arch = "wasm32"))
}

/// Run `f` inside a validation + out-of-memory error scope and turn a captured error into
/// [`Error::Gpu`], so bad input becomes an error message instead of wgpu's default panic.
pub(crate) fn scoped<T>(device: &wgpu::Device, stage: &str, f: impl FnOnce() -> T) -> Result<T> {
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let value = f();
    // A page's error scopes answer later, from the browser's event loop: what they catch is
    // a late error ([`take_late_errors`]), which the page reports a frame later.
    #[cfg(target_arch = "wasm32")]
    {
        let stage = stage.to_string();
        // Popped now, innermost first (wgpu requires it); answered later.
        let (v, o) = (validation.pop(), oom.pop());
        wasm_bindgen_futures::spawn_local(async move {
            let (v, o) = (v.await, o.await);
            match (o, v) {
                (Some(_), _) => report_late(&stage, "out of memory".into()),
                (None, Some(e)) => report_late(&stage, e.to_string()),
                (None, None) => {}
            }
        });
        Ok(value)
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        let v = pollster::block_on(validation.pop());
        let o = pollster::block_on(oom.pop());
        // An allocation that fails can also fail validation after it; the cause is memory.
        match (o, v) {
            (Some(_), _) => Err(Error::Gpu {
                stage: stage.to_string(),
                message: "out of memory".into(),
            }),
            (None, Some(e)) => Err(Error::Gpu {
                stage: stage.to_string(),
                message: e.to_string(),
            }),
            (None, None) => Ok(value),
        }
    }
}

/// GPU errors that no error scope returned to its call: on native, only a bug (printed at
/// once); on the web, every validation error, since a page's scopes answer after the call.
static LATE_ERRORS: std::sync::Mutex<Vec<Error>> = std::sync::Mutex::new(Vec::new());

pub(crate) fn report_late(stage: &str, message: String) {
    #[cfg(not(target_arch = "wasm32"))]
    eprintln!("lightgrid: uncaptured GPU error during {stage}: {message}");
    if let Ok(mut errors) = LATE_ERRORS.lock() {
        errors.push(Error::Gpu {
            stage: stage.to_string(),
            message,
        });
    }
}

/// The GPU errors reported since the last call, oldest first (see `scoped`).
pub fn take_late_errors() -> Vec<Error> {
    LATE_ERRORS
        .lock()
        .map(|mut e| std::mem::take(&mut *e))
        .unwrap_or_default()
}

/// A page cannot wait for the GPU: what needs a blocking readback is native-only there.
#[cfg(target_arch = "wasm32")]
fn native_only(stage: &str) -> Error {
    Error::Gpu {
        stage: stage.to_string(),
        message: "a web page cannot wait for the GPU; this needs lightgrid's native build".into(),
    }
}

/// Block until all submitted work is done.
pub(crate) fn wait_idle(device: &wgpu::Device) -> Result<()> {
    #[cfg(target_arch = "wasm32")]
    if cfg!(target_arch = "wasm32") {
        let _ = device;
        return Err(native_only("waiting for the GPU"));
    }
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| Error::Gpu {
            stage: "device poll".into(),
            message: e.to_string(),
        })
}

/// Map a MAP_READ buffer, copy its bytes out and unmap it.
pub(crate) fn read_buffer(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
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

/// A compute-visible buffer binding of the given type (layout boilerplate of the compute
/// passes).
pub fn buffer_entry(binding: u32, ty: wgpu::BufferBindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// `buffer_entry` shorthands.
pub const UNIFORM: wgpu::BufferBindingType = wgpu::BufferBindingType::Uniform;
pub(crate) const STORAGE_READ: wgpu::BufferBindingType =
    wgpu::BufferBindingType::Storage { read_only: true };
pub(crate) const STORAGE_RW: wgpu::BufferBindingType =
    wgpu::BufferBindingType::Storage { read_only: false };

/// A compute layout whose bindings 0.. are buffers of the given types.
pub(crate) fn buffer_layout(
    device: &wgpu::Device,
    label: &str,
    types: &[wgpu::BufferBindingType],
) -> wgpu::BindGroupLayout {
    let entries: Vec<_> = types
        .iter()
        .enumerate()
        .map(|(i, &ty)| buffer_entry(i as u32, ty))
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

/// A bind group binding `resources[i]` at binding i.
pub fn bind_resources(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource],
) -> wgpu::BindGroup {
    let entries: Vec<_> = resources
        .iter()
        .enumerate()
        .map(|(i, r)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: r.clone(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// A 16-byte INDIRECT buffer that dispatch arguments written by a kernel (into the frame
/// counters, or the cell lists' header) are copied to: a buffer bound for storage cannot
/// also feed an indirect dispatch in the same pass.
pub(crate) fn indirect_args_buffer(device: &wgpu::Device, label: &str) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: 16,
        usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// A storage buffer (also copy source and destination) of at least `size` bytes.
pub(crate) fn storage_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16).next_multiple_of(4),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

/// Make `buffer` hold at least `size` bytes, replacing it (contents lost) with one of the
/// next power-of-two size when it is smaller. Returns true when it was replaced.
pub(crate) fn grow_storage(
    device: &wgpu::Device,
    buffer: &mut wgpu::Buffer,
    label: &str,
    size: u64,
) -> bool {
    if size <= buffer.size() {
        return false;
    }
    *buffer = storage_buffer(device, label, size.next_power_of_two());
    true
}

/// Copy the first `bytes` of `buffer` to the CPU, after everything submitted so far.
pub fn download(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    bytes: u64,
) -> Result<Vec<u8>> {
    if bytes == 0 {
        return Ok(Vec::new());
    }
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("download"),
        size: bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, bytes);
    scoped(device, "downloading a buffer", || {
        queue.submit([encoder.finish()])
    })?;
    read_buffer(device, &staging)
}

/// Workgroup counts for `groups` one-dimensional workgroups, folded into two dimensions when
/// above the per-dimension limit; shaders rebuild the flat index as `wg.y * nwg.x + wg.x` and
/// return early past the end.
pub fn groups_1d(groups: u32) -> (u32, u32) {
    const MAX: u32 = 65535;
    if groups <= MAX {
        (groups.max(1), 1)
    } else {
        (MAX, groups.div_ceil(MAX))
    }
}

/// A uniform buffer of 16-byte parameter records, one per pass of a multi-pass stage, each at
/// the minimum uniform offset alignment so a pass binds its own record (every record is
/// written before the command buffer runs, so the passes cannot share one).
pub(crate) struct UniformSlots {
    buffer: wgpu::Buffer,
    slots: u64,
    /// Bytes of one record (the binding's size).
    record: u64,
}

impl UniformSlots {
    const STRIDE: u64 = 256;

    /// Slots for records of type `T` (a `gpu_types` struct).
    pub fn new<T: bytemuck::Pod>(device: &wgpu::Device, label: &str, slots: u64) -> Self {
        let record = std::mem::size_of::<T>() as u64;
        assert!(record <= Self::STRIDE, "a record fills at most one slot");
        UniformSlots {
            record,
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: Self::STRIDE * slots,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            slots,
        }
    }

    /// Write `records[i]` to slot i (at most `slots` records of at most 256 bytes).
    pub fn write<T: bytemuck::Pod>(&self, queue: &wgpu::Queue, records: &[T]) {
        let size = std::mem::size_of::<T>();
        assert_eq!(
            size as u64, self.record,
            "records of the type the slots were made for"
        );
        assert!(
            records.len() as u64 <= self.slots,
            "more records than slots"
        );
        let mut bytes = vec![0u8; (Self::STRIDE as usize) * records.len()];
        for (i, r) in records.iter().enumerate() {
            let at = i * Self::STRIDE as usize;
            bytes[at..at + size].copy_from_slice(bytemuck::bytes_of(r));
        }
        queue.write_buffer(&self.buffer, 0, &bytes);
    }

    /// The binding of slot `i`.
    pub fn binding(&self, i: usize) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &self.buffer,
            offset: Self::STRIDE * i as u64,
            size: std::num::NonZeroU64::new(self.record),
        })
    }
}
