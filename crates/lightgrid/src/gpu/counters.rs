//! The frame counters (`consts::COUNTER_*`, group 0 binding 3) and their read-back without
//! waiting: each frame copies the counters and its pass timestamps into a staging slot, maps it
//! after the submission, and a later frame (or an analysis run, which waits) collects the
//! values. A real-time frame never waits on its own results: index lists are sized from these
//! values a frame or more later, and a frame they show to be wrong (lists that did not fit, a
//! loop cut short) is reported, never passed off as right.

use super::{wait_idle, PassTimer};
use crate::consts::{
    COUNTER_EDGE_PIXELS, COUNTER_GEOMETRY_SAMPLES, COUNTER_INDEX_NEEDED, COUNTER_INDEX_OUT_OF_ROOM,
    COUNTER_INVALID_LIGHTS, COUNTER_OFF_BOUNDS_FRAGMENTS, COUNTER_PAIRS_NEEDED,
    COUNTER_PAIRS_OUT_OF_ROOM, COUNTER_SHADED_SAMPLES, COUNTER_SHADOW_RAYS, COUNTER_SLOTS,
    COUNTER_TRUNCATED_LOOPS, COUNTER_WRITE_OVERFLOW,
};
use crate::error::{Error, Result};
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::Arc;

/// Bytes of the counters.
pub const COUNTER_BYTES: u64 = COUNTER_SLOTS as u64 * 4;

/// The frame counters' values after a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct CounterValues(pub [u32; COUNTER_SLOTS as usize]);

impl CounterValues {
    fn get(&self, slot: u32) -> u32 {
        self.0[slot as usize]
    }
    /// Data-dependent shader loops that stopped before their bound.
    pub fn truncated_loops(&self) -> u32 {
        self.get(COUNTER_TRUNCATED_LOOPS)
    }
    /// Index-list entries the per-cell assignment kernels needed.
    pub fn index_needed(&self) -> u32 {
        self.get(COUNTER_INDEX_NEEDED)
    }
    /// (cell, light) pairs the scatter strategy needed.
    pub fn pairs_needed(&self) -> u32 {
        self.get(COUNTER_PAIRS_NEEDED)
    }
    /// Some list did not fit its buffer: the frame's grid is missing lights.
    pub fn overflowed(&self) -> bool {
        self.get(COUNTER_INDEX_OUT_OF_ROOM) > 0 || self.get(COUNTER_PAIRS_OUT_OF_ROOM) > 0
    }
    /// Edge pixels the MSAA deferred kernels shaded per sample.
    pub fn edge_pixels(&self) -> u32 {
        self.get(COUNTER_EDGE_PIXELS)
    }
    /// Samples the MSAA deferred kernels shaded.
    pub fn shaded_samples(&self) -> u32 {
        self.get(COUNTER_SHADED_SAMPLES)
    }
    /// Samples with geometry the MSAA deferred kernels saw.
    pub fn geometry_samples(&self) -> u32 {
        self.get(COUNTER_GEOMETRY_SAMPLES)
    }
    /// MSAA forward fragments outside their cell's bounds (the frame is wrong when non-zero).
    pub fn fragments_off_bounds(&self) -> u32 {
        self.get(COUNTER_OFF_BOUNDS_FRAGMENTS)
    }
    /// Shadow rays the light function cast.
    pub fn shadow_rays(&self) -> u32 {
        self.get(COUNTER_SHADOW_RAYS)
    }
    /// Lights a `LightCuller` refused (not finite, range not positive).
    pub fn invalid_lights(&self) -> u32 {
        self.get(COUNTER_INVALID_LIGHTS)
    }
    /// Count and write passes disagreed (a bug, never silent).
    pub fn write_overflow(&self) -> u32 {
        self.get(COUNTER_WRITE_OVERFLOW)
    }
}

/// Who a slot's values belong to.
#[derive(Clone, Debug)]
pub(crate) struct FrameTag {
    /// The renderer's frame number (counts every submitted frame).
    pub serial: u64,
    /// The pipeline that rendered it.
    pub pipeline: &'static str,
    /// The passes it recorded, in timestamp order.
    pub pass_labels: Vec<super::TimedPass>,
}

/// A finished frame's counters and raw pass timestamps.
#[derive(Clone, Debug)]
pub(crate) struct FrameReadback {
    pub tag: FrameTag,
    pub values: CounterValues,
    pub ticks: Vec<u64>,
}

const FREE: u8 = 0;
const PENDING: u8 = 1;
const READY: u8 = 2;
const FAILED: u8 = 3;

struct Slot {
    buffer: wgpu::Buffer,
    state: Arc<AtomicU8>,
    tag: Option<FrameTag>,
}

/// The counters buffer and a ring of staging slots (grown when every slot is in flight).
pub(crate) struct FrameCounters {
    buffer: wgpu::Buffer,
    slot_bytes: u64,
    slots: Vec<Slot>,
    /// The slot the frame being recorded copies into (between `encode_copy` and `after_submit`).
    recording: Option<usize>,
}

