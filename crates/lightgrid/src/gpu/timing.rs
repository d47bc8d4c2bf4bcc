//! GPU time per pass from timestamp queries written at pass boundaries (the only placement
//! that lavapipe measures accurately; ECOSYSTEM.md). Without TIMESTAMP_QUERY the timer
//! records nothing and callers fall back to wall time after a device sync.

use super::GpuContext;

/// GPU time of one pass.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PassTiming {
    pub label: String,
    pub ms: f64,
}

/// Hands out begin/end timestamp slots to passes; [`PassTimer::resolve_into`] copies the
/// frame's timestamps into a buffer the frame counters read back (`gpu/counters.rs`).
pub struct PassTimer {
    queries: Option<(wgpu::QuerySet, wgpu::Buffer)>,
    labels: Vec<String>,
    capacity: u32,
    period_ns: f64,
}

impl PassTimer {
    /// A timer for at most `max_passes` passes per frame.
    pub fn new(ctx: &GpuContext, max_passes: u32) -> Self {
        let count = max_passes * 2;
        let queries = ctx.timestamps.then(|| {
            let set = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count,
            });
            let resolve = ctx.device.create_buffer(&wgpu::BufferDescriptor {
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
            capacity: max_passes,
            period_ns: f64::from(ctx.queue.get_timestamp_period()),
        }
    }

    /// Bytes of the timestamps of `passes` passes.
    pub fn bytes_for(passes: u32) -> u64 {
        u64::from(passes) * 16
    }

    /// Does this timer measure GPU time (false: wall time must be used)?
    pub fn enabled(&self) -> bool {
        self.queries.is_some()
    }

    /// Forget last frame's passes.
    pub fn reset(&mut self) {
        self.labels.clear();
    }

    /// The passes recorded this frame, in order.
    pub fn labels(&self) -> &[String] {
        &self.labels
    }

    fn slot(&mut self, label: &str) -> Option<(&wgpu::QuerySet, u32)> {
        let (set, _) = self.queries.as_ref()?;
        let index = self.labels.len() as u32;
        assert!(
            index < self.capacity,
            "PassTimer: more than {} passes in a frame; raise max_passes",
            self.capacity
        );
        self.labels.push(label.to_string());
        Some((set, index * 2))
    }

    /// Timestamp writes for a render pass labelled `label`.
    pub fn render_pass(&mut self, label: &str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.slot(label)
            .map(|(query_set, i)| wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(i),
                end_of_pass_write_index: Some(i + 1),
            })
    }

    /// Timestamp writes for a compute pass labelled `label`.
    pub fn compute_pass(&mut self, label: &str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.slot(label)
            .map(|(query_set, i)| wgpu::ComputePassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(i),
                end_of_pass_write_index: Some(i + 1),
            })
    }

    /// Record the resolve of this frame's queries and their copy into `dst` at `offset`
    /// (room for [`PassTimer::bytes_for`] the recorded passes); call once, after the last pass.
    pub fn resolve_into(
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

    /// Per-pass GPU times from the raw timestamps of `labels`' passes (two ticks per pass),
    /// and their sum: the frame's GPU work, CPU stalls between submissions excluded.
    pub fn timings(&self, labels: &[String], ticks: &[u64]) -> (Vec<PassTiming>, Option<f64>) {
        if self.queries.is_none() || labels.is_empty() || ticks.len() < labels.len() * 2 {
            return (Vec::new(), None);
        }
        let to_ms = |t: u64| t as f64 * self.period_ns / 1.0e6;
        let passes: Vec<PassTiming> = labels
            .iter()
            .enumerate()
            .map(|(i, label)| PassTiming {
                label: label.clone(),
                ms: to_ms(ticks[2 * i + 1].saturating_sub(ticks[2 * i])),
            })
            .collect();
        let sum = passes.iter().map(|p| p.ms).sum();
        (passes, Some(sum))
    }
}
