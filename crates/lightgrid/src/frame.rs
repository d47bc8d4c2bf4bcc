//! What one frame carries, below `pipelines/`, `passes/` and `culling/` (which all use it):
//! the settings every pipeline shares, what a pipeline needs to create its GPU objects
//! ([`PipelineContext`]), what it reads to record a frame ([`FrameInputs`]), and the frame's
//! command encoder ([`FrameEncoder`]), which counts the queue submissions, blocking readbacks
//! and CPU waits the frame makes ([`FrameIo`]): a real-time frame makes one submission and no
//! blocking readback; only the `cpu` strategy with depth bounds waits part-way (the papers'
//! CPU pipeline reads the tile bounds back).

use crate::culling::{Assign, GridDims, ViewSetup};
use crate::error::Result;
use crate::gpu::{read_buffer, scoped, PassTimer};
use crate::passes::{GBufferFormat, Targets};
use crate::scene::PointLight;
use std::time::Instant;

/// Settings every pipeline of a renderer shares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderSettings {
    /// Screen tile edge in pixels (`--tile`).
    pub tile_size: u32,
    /// G-buffer channel precision (`--gbuffer 16|32`).
    pub gbuffer: GBufferFormat,
    /// View-depth slices of clustered grids (`--slices`).
    pub slices: u32,
    /// Who builds the grid (`--assign`).
    pub assign: Assign,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            tile_size: crate::consts::DEFAULT_TILE_SIZE,
            gbuffer: GBufferFormat::F16,
            slices: crate::consts::DEFAULT_SLICES,
            assign: Assign::default(),
        }
    }
}

/// What a pipeline needs to create its GPU objects.
/// (Built by the renderer for each registry row it is asked to render.)
pub struct PipelineContext<'a> {
    pub device: &'a wgpu::Device,
    /// Group 0 layout (`shading/scene_bindings.wgsl`), shared by all pipelines.
    pub scene_layout: &'a wgpu::BindGroupLayout,
    pub dims: GridDims,
    pub settings: RenderSettings,
    /// The adapter can blend into the R32Float count target.
    pub count_blend: bool,
    /// A CPU-emulated adapter (lavapipe): `--assign auto` keeps assignment on the CPU.
    pub software_adapter: bool,
}

/// What a pipeline reads to render one frame.
pub struct FrameInputs<'a> {
    pub device: &'a wgpu::Device,
    pub queue: &'a wgpu::Queue,
    pub scene_bind_group: &'a wgpu::BindGroup,
    /// The frame counters bound in group 0 (`consts::COUNTER_*`); indirect dispatch arguments
    /// that kernels write there are copied out of it.
    pub counters: &'a wgpu::Buffer,
    pub vertices: &'a wgpu::Buffer,
    pub indices: &'a wgpu::Buffer,
    pub index_count: u32,
    pub targets: &'a Targets,
    /// Camera and frame size, for CPU light assignment.
    pub setup: ViewSetup,
    /// The frame's lights (world space), as uploaded to group 0.
    pub lights: &'a [PointLight],
    /// The count target is blended into (see `PipelineContext::count_blend`).
    pub count_blend: bool,
}

/// What a frame cost the CPU side: queue submissions, bytes it waited to read back, and the
/// time it spent waiting for the GPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FrameIo {
    pub submits: u32,
    /// Bytes read back with a wait for the GPU (not the asynchronous frame counters).
    pub readback_bytes: u64,
    /// Wall time the CPU waited for the GPU inside the frame.
    pub cpu_wait_ms: f64,
}

/// The frame's command encoder. A pipeline records into it; only the `cpu` strategy submits
/// part-way (to read the cell bounds back). Every submission and blocking read goes through
/// here, so [`FrameIo`] is the whole story of the frame's CPU-GPU traffic.
pub struct FrameEncoder<'a> {
    device: &'a wgpu::Device,
    queue: &'a wgpu::Queue,
    encoder: wgpu::CommandEncoder,
    pub timer: &'a mut PassTimer,
    io: FrameIo,
}

impl<'a> FrameEncoder<'a> {
    pub(crate) fn new(
        device: &'a wgpu::Device,
        queue: &'a wgpu::Queue,
        timer: &'a mut PassTimer,
    ) -> Self {
        let encoder = device.create_command_encoder(&Default::default());
        FrameEncoder {
            device,
            queue,
            encoder,
            timer,
            io: FrameIo::default(),
        }
    }

    /// The encoder and the pass timer, to begin a pass.
    pub fn parts(&mut self) -> (&mut wgpu::CommandEncoder, &mut PassTimer) {
        (&mut self.encoder, self.timer)
    }

    fn submit_recorded(&mut self, stage: &str) -> Result<wgpu::SubmissionIndex> {
        let done = std::mem::replace(
            &mut self.encoder,
            self.device.create_command_encoder(&Default::default()),
        );
        let index = scoped(self.device, stage, || self.queue.submit([done.finish()]))?;
        self.io.submits += 1;
        Ok(index)
    }

    /// Submit what was recorded, copy the first `bytes` of `buffer` to the CPU and wait for
    /// them (the `cpu` strategy's cell bounds). Counted as a submission, a blocking readback
    /// and CPU wait.
    pub fn download(&mut self, buffer: &wgpu::Buffer, bytes: u64) -> Result<Vec<u8>> {
        if bytes == 0 {
            return Ok(Vec::new());
        }
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("download"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.encoder
            .copy_buffer_to_buffer(buffer, 0, &staging, 0, bytes);
        self.submit_recorded("submitting a frame part")?;
        let start = Instant::now();
        let out = read_buffer(self.device, &staging)?;
        self.io.cpu_wait_ms += start.elapsed().as_secs_f64() * 1e3;
        self.io.readback_bytes += bytes;
        Ok(out)
    }

    /// Submit the frame (no wait). Returns what the frame cost and its submission.
    pub(crate) fn submit(mut self, stage: &str) -> Result<(FrameIo, wgpu::SubmissionIndex)> {
        let index = self.submit_recorded(stage)?;
        Ok((self.io, index))
    }
}
