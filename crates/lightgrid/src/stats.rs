//! Per-frame statistics written by `lightgrid render --stats`.

use crate::gpu::PassTiming;
use serde::{Deserialize, Serialize};

/// How `gpu_ms` was measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TimingSource {
    /// Timestamp queries at pass boundaries: first pass start to last pass end.
    GpuTimestamps,
    /// No timestamp queries: wall time from submit until the device is idle.
    WallClock,
}

/// Statistics of one rendered frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameStats {
    pub scene: String,
    pub pipeline: String,
    pub adapter: String,
    pub width: u32,
    pub height: u32,
    pub frame: u32,
    pub lights: u32,
    pub triangles: u32,
    /// GPU time of the frame in milliseconds (see `timing`).
    pub gpu_ms: f64,
    pub timing: TimingSource,
    /// Wall time from submit until the device was idle, including readback.
    pub wall_ms: f64,
    /// GPU time per pass, when timestamps are available.
    pub passes: Vec<PassTiming>,
}
