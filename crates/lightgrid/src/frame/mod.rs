//! What one frame carries, below `pipelines/`, `passes/` and `culling/` (which all use it):
//! the settings every pipeline shares (`settings.rs`), the render targets (`targets.rs`),
//! what a pipeline reads to record a frame (`FrameInputs`), the frame's command encoder
//! (`FrameEncoder`), which counts the queue submissions, blocking readbacks and CPU waits
//! the frame makes ([`FrameIo`]), and what the renderer reports about a frame once submitted
//! ([`SubmittedFrame`]) and once the GPU has finished it ([`FinishedFrame`]). A real-time
//! frame makes one submission and no blocking readback; only the `cpu` strategy with depth
//! bounds waits part-way (the papers' CPU pipeline reads the tile bounds back).

mod settings;
pub mod targets;

pub use settings::{
    validate_msaa, validate_tile_size, Assign, Brdf, CellBox, CullConfig, DepthBounds, DepthMask,
    DepthReduction, GBufferFormat, GridLists, GridStorage, LightLoop, MaterialDraws, MsaaResolve,
    RenderSettings, Shadows, SpotCull, AUTO_GATHER_MAX_LIGHTS,
};
pub(crate) use settings::{
    validate_shadow_atlas, validate_shadow_lights, validate_shadow_map_size, validate_slices,
};
pub(crate) use targets::Targets;
pub use targets::{check_msaa, msaa_counts};

use crate::error::Result;
use crate::gpu::{read_buffer, scoped, PassTimer, PassTiming};
use crate::scene::{Draw, Light, ViewSetup};
use web_time::Instant;

/// What a pipeline reads to render one frame.
pub(crate) struct FrameInputs<'a> {
    pub device: &'a wgpu::Device,
    pub queue: &'a wgpu::Queue,
    pub scene_bind_group: &'a wgpu::BindGroup,
    /// Group 0 for `PipelineContext::scene_culling_layout`.
    pub scene_culling_bind_group: &'a wgpu::BindGroup,
    pub vertices: &'a wgpu::Buffer,
    pub indices: &'a wgpu::Buffer,
    /// Runs of the opaque geometry's indices, one material shader each.
    pub opaque: &'a [Draw],
    /// Runs of the transparent objects' indices, back to front.
    pub transparent: &'a [Draw],
    pub targets: &'a Targets,
    /// Camera and frame size, for CPU light assignment.
    pub setup: ViewSetup,
    /// The frame's lights (world space).
    pub lights: &'a [Light],
    /// The same lights as uploaded to group 0 (camera-relative), in the buffer and on the
    /// CPU (a `LightCuller` reads both: `GpuLight` has `CullLight`'s layout).
    pub light_buffer: &'a wgpu::Buffer,
    pub gpu_lights: &'a [crate::gpu_types::GpuLight],
    /// The camera's projection (the view is `setup.view`, a rotation).
    pub proj: glam::Mat4,
    /// The count target is blended into (see `PipelineContext::count_blend`).
    pub count_blend: bool,
    /// `--shadows maps` in a pipeline that re-uses one light's maps (its
    /// `Technique::reuses_shadow_maps`): render each shadowed light's maps before its volume.
    pub reused_shadow_maps: Option<&'a dyn ReusedShadowMaps>,
}

/// Re-used shadow maps (`crate::shadows::maps`): the light-volume pipelines shade one light at
/// a time and render a shadowed light's maps into the same six tiles just before it.
pub(crate) trait ReusedShadowMaps {
    /// Does light `i` cast shadows this frame?
    fn casts(&self, light: usize) -> bool;
    /// Record light `i`'s maps into the re-used tiles.
    fn encode_light(&self, encoder: &mut wgpu::CommandEncoder, f: &FrameInputs, light: usize);
}

impl FrameInputs<'_> {
    /// Does the frame draw transparent geometry?
    pub fn has_transparency(&self) -> bool {
        !self.transparent.is_empty()
    }
}

