//! GPU time per pass from timestamp queries written at pass boundaries (the only placement
//! that lavapipe measures accurately; ECOSYSTEM.md). Without TIMESTAMP_QUERY the timer
//! records nothing and callers fall back to wall time after a device sync.
//!
//! A frame's GPU time is the span of each submission (its first pass's start to its last
//! pass's end), summed over the frame's submissions: CPU stalls between submissions are left
//! out, and work the driver runs outside the pass that recorded it still counts. (lavapipe
//! reports directly dispatched compute passes as taking ~0.01 ms and runs their work later
//! in the submission: scatter's radix sort of 260k pairs read 0.1 ms pass by pass against
//! 1.45 s of wall time, so per-pass durations can be attributed to the wrong pass there, but
//! spans are right.)

use super::GpuContext;

/// GPU time of one pass.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PassTiming {
    /// The pass's label (light-assignment passes' labels start with `assign: `).
    pub label: String,
    /// GPU time from the pass's begin timestamp to its end timestamp, in milliseconds.
    pub ms: f64,
}

/// A pass the timer handed slots to: its label and the submission of the frame it is in.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct TimedPass {
    pub label: String,
    pub submission: u32,
}

/// What a frame's timestamps say.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct FrameTimings {
    /// Each pass's begin-to-end time.
    pub passes: Vec<PassTiming>,
    /// The frame's GPU time: its submissions' spans, summed (None without timestamps).
    pub gpu_ms: Option<f64>,
    /// The span of the light-assignment passes (labels `assign: ...`), summed over the
    /// submissions holding them; None when the frame has none.
    pub assign_ms: Option<f64>,
}

/// A frame's pass timer: hands out begin/end timestamp slots to the passes recorded into one
/// frame (lightgrid's renderer copies them into the buffer its frame counters read back,
/// `gpu/counters.rs`). Without `TIMESTAMP_QUERY` it times nothing. A
/// [`crate::LightCuller`] given one ([`crate::culling::CullExtras::timer`]) times its passes
/// in it; [`PassTimer::read_passes`] reads what a frame's passes took.
pub struct PassTimer {
    queries: Option<(wgpu::QuerySet, wgpu::Buffer)>,
    labels: Vec<TimedPass>,
    /// The frame's submissions so far (the passes recorded now go into this one).
    submission: u32,
    capacity: u32,
    period_ns: f64,
}

impl PassTimer {
    /// A timer for at most `max_passes` passes per frame.
    pub fn new(ctx: &GpuContext, max_passes: u32) -> Self {
        Self::for_device(&ctx.device, &ctx.queue, ctx.timestamps, max_passes)
    }

    /// A timer on any device and queue (`timestamps`: the device was created with
    /// `TIMESTAMP_QUERY`), for at most `max_passes` passes per frame (later passes of a frame
    /// go untimed).
    pub fn for_device(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        timestamps: bool,
        max_passes: u32,
    ) -> Self {
        let count = max_passes * 2;
        let queries = timestamps.then(|| {
            let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count,
            });
            let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size: Self::bytes_for(max_passes),
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            (set, resolve)
        });
        Self {
            queries,
            labels: Vec::new(),
            submission: 0,
            capacity: max_passes,
            period_ns: f64::from(queue.get_timestamp_period()),
        }
    }

    /// A timer that measures nothing (a `LightCuller` recording into a caller's encoder).
    pub fn disabled() -> Self {
        Self {
            queries: None,
            labels: Vec::new(),
            submission: 0,
            capacity: 0,
            period_ns: 1.0,
        }
    }

    /// Bytes of the timestamps of `passes` passes.
    pub(crate) fn bytes_for(passes: u32) -> u64 {
        u64::from(passes) * 16
    }

    /// The GPU time of each pass timed since [`Self::reset`], once their submissions are
    /// done (tools: submits a resolve and waits). Empty without timestamps.
    pub fn read_passes(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> crate::error::Result<Vec<PassTiming>> {
        let n = self.labels.len() as u32;
        if self.queries.is_none() || n == 0 {
            return Ok(Vec::new());
        }
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp readback"),
            size: Self::bytes_for(n),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        self.resolve_into(&mut encoder, &staging, 0);
        queue.submit([encoder.finish()]);
        let bytes = super::read_buffer(device, &staging)?;
        let ticks: Vec<u64> = bytes
            .chunks_exact(8)
            .map(|c| c.iter().rev().fold(0u64, |t, &b| t << 8 | u64::from(b)))
            .collect();
        Ok(self.timings(&self.labels, &ticks).passes)
    }

    /// Forget last frame's passes.
    pub fn reset(&mut self) {
        self.labels.clear();
        self.submission = 0;
    }

    /// The passes recorded this frame, in order.
    pub(crate) fn labels(&self) -> &[TimedPass] {
        &self.labels
    }

    /// Begin a compute pass labelled `label`, timed at its boundaries.
    pub(crate) fn begin_compute<'e>(
        &mut self,
        encoder: &'e mut wgpu::CommandEncoder,
        label: &str,
    ) -> wgpu::ComputePass<'e> {
        encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: self.compute_pass(label),
        })
    }

    /// The frame was submitted part-way: later passes go into its next submission.
    pub(crate) fn next_submission(&mut self) {
        self.submission += 1;
    }

    fn slot(&mut self, label: &str) -> Option<(&wgpu::QuerySet, u32)> {
        let (set, _) = self.queries.as_ref()?;
        let index = self.labels.len() as u32;
        // Passes beyond the capacity go untimed (a frame's span then ends before them).
        if index >= self.capacity {
            return None;
        }
        self.labels.push(TimedPass {
            label: label.to_string(),
            submission: self.submission,
        });
        Some((set, index * 2))
    }

    /// Timestamp writes for a render pass labelled `label`.
    pub(crate) fn render_pass(
        &mut self,
        label: &str,
    ) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.slot(label)
            .map(|(query_set, i)| wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(i),
                end_of_pass_write_index: Some(i + 1),
            })
    }

    /// Timestamp writes for a compute pass labelled `label`.
    pub(crate) fn compute_pass(
        &mut self,
        label: &str,
    ) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.slot(label)
            .map(|(query_set, i)| wgpu::ComputePassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(i),
                end_of_pass_write_index: Some(i + 1),
            })
    }

    /// Record the resolve of this frame's queries and their copy into `dst` at `offset`
    /// (room for [`PassTimer::bytes_for`] the recorded passes); call once, after the last pass.
    pub(crate) fn resolve_into(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        dst: &wgpu::Buffer,
        offset: u64,
    ) {
        if let Some((set, resolve)) = &self.queries {
            let n = self.labels.len() as u32 * 2;
            if n == 0 {
                return;
            }
            encoder.resolve_query_set(set, 0..n, resolve, 0);
            encoder.copy_buffer_to_buffer(resolve, 0, dst, offset, u64::from(n) * 8);
        }
    }

    /// What the raw timestamps of `labels`' passes (two ticks per pass) say.
    pub(crate) fn timings(&self, labels: &[TimedPass], ticks: &[u64]) -> FrameTimings {
        if self.queries.is_none() {
            return FrameTimings::default();
        }
        frame_timings(labels, ticks, self.period_ns)
    }
}