impl FrameCounters {
    /// Counters plus room for `max_passes` passes' timestamps per frame, and after the
    /// counters `pixels` per-pixel lighting counts (MSAA frames: `count_pixel` in
    /// `scene_bindings.wgsl`; one buffer keeps group 0 within WebGPU's 8 storage buffers per
    /// stage).
    pub fn new(device: &wgpu::Device, max_passes: u32, pixels: u64) -> Self {
        FrameCounters {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("frame counters"),
                size: COUNTER_BYTES + pixels * 4,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            slot_bytes: COUNTER_BYTES + PassTimer::bytes_for(max_passes),
            slots: Vec::new(),
            recording: None,
        }
    }

    /// The counters (group 0, binding 3).
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// Record the clear that starts a frame (the counters and the pixel counts).
    pub fn clear(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.buffer, 0, None);
    }

    /// Record the copy of the counters and the frame's timestamps into a free slot; call
    /// after the frame's last pass, then [`FrameCounters::after_submit`].
    pub fn encode_copy(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        timer: &PassTimer,
        tag: FrameTag,
    ) {
        let free = self
            .slots
            .iter()
            .position(|s| s.state.load(Ordering::Acquire) == FREE && s.tag.is_none());
        let i = free.unwrap_or_else(|| {
            self.slots.push(Slot {
                buffer: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("frame counters readback"),
                    size: self.slot_bytes,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                state: Arc::new(AtomicU8::new(FREE)),
                tag: None,
            });
            self.slots.len() - 1
        });
        let slot = &mut self.slots[i];
        encoder.copy_buffer_to_buffer(&self.buffer, 0, &slot.buffer, 0, COUNTER_BYTES);
        timer.resolve_into(encoder, &slot.buffer, COUNTER_BYTES);
        slot.tag = Some(tag);
        self.recording = Some(i);
    }

    /// Ask for the slot recorded this frame to be mapped once the GPU is done with it.
    pub fn after_submit(&mut self) {
        let Some(i) = self.recording.take() else {
            return;
        };
        let slot = &self.slots[i];
        slot.state.store(PENDING, Ordering::Release);
        let state = slot.state.clone();
        slot.buffer.map_async(wgpu::MapMode::Read, .., move |r| {
            state.store(if r.is_ok() { READY } else { FAILED }, Ordering::Release);
        });
    }

    /// Map the slot recorded this frame once `encoder` is submitted (by its owner, who may
    /// submit it after this returns: `culling::LightCuller`).
    pub fn map_on_submit(&mut self, encoder: &wgpu::CommandEncoder) {
        let Some(i) = self.recording.take() else {
            return;
        };
        let slot = &self.slots[i];
        slot.state.store(PENDING, Ordering::Release);
        let state = slot.state.clone();
        encoder.map_buffer_on_submit(&slot.buffer, wgpu::MapMode::Read, .., move |r| {
            state.store(if r.is_ok() { READY } else { FAILED }, Ordering::Release);
        });
    }

    /// The frame being recorded was abandoned (an error before its submission).
    pub fn abandon(&mut self) {
        if let Some(i) = self.recording.take() {
            self.slots[i].tag = None;
        }
    }

    /// Frames in flight whose values are not collected yet.
    pub fn in_flight(&self) -> usize {
        self.slots.iter().filter(|s| s.tag.is_some()).count()
    }

    /// Collect the slots the GPU has finished, without waiting (oldest first).
    pub fn poll(&mut self, device: &wgpu::Device) -> Result<Vec<FrameReadback>> {
        device.poll(wgpu::PollType::Poll).map_err(|e| Error::Gpu {
            stage: "device poll".into(),
            message: e.to_string(),
        })?;
        self.collect()
    }

    /// Wait for every frame in flight and collect them all (analysis, and the end of a run).
    pub fn wait(&mut self, device: &wgpu::Device) -> Result<Vec<FrameReadback>> {
        if self.in_flight() > 0 {
            wait_idle(device)?;
        }
        self.collect()
    }

    fn collect(&mut self) -> Result<Vec<FrameReadback>> {
        let mut out = Vec::new();
        for slot in &mut self.slots {
            match slot.state.load(Ordering::Acquire) {
                READY => {
                    let bytes = slot
                        .buffer
                        .get_mapped_range(..)
                        .map_err(|e| Error::Gpu {
                            stage: "frame counters readback".into(),
                            message: e.to_string(),
                        })?
                        .to_vec();
                    slot.buffer.unmap();
                    slot.state.store(FREE, Ordering::Release);
                    let tag = slot.tag.take().expect("a mapped slot has a tag");
                    let (counters, rest) = bytes.split_at(COUNTER_BYTES as usize);
                    let ticks = rest
                        .chunks_exact(8)
                        .take(tag.pass_labels.len() * 2)
                        .map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes")))
                        .collect();
                    let mut values = [0u32; COUNTER_SLOTS as usize];
                    values.copy_from_slice(bytemuck::cast_slice(counters));
                    out.push(FrameReadback {
                        tag,
                        values: CounterValues(values),
                        ticks,
                    });
                }
                FAILED => {
                    slot.state.store(FREE, Ordering::Release);
                    slot.tag = None;
                    return Err(Error::Gpu {
                        stage: "frame counters readback".into(),
                        message: "mapping the counters failed".into(),
                    });
                }
                _ => {}
            }
        }
        out.sort_by_key(|r| r.tag.serial);
        Ok(out)
    }
}
