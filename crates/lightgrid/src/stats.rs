//! Per-frame statistics written by `lightgrid render --stats`, and [`Distribution`]: the one
//! summary of a series of values (frame times, counts) every command and the benchmark use.

use crate::gpu::PassTiming;
use crate::memory::FrameMemory;
use serde::{Deserialize, Serialize};

/// How `gpu_ms` was measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TimingSource {
    /// Timestamp queries at pass boundaries: per submission of the frame, its first pass's
    /// start to its last pass's end, summed (GPU work only; CPU waits between submissions are
    /// not in it).
    GpuTimestamps,
    /// No timestamp queries: wall time from the first submission until the device is idle
    /// (CPU waits included).
    WallClock,
}

impl TimingSource {
    /// The name used in JSON, CSV and tables.
    pub fn label(self) -> &'static str {
        match self {
            TimingSource::GpuTimestamps => "gpu-timestamps",
            TimingSource::WallClock => "wall-clock",
        }
    }
}

/// A frame's shadow maps (`crate::shadows::maps`).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShadowMapStats {
    /// Bytes of the depth texture the maps were rendered into this frame.
    pub bytes: u64,
    /// Texels on a side of one face.
    pub face: u32,
    /// Faces rendered (six per cube, one per narrow spot).
    pub faces: u32,
    /// One light's maps re-used light by light (the light-volume pipelines), or every
    /// light's in flight in an atlas.
    pub reused: bool,
}

/// Statistics of one analysis frame (what `lightgrid render --stats` writes).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameStats {
    /// The scene's name.
    pub scene: String,
    /// The pipeline's id.
    pub pipeline: String,
    /// The adapter as `GpuContext::adapter_label` prints it: "name (backend)".
    pub adapter: String,
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// The animation frame rendered.
    pub frame: u32,
    /// Lights in the scene at this frame.
    pub lights: u32,
    /// Triangles drawn (static and moving, opaque and transparent).
    pub triangles: u32,
    /// GPU time of the frame in milliseconds (see `timing`).
    pub gpu_ms: f64,
    /// How `gpu_ms` was measured.
    pub timing: TimingSource,
    /// Wall time from the frame's first submission until the device was idle (analysis
    /// copies included).
    pub wall_ms: f64,
    /// CPU time the frame itself waited for the GPU (the `cpu` strategy's read-back of the
    /// cell bounds; 0 for a frame in one submission). The analysis wait is not in it.
    #[serde(default)]
    pub cpu_wait_ms: f64,
    /// Queue submissions the frame made (1, or 2 for `cpu` with depth bounds).
    #[serde(default)]
    pub submits: u32,
    /// Bytes the frame itself read back with a wait (analysis readbacks not counted).
    #[serde(default)]
    pub readback_bytes: u64,
    /// Shader loops that ended before their bound (llvmpipe's loop guard). An analysis run
    /// refuses a frame where this is non-zero, so a written file always says 0.
    #[serde(default)]
    pub truncated_loops: u32,
    /// GPU time per pass, when timestamps are available.
    pub passes: Vec<PassTiming>,
    /// Screen tile edge in pixels used by grid pipelines (and for the ideal count's grid).
    pub tile_size: u32,
    /// G-buffer channel bits (16 or 32); meaningful for deferred pipelines.
    pub gbuffer_bits: u32,
    /// MSAA samples per pixel (`--msaa`).
    #[serde(default = "one")]
    pub msaa: u32,
    /// The edge-aware MSAA deferred kernels: pixels shaded per sample, samples shaded, and
    /// samples with geometry (what shading every sample would shade). None for other frames.
    #[serde(default)]
    pub msaa_shading: Option<crate::frame::MsaaShading>,
    /// MSAA grid-forward fragments whose pixel centre (extrapolated off their triangle) lay
    /// outside their cell's bounds (`light_grid_shade_fragment`). An analysis frame refuses a
    /// non-zero count, so a written file always says 0.
    #[serde(default)]
    pub fragments_off_bounds: u64,
    /// Shadow rays cast (`--shadows rays`; None without shadows).
    #[serde(default)]
    pub shadow_rays: Option<u64>,
    /// Lights lit without shadows this frame (`--shadow-lights`; None without shadows).
    #[serde(default)]
    pub unshadowed_lights: Option<u32>,
    /// The shadow maps' memory and resolution (`--shadows maps`).
    #[serde(default)]
    pub shadow_maps: Option<ShadowMapStats>,
    /// Where the MSAA deferred kernel resolved this frame: `kernel` (Trick 1) or `separate`
    /// (per-sample buffer, tonemap); None for other frames.
    #[serde(default)]
    pub msaa_resolve: Option<crate::frame::MsaaResolve>,
    /// Times the light function ran this frame (tiled-shading §8): for forward pipelines the
    /// fragments shaded times the lights each looped over, for deferred ones the samples
    /// times their tile's list length. None where the adapter cannot count (no R32Float
    /// blending).
    pub lighting_computations: Option<u64>,
    /// For every visible sample and every transparent fragment in front of the opaque
    /// depth, the lights that reach it: the floor no technique can go below.
    pub ideal_lighting_computations: u64,
    /// Transparent fragments shaded (CPU rasterization of the transparent objects in front
    /// of the opaque depth): the transparent overdraw.
    #[serde(default)]
    pub transparent_fragments: u64,
    /// The part of the ideal count that is the transparent fragments'.
    #[serde(default)]
    pub ideal_transparent_computations: u64,
    /// The transparent pass's lighting computations (the count target before and after it).
    #[serde(default)]
    pub transparent_lighting_computations: Option<u64>,
    /// ideal / actual (1.0 is perfect culling).
    pub efficiency: Option<f64>,
    /// Lights per cell (tile, or cluster) of the grid this pipeline shaded with (None: it
    /// builds no grid).
    pub lights_per_tile_avg: Option<f64>,
    /// The longest light list of a cell in that grid (None: it builds no grid).
    pub lights_per_tile_max: Option<u32>,
    /// tiled-shading Fig. 3's count for tiled grids: tile area × list length, summed over the
    /// tiles (`LightGrid::tile_area_computations`; None for clustered grids and without one).
    #[serde(default)]
    pub tile_area_computations: Option<u64>,
    /// Total entries of the grid's index lists.
    pub grid_indices: Option<u64>,
    /// Cells of the grid (tiles × slices) and how many hold samples (non-empty bounds).
    #[serde(default)]
    pub grid_cells: Option<u64>,
    /// Cells of the grid whose depth bounds are non-empty (None without a grid).
    #[serde(default)]
    pub grid_cells_occupied: Option<u64>,
    /// The light-assignment strategy that built the grid (`--assign`, `auto` resolved).
    #[serde(default)]
    pub assign: Option<String>,
    /// GPU time of the assignment passes (cell bounds, and for GPU strategies the
    /// assignment kernels), from timestamps: the span from the first pass labelled
    /// `assign: ...` to the last, per submission.
    #[serde(default)]
    pub assign_gpu_ms: Option<f64>,
    /// CPU time of the assignment: `assign_cpu` for `cpu`, the hierarchy build for `bvh`.
    #[serde(default)]
    pub assign_cpu_ms: Option<f64>,
    /// The assignment strategy's cost: `assign_gpu_ms` + `assign_cpu_ms` (the `cpu`
    /// strategy's wait for the cell bounds is the frame's `cpu_wait_ms`).
    #[serde(default)]
    pub assign_ms: Option<f64>,
    /// Times the analysis frame was rendered again because a light list, sized from earlier
    /// frames, was too small (grown to the needed size first: nothing is dropped).
    #[serde(default)]
    pub assign_reruns: Option<u32>,
    /// Render targets, grid size and the traffic models (`memory.rs`).
    pub memory: FrameMemory,
}