/// What the raw timestamps of `labels`' passes say (two ticks per pass, `period_ns` each):
/// per-pass times, and the spans of the frame's submissions (see the module doc).
pub fn frame_timings(labels: &[TimedPass], ticks: &[u64], period_ns: f64) -> FrameTimings {
    if labels.is_empty() || ticks.len() < labels.len() * 2 {
        return FrameTimings::default();
    }
    let to_ms = |t: u64| t as f64 * period_ns / 1.0e6;
    let passes: Vec<PassTiming> = labels
        .iter()
        .enumerate()
        .map(|(i, p)| PassTiming {
            label: p.label.clone(),
            ms: to_ms(ticks[2 * i + 1].saturating_sub(ticks[2 * i])),
        })
        .collect();
    // Spans per submission of the passes `keep` selects: (first begin, last end).
    let spans = |keep: &dyn Fn(&TimedPass) -> bool| {
        let mut spans: Vec<(u32, u64, u64)> = Vec::new();
        for (i, p) in labels.iter().enumerate().filter(|(_, p)| keep(p)) {
            let (begin, end) = (ticks[2 * i], ticks[2 * i + 1]);
            match spans.iter_mut().find(|s| s.0 == p.submission) {
                Some(s) => {
                    s.1 = s.1.min(begin);
                    s.2 = s.2.max(end);
                }
                None => spans.push((p.submission, begin, end)),
            }
        }
        (!spans.is_empty()).then(|| {
            spans
                .iter()
                .map(|&(_, b, e)| to_ms(e.saturating_sub(b)))
                .sum::<f64>()
        })
    };
    FrameTimings {
        passes,
        gpu_ms: spans(&|_| true),
        assign_ms: spans(&|p| {
            p.label
                .starts_with(crate::consts::pass_labels::ASSIGN_PREFIX)
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pass(label: &str, submission: u32) -> TimedPass {
        TimedPass {
            label: label.into(),
            submission,
        }
    }

    #[test]
    fn spans_per_submission_leave_out_the_wait_between_them() {
        // Submission 0: depth 0..10 ms, bounds 10..12; the CPU waits until 50; submission 1:
        // a compute pass reported as 0.01 ms whose work shows up before shading's end (lavapipe).
        let labels = [
            pass("depth pre-pass", 0),
            pass("assign: cell bounds", 0),
            pass("assign: gather", 1),
            pass("shading", 1),
        ];
        let ms = 1_000_000u64; // ticks of 1 ns
        let ticks = [
            0,
            10 * ms,
            10 * ms,
            12 * ms,
            50 * ms,
            50 * ms + 10_000,
            60 * ms,
            90 * ms,
        ];
        let t = frame_timings(&labels, &ticks, 1.0);
        assert_eq!(t.passes.len(), 4);
        assert!((t.passes[2].ms - 0.01).abs() < 1e-9);
        // 12 ms + (90 - 50) ms: not the 90 ms from first to last, not the 42.01 ms of passes.
        assert!((t.gpu_ms.unwrap() - 52.0).abs() < 1e-9, "{t:?}");
        // Assignment: 10..12 in submission 0, 50..50.01 in submission 1.
        assert!((t.assign_ms.unwrap() - 2.01).abs() < 1e-9, "{t:?}");
        let none = frame_timings(&labels[..1], &ticks[..2], 1.0);
        assert_eq!(none.assign_ms, None);
        assert_eq!(
            frame_timings(&labels, &ticks[..3], 1.0),
            FrameTimings::default()
        );
    }
}