/// What a frame cost the CPU side: queue submissions, bytes it waited to read back, and the
/// time it spent waiting for the GPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FrameIo {
    /// Queue submissions the frame made (more than one when it read data back part-way).
    pub submits: u32,
    /// Bytes read back with a wait for the GPU (not the asynchronous frame counters).
    pub readback_bytes: u64,
    /// Wall time the CPU waited for the GPU inside the frame.
    pub cpu_wait_ms: f64,
}

impl FrameIo {
    /// Add `other`'s costs (a part of the frame recorded elsewhere).
    pub fn add(&mut self, other: FrameIo) {
        self.submits += other.submits;
        self.readback_bytes += other.readback_bytes;
        self.cpu_wait_ms += other.cpu_wait_ms;
    }
}

/// The frame's command encoder. A pipeline records into it; only the `cpu` strategy submits
/// part-way (to read the cell bounds back). Every submission and blocking read goes through
/// here, so [`FrameIo`] is the whole story of the frame's CPU-GPU traffic.
pub(crate) struct FrameEncoder<'a> {
    device: &'a wgpu::Device,
    queue: &'a wgpu::Queue,
    encoder: Recording<'a>,
    pub timer: &'a mut PassTimer,
    io: FrameIo,
}

/// The encoder a frame records into: the renderer's own, or a caller's
/// (`culling::LightCuller`), which the caller submits at the end of its frame; only a
/// part-way readback (the `cpu` strategy's) submits what it holds so far and replaces it.
enum Recording<'a> {
    Owned(wgpu::CommandEncoder),
    Borrowed(&'a mut wgpu::CommandEncoder),
}

impl<'a> FrameEncoder<'a> {
    pub(crate) fn new(
        device: &'a wgpu::Device,
        queue: &'a wgpu::Queue,
        timer: &'a mut PassTimer,
    ) -> Self {
        let encoder = Recording::Owned(device.create_command_encoder(&Default::default()));
        FrameEncoder {
            device,
            queue,
            encoder,
            timer,
            io: FrameIo::default(),
        }
    }

    /// Record into a caller's encoder: the caller submits it. A part-way readback
    /// (`download_all`) submits what it holds so far and leaves a new encoder in its place.
    pub(crate) fn borrowed(
        device: &'a wgpu::Device,
        queue: &'a wgpu::Queue,
        encoder: &'a mut wgpu::CommandEncoder,
        timer: &'a mut PassTimer,
    ) -> Self {
        FrameEncoder {
            device,
            queue,
            encoder: Recording::Borrowed(encoder),
            timer,
            io: FrameIo::default(),
        }
    }

    /// What the frame has cost the CPU side so far.
    pub fn io(&self) -> FrameIo {
        self.io
    }

    /// The encoder, the pass timer and the frame's CPU-side costs (a `LightCuller` records
    /// into the frame and adds its own: `CullExtras`).
    pub fn split(&mut self) -> (&mut wgpu::CommandEncoder, &mut PassTimer, &mut FrameIo) {
        let encoder = match &mut self.encoder {
            Recording::Owned(e) => e,
            Recording::Borrowed(e) => &mut **e,
        };
        (encoder, self.timer, &mut self.io)
    }

    /// The encoder and the pass timer, to begin a pass.
    pub fn parts(&mut self) -> (&mut wgpu::CommandEncoder, &mut PassTimer) {
        let encoder = match &mut self.encoder {
            Recording::Owned(e) => e,
            Recording::Borrowed(e) => &mut **e,
        };
        (encoder, self.timer)
    }

    fn encoder(&mut self) -> &mut wgpu::CommandEncoder {
        self.parts().0
    }

    /// Submit what is recorded so far and go on in a new encoder (a caller's is replaced in
    /// its place: the rest of its frame records into the new one).
    fn submit_recorded(&mut self, stage: &str) -> Result<wgpu::SubmissionIndex> {
        let next = self.device.create_command_encoder(&Default::default());
        let done = std::mem::replace(self.encoder(), next);
        let index = scoped(self.device, stage, || self.queue.submit([done.finish()]))?;
        self.io.submits += 1;
        self.timer.next_submission();
        Ok(index)
    }

