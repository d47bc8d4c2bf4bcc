//! GPU time per pass from timestamp queries written at pass boundaries (the only placement
//! that lavapipe measures accurately; ECOSYSTEM.md). Without TIMESTAMP_QUERY the timer
//! records nothing and callers fall back to wall time after a device sync.

use super::{read_buffer, GpuContext};
use crate::error::Result;

/// GPU time of one pass.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PassTiming {
    pub label: String,
    pub ms: f64,
}

/// Hands out begin/end timestamp slots to passes and reads them back after the frame.
pub struct PassTimer {
    queries: Option<(wgpu::QuerySet, wgpu::Buffer, wgpu::Buffer)>,
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
            let size = u64::from(count) * 8;
            let resolve = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp readback"),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            (set, resolve, readback)
        });
        Self {
            queries,
            labels: Vec::new(),
            capacity: max_passes,
            period_ns: f64::from(ctx.queue.get_timestamp_period()),
        }
    }

    /// Does this timer measure GPU time (false: wall time must be used)?
    pub fn enabled(&self) -> bool {
        self.queries.is_some()
    }

    /// Forget last frame's passes.
    pub fn reset(&mut self) {
        self.labels.clear();
    }

    fn slot(&mut self, label: &str) -> Option<(&wgpu::QuerySet, u32)> {
        let (set, _, _) = self.queries.as_ref()?;
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

    /// Record the resolve of this frame's queries; call once, after the last pass.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some((set, resolve, readback)) = &self.queries {
            let n = self.labels.len() as u32 * 2;
            if n == 0 {
                return;
            }
            encoder.resolve_query_set(set, 0..n, resolve, 0);
            encoder.copy_buffer_to_buffer(resolve, 0, readback, 0, u64::from(n) * 8);
        }
    }

    /// Per-pass GPU times of the frame just submitted, and the frame's span from the first
    /// pass's start to the last pass's end. Empty when timestamps are unavailable.
    pub fn read(&self, device: &wgpu::Device) -> Result<(Vec<PassTiming>, Option<f64>)> {
        let Some((_, _, readback)) = &self.queries else {
            return Ok((Vec::new(), None));
        };
        if self.labels.is_empty() {
            return Ok((Vec::new(), None));
        }
        let bytes = read_buffer(device, readback)?;
        let ticks: Vec<u64> = bytes
            .chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect();
        let to_ms = |t: u64| t as f64 * self.period_ns / 1.0e6;
        let passes = self
            .labels
            .iter()
            .enumerate()
            .map(|(i, label)| PassTiming {
                label: label.clone(),
                ms: to_ms(ticks[2 * i + 1].saturating_sub(ticks[2 * i])),
            })
            .collect();
        let first = ticks[0];
        let last = ticks[self.labels.len() * 2 - 1];
        Ok((passes, Some(to_ms(last.saturating_sub(first)))))
    }
}
