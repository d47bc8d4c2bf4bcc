//! The live figures the panel shows from the real-time path, gathered without waiting: the
//! wall time between displayed frames (what a user sees), the GPU time and per-pass times of
//! each frame as its timestamps come back a frame or more later, fps, and the counters of
//! frames shown wrong (lists that overflowed, shader loops cut short, MSAA fragments off
//! their cell's bounds), which stay visible even with the panel hidden.

use lightgrid::frame::FinishedFrame;
use lightgrid::gpu::PassTiming;
use std::collections::VecDeque;

/// Frames kept for the graph (a few seconds at interactive rates).
pub const HISTORY: usize = 240;

#[derive(Default)]
pub struct LiveFigures {
    /// Wall milliseconds from one displayed frame to the next, oldest first.
    pub frame_ms: VecDeque<f32>,
    /// GPU milliseconds of finished frames (timestamp spans), oldest first.
    pub gpu_ms: VecDeque<f32>,
    /// The passes of the newest finished frame with timestamps.
    pub passes: Vec<PassTiming>,
    /// The newest frame's light-assignment GPU time.
    pub assign_ms: Option<f64>,
    pub displayed: u64,
    pub finished: u64,
    /// Frames whose lists did not fit their buffers (they grew for the next frame).
    pub overflowed: u64,
    /// Frames with shader loops ended early by the adapter (their images miss light).
    pub truncated: u64,
    /// Frames with MSAA fragments outside their cell's depth bounds.
    pub off_bounds: u64,
}

fn push(q: &mut VecDeque<f32>, v: f32) {
    if q.len() == HISTORY {
        q.pop_front();
    }
    q.push_back(v);
}

impl LiveFigures {
    /// A frame was put on the window `ms` after the one before it.
    pub fn displayed(&mut self, ms: f64) {
        self.displayed += 1;
        if ms.is_finite() && ms >= 0.0 {
            push(&mut self.frame_ms, ms as f32);
        }
    }

    /// A frame's counters and timestamps came back.
    pub fn finished(&mut self, f: &FinishedFrame) {
        self.finished += 1;
        if let Some(ms) = f.gpu_ms {
            push(&mut self.gpu_ms, ms as f32);
            self.passes = f.passes.clone();
            self.assign_ms = f.assign_gpu_ms;
        }
        self.overflowed += u64::from(f.overflowed);
        self.truncated += u64::from(f.truncated_loops > 0);
        self.off_bounds += u64::from(f.fragments_off_bounds > 0);
    }

    /// Frames per second over the newest second of displayed frames (at least one frame).
    pub fn fps(&self) -> Option<f64> {
        let mut total = 0.0f64;
        let mut n = 0u32;
        for &ms in self.frame_ms.iter().rev() {
            total += f64::from(ms);
            n += 1;
            if total >= 1000.0 {
                break;
            }
        }
        (n > 0 && total > 0.0).then(|| f64::from(n) * 1000.0 / total)
    }

    /// Mean of the newest `n` values of `q`.
    pub fn recent_mean(q: &VecDeque<f32>, n: usize) -> Option<f64> {
        let take = q.len().min(n);
        (take > 0).then(|| {
            q.iter()
                .rev()
                .take(take)
                .map(|&v| f64::from(v))
                .sum::<f64>()
                / take as f64
        })
    }

    /// Forget the times (a new renderer measures anew); the wrong-frame counters stay.
    pub fn restart_times(&mut self) {
        self.frame_ms.clear();
        self.gpu_ms.clear();
        self.passes.clear();
        self.assign_ms = None;
    }

    /// The always-visible line: fps and the wrong-frame counters.
    pub fn status_line(&self) -> String {
        format!(
            "{} fps | overflowed {} | truncated {}{}",
            self.fps().map_or("-".into(), |f| format!("{f:.1}")),
            self.overflowed,
            self.truncated,
            if self.off_bounds > 0 {
                format!(" | off bounds {}", self.off_bounds)
            } else {
                String::new()
            }
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn finished(gpu: Option<f64>, overflowed: bool, truncated: u32) -> FinishedFrame {
        FinishedFrame {
            serial: 0,
            pipeline: "forward",
            gpu_ms: gpu,
            assign_gpu_ms: None,
            passes: vec![PassTiming {
                label: "shade".into(),
                ms: gpu.unwrap_or(0.0),
            }],
            truncated_loops: truncated,
            overflowed,
            msaa_shading: None,
            fragments_off_bounds: 0,
            shadow_rays: 0,
        }
    }

    #[test]
    fn fps_covers_the_newest_second() {
        let mut live = LiveFigures::default();
        assert_eq!(live.fps(), None);
        for _ in 0..100 {
            live.displayed(100.0);
        }
        // 10 frames of 100 ms make the newest second.
        assert!((live.fps().unwrap() - 10.0).abs() < 1e-9);
        // Half a second of 10 ms frames and half of the older 100 ms ones: 55 frames.
        for _ in 0..50 {
            live.displayed(10.0);
        }
        assert!((live.fps().unwrap() - 55.0).abs() < 1e-9);
        for _ in 0..100 {
            live.displayed(10.0);
        }
        assert!((live.fps().unwrap() - 100.0).abs() < 1e-9);
        live.displayed(f64::NAN);
        assert_eq!(live.displayed, 251);
        assert!(live.frame_ms.len() <= HISTORY);
    }

    #[test]
    fn counts_wrong_frames_and_keeps_the_newest_passes() {
        let mut live = LiveFigures::default();
        live.finished(&finished(Some(5.0), false, 0));
        live.finished(&finished(None, true, 0));
        live.finished(&finished(Some(7.0), false, 3));
        assert_eq!((live.finished, live.overflowed, live.truncated), (3, 1, 1));
        assert_eq!(
            live.gpu_ms.iter().copied().collect::<Vec<_>>(),
            vec![5.0, 7.0]
        );
        assert_eq!(live.passes[0].ms, 7.0);
        assert_eq!(LiveFigures::recent_mean(&live.gpu_ms, 10), Some(6.0));
        assert!(live.status_line().contains("overflowed 1 | truncated 1"));
        live.restart_times();
        assert!(live.gpu_ms.is_empty() && live.overflowed == 1);
    }

    #[test]
    fn history_is_bounded() {
        let mut live = LiveFigures::default();
        for i in 0..(HISTORY + 10) {
            live.displayed(i as f64);
        }
        assert_eq!(live.frame_ms.len(), HISTORY);
        assert_eq!(live.frame_ms[0], 10.0);
    }
}