    /// [`Self::download`] of several buffers (the first `bytes` of each, multiples of 4) in
    /// one submission and one wait.
    pub fn download_all(&mut self, parts: &[(&wgpu::Buffer, u64)]) -> Result<Vec<Vec<u8>>> {
        let total: u64 = parts.iter().map(|&(_, bytes)| bytes).sum();
        if total == 0 {
            return Ok(vec![Vec::new(); parts.len()]);
        }
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("download"),
            size: total,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut offset = 0;
        for &(buffer, bytes) in parts {
            if bytes > 0 {
                self.parts()
                    .0
                    .copy_buffer_to_buffer(buffer, 0, &staging, offset, bytes);
            }
            offset += bytes;
        }
        self.submit_recorded("submitting a frame part")?;
        let start = Instant::now();
        let all = read_buffer(self.device, &staging)?;
        self.io.cpu_wait_ms += start.elapsed().as_secs_f64() * 1e3;
        self.io.readback_bytes += total;
        let mut rest = all.as_slice();
        Ok(parts
            .iter()
            .map(|&(_, bytes)| {
                let (part, tail) = rest.split_at(bytes as usize);
                rest = tail;
                part.to_vec()
            })
            .collect())
    }

    /// Submit the frame (no wait). Returns what the frame cost and its submission.
    pub(crate) fn submit(mut self, stage: &str) -> Result<(FrameIo, wgpu::SubmissionIndex)> {
        let index = self.submit_recorded(stage)?;
        Ok((self.io, index))
    }
}

/// A frame submitted by `Renderer::render_frame`.
#[derive(Clone, Copy, Debug)]
pub struct SubmittedFrame {
    /// The renderer's frame number (counts every submitted frame).
    pub serial: u64,
    /// Submissions, blocking readbacks and CPU waits the frame made.
    pub io: FrameIo,
    /// CPU time spent waiting for older frames before this one could be queued
    /// (more than `MAX_FRAMES_IN_FLIGHT` in flight).
    pub throttle_ms: f64,
    /// Bytes uploaded for the frame (lights, uniforms, moving geometry).
    pub upload_bytes: u64,
}

/// What the edge-aware MSAA deferred kernels did in a frame (tiled-deferred-tricks).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct MsaaShading {
    /// Pixels whose samples differ (shaded per sample).
    pub edge_pixels: u64,
    /// Samples shaded: one per pixel with geometry plus the other covered samples of edge
    /// pixels.
    pub shaded_samples: u64,
    /// Samples with geometry: what shading every sample would shade.
    pub geometry_samples: u64,
}

/// What the GPU reported about a finished real-time frame (read back without waiting).
#[derive(Clone, Debug)]
pub struct FinishedFrame {
    /// The frame's number, as [`SubmittedFrame::serial`] gave it when it was submitted.
    pub serial: u64,
    /// Id of the pipeline that rendered it (`PipelineInfo::id`, as given to `--pipeline`).
    pub pipeline: &'static str,
    /// The frame's GPU time: the span of each of its submissions (first pass start to last
    /// pass end), summed, so CPU waits between them are left out; None without timestamps.
    pub gpu_ms: Option<f64>,
    /// The span of its light-assignment passes (`assign: ...`, cell bounds included).
    pub assign_gpu_ms: Option<f64>,
    /// Each timed pass's label and begin-to-end GPU time, in recording order (empty without
    /// timestamps).
    pub passes: Vec<PassTiming>,
    /// Shader loops that ended before their bound: the frame is wrong when non-zero.
    pub truncated_loops: u32,
    /// Some light list did not fit its buffer (sized from earlier frames): the frame is
    /// missing lights; the buffers have grown for the next one.
    pub overflowed: bool,
    /// The MSAA deferred kernels' edge counts (None where none ran).
    pub msaa_shading: Option<MsaaShading>,
    /// MSAA forward fragments whose shading point lay outside their cell's bounds, so their
    /// lists may have missed lights: the frame is wrong when non-zero.
    pub fragments_off_bounds: u64,
    /// Shadow rays the light function cast (`--shadows rays`).
    pub shadow_rays: u64,
}