fn one() -> u32 {
    1
}

/// The summary of a series: min / mean / median / 95th percentile / max.
///
/// The median and the percentile are order statistics (a value of the series: the one at
/// rank `round((n - 1) q)` in ascending order, so the median of an even count is the upper of
/// the middle two); [`Distribution::median_index`] finds which value that is.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Distribution {
    /// The smallest value.
    pub min: f64,
    /// The arithmetic mean.
    pub mean: f64,
    /// The value at rank `round((n - 1) 0.5)` (of an even count, the upper of the middle two).
    pub median: f64,
    /// The 95th percentile: the value at rank `round((n - 1) 0.95)`.
    pub p95: f64,
    /// The largest value.
    pub max: f64,
}

impl Distribution {
    /// The summary of `values`; None when there are none.
    pub fn of(values: impl IntoIterator<Item = f64>) -> Option<Distribution> {
        let v: Vec<f64> = values.into_iter().collect();
        let order = Self::ascending(&v);
        let last = *order.last()?;
        let at = |q: f64| v[order[Self::rank(v.len(), q)]];
        Some(Distribution {
            min: v[order[0]],
            mean: v.iter().sum::<f64>() / v.len() as f64,
            median: at(0.5),
            p95: at(0.95),
            max: v[last],
        })
    }

    /// The index in `values` of the value [`Distribution::of`] reports as the median (the
    /// first of equal values); None when there are none.
    pub fn median_index(values: &[f64]) -> Option<usize> {
        let order = Self::ascending(values);
        order.get(Self::rank(values.len(), 0.5)).copied()
    }

    /// Indices of `values` in ascending order (a stable sort: equal values keep their order).
    fn ascending(values: &[f64]) -> Vec<usize> {
        let mut order: Vec<usize> = (0..values.len()).collect();
        order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
        order
    }

    /// The rank of the `q` quantile among `n` sorted values.
    fn rank(n: usize, q: f64) -> usize {
        (n.saturating_sub(1) as f64 * q).round() as usize
    }
}

#[cfg(test)]
mod tests {
    use super::Distribution;

    #[test]
    fn distribution_of_a_series() {
        assert_eq!(Distribution::of(std::iter::empty()), None);
        assert_eq!(Distribution::median_index(&[]), None);
        let d = Distribution::of([4.0, 1.0, 3.0, 2.0]).unwrap();
        assert_eq!((d.min, d.mean, d.max), (1.0, 2.5, 4.0));
        // The upper of the middle two, as the benchmark has always picked its median frame.
        assert_eq!((d.median, d.p95), (3.0, 4.0));
        assert_eq!(Distribution::median_index(&[4.0, 1.0, 3.0, 2.0]), Some(2));
        let one = Distribution::of([7.0]).unwrap();
        assert_eq!(
            (one.min, one.mean, one.median, one.p95, one.max),
            (7.0, 7.0, 7.0, 7.0, 7.0)
        );
        let odd: Vec<f64> = (1..=21).map(f64::from).rev().collect();
        let d = Distribution::of(odd.iter().copied()).unwrap();
        assert_eq!((d.median, d.p95), (11.0, 20.0));
        assert_eq!(odd[Distribution::median_index(&odd).unwrap()], 11.0);
    }
}
