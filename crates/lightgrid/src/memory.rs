//! Memory accounting: each pipeline's render targets in bytes per pixel, and the traffic model
//! of deferred-shading-vs-deferred-lighting (render-target bytes written and read per pixel and
//! per lit pixel, i.e. per lighting computation; blending counts as a read and a write; vertex
//! and material data excluded) plus the Forward+ paper's Table 1 evaluated with a frame's
//! actual lights per tile. The R32Float lighting-count target is a statistics aid and is not
//! counted.

use serde::{Deserialize, Serialize};

/// One render target (or per-pixel buffer) of a pipeline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TargetBytes {
    /// The target's short name (e.g. `hdr`, `depth`).
    pub name: String,
    /// Bytes the target holds per pixel, all MSAA samples included.
    pub bytes_per_pixel: u32,
}

/// The blog's traffic model, in bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Traffic {
    /// Bytes written per pixel whatever its lights (e.g. depth, G-buffer, final colour).
    pub write_per_pixel: u32,
    /// Bytes read per pixel whatever its lights (e.g. the G-buffer read back once).
    pub read_per_pixel: u32,
    /// Per lighting computation (a lit pixel, counted once per light).
    pub write_per_lit: u32,
    /// Bytes read per lighting computation (light data, list indices, re-read targets).
    pub read_per_lit: u32,
}

/// A pipeline's memory footprint and traffic model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MemoryModel {
    /// The pipeline's render targets and per-pixel buffers.
    pub targets: Vec<TargetBytes>,
    /// The pipeline's traffic model.
    pub traffic: Traffic,
}

impl MemoryModel {
    /// A model from `(name, bytes per pixel)` pairs, one sample per pixel (see
    /// [`MemoryModel::multisampled`]).
    pub fn new(targets: &[(&str, u32)], traffic: Traffic) -> Self {
        MemoryModel {
            targets: targets
                .iter()
                .map(|(n, b)| TargetBytes {
                    name: n.to_string(),
                    bytes_per_pixel: *b,
                })
                .collect(),
            traffic,
        }
    }

    /// The model with every target holding `samples` samples per pixel (tiled-forward-shading
    /// Fig. 4.4: MSAA multiplies the targets and the per-pixel traffic).
    pub fn multisampled(mut self, samples: u32) -> Self {
        for t in &mut self.targets {
            t.bytes_per_pixel *= samples;
        }
        self.traffic.write_per_pixel *= samples;
        self.traffic.read_per_pixel *= samples;
        self
    }

    /// Bytes per pixel of all targets together.
    pub fn bytes_per_pixel(&self) -> u32 {
        self.targets.iter().map(|t| t.bytes_per_pixel).sum()
    }

    /// Bytes of all targets at `width` × `height` pixels (saturating).
    pub fn target_bytes(&self, width: u32, height: u32) -> u64 {
        u64::from(self.bytes_per_pixel())
            .saturating_mul(u64::from(width))
            .saturating_mul(u64::from(height))
    }
}

/// Bytes of the HDR colour target (RGBA16F).
pub const HDR_BYTES: u32 = 8;
/// Bytes of the scene depth (32-bit float).
pub const DEPTH_BYTES: u32 = 4;
/// Bytes of one light in the global light list as shading reads it (`GpuLight`: the paper's
/// L = 8 floats of a point light, plus the spot cone; culling's bounding spheres are apart).
pub const LIGHT_BYTES: u32 = std::mem::size_of::<crate::gpu_types::GpuLight>() as u32;
/// Bytes of one light index in a grid list.
pub const INDEX_BYTES: u32 = 4;

/// Memory of a frame as reported in the stats.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameMemory {
    /// The pipeline's render targets at the frame's MSAA sample count.
    pub targets: Vec<TargetBytes>,
    /// Bytes per pixel of all targets together.
    pub bytes_per_pixel: u32,
    /// Bytes of all targets at the frame's size.
    pub target_bytes: u64,
    /// Bytes of the frame's light grid (cells + index lists, and each cell's 48-byte culling
    /// record with `--depth-mask on` or `--cell-box on`), if any.
    pub grid_bytes: Option<u64>,
    /// The pipeline's traffic model (per-pixel terms scaled by the MSAA sample count).
    pub traffic: Traffic,
    /// The traffic model applied to this frame's pixels and lighting computations.
    pub modelled_write_bytes: Option<u64>,
    /// Bytes read in the frame by the traffic model: `read_per_pixel` × pixels plus
    /// `read_per_lit` × the opaque passes' lighting computations (None where not countable).
    pub modelled_read_bytes: Option<u64>,
    /// Forward+ Table 1 with this frame's M (average lights per tile), when a grid exists.
    pub forward_plus_table1: Option<ForwardPlusTable1>,
}

/// Forward+ (forward-plus §3, Table 1): total memory traffic of Forward+ and of compute-based
/// deferred lighting, N pixels, F = 4-byte floats, M lights per tile, T pixels per tile,
/// L = 8 floats per light.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ForwardPlusTable1 {
    /// M: average lights per cell of the frame's grid (tile, or cluster).
    pub m: f64,
    /// T: pixels per tile (tile edge squared).
    pub t: u32,
    /// Forward+'s traffic for the frame in bytes: N·F + M·N·F·(1/T + 1 + L).
    pub forward_plus_bytes: f64,
    /// Compute-based deferred lighting's traffic for the frame in bytes: 16·N·F.
    pub deferred_bytes: f64,
}

impl ForwardPlusTable1 {
    /// Table 1 for `pixels` pixels (N), `lights_per_tile` (M) and a tile edge of `tile_size`
    /// pixels.
    pub fn new(pixels: u64, lights_per_tile: f64, tile_size: u32) -> Self {
        let (n, f, l) = (pixels as f64, 4.0, 8.0);
        let t = tile_size * tile_size;
        ForwardPlusTable1 {
            m: lights_per_tile,
            t,
            forward_plus_bytes: n * f + lights_per_tile * n * f * (1.0 / t as f64 + 1.0 + l),
            deferred_bytes: n * f * 16.0,
        }
    }
}
