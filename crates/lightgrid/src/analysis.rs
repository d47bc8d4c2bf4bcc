//! Analysis: what only a measuring run asks for (`render --stats`, `compare`, `bench`, the
//! tests), never the real-time path. The frame's image, depth and lighting counts are copied
//! out in the frame's own submission (`AnalysisReadbacks`); after the wait the ideal count
//! is computed on the CPU, the grid the pipeline shaded with is downloaded
//! (`LightCuller::download`) and everything lands in [`FrameStats`].

use crate::culling::{
    assign_cpu, cell_bounds_cpu_samples, ideal_fragment_counts, ideal_pixel_counts, DepthRange,
    GridDims, GridLists, LightGrid, ViewSetup,
};
use crate::error::Result;
use crate::frame::{FinishedFrame, FrameIo, RenderSettings};
use crate::memory::{ForwardPlusTable1, FrameMemory, MemoryModel};
use crate::passes::{BufferReadback, DepthBits, DepthSamples, Readback, Targets};
use crate::pipelines::PipelineInfo;
use crate::scene::{rasterize, FrameState, Light};
use crate::stats::{FrameStats, TimingSource};
use glam::Vec3;
use image::RgbaImage;

/// An image, its statistics, and what the analysis saw.
pub struct FrameOutput {
    /// The rendered frame, tonemapped to 8-bit sRGB RGBA.
    pub image: RgbaImage,
    /// The frame's statistics (what `render --stats` writes).
    pub stats: FrameStats,
    /// The grid the pipeline shaded with; for pipelines that build none, the depth-bounded
    /// CPU tile grid used for the ideal count (see `grid_is_pipelines`).
    pub grid: LightGrid,
    /// True when `grid` is the pipeline's own; false when it is the CPU tile grid of the
    /// ideal count (the pipeline builds no grid).
    pub grid_is_pipelines: bool,
    /// The cell bounds the pipeline's light assignment read (`culling::cell_bounds_cpu` is
    /// their CPU twin); None for pipelines without a grid.
    pub cell_bounds: Option<Vec<[f32; 2]>>,
    /// Each cell's 2.5D depth mask (`culling::NO_MASK` everywhere unless `--depth-mask on`);
    /// None for pipelines without a grid.
    pub cell_culls: Option<Vec<crate::culling::CellCull>>,
    /// The frame's depth buffer (row-major, reversed-Z: `crate::depth`); with MSAA its sample 0.
    pub depth: Vec<f32>,
    /// Every sample of the depth buffer, one plane per sample (one plane without MSAA).
    pub depth_samples: Vec<Vec<f32>>,
    /// Per pixel, the lighting computations of every pass (None where not countable).
    pub counts: Option<Vec<u32>>,
    /// Per pixel, the ideal of [`FrameStats::ideal_lighting_computations`]: the lights
    /// reaching its visible sample (averaged over its samples with MSAA) and each
    /// transparent fragment in front of it.
    pub ideal_counts: Vec<f32>,
    /// The frame's camera and size.
    pub setup: ViewSetup,
}

/// Where a frame's per-pixel lighting counts are read from: the count target, or with MSAA
/// the per-pixel counts after the frame counters (`gpu/counters.rs`).
enum CountsReadback {
    Target(Readback),
    Pixels(BufferReadback),
}

impl CountsReadback {
    fn new(device: &wgpu::Device, label: &str, (width, height): (u32, u32), samples: u32) -> Self {
        if samples > 1 {
            CountsReadback::Pixels(BufferReadback::new(
                device,
                label,
                u64::from(width) * u64::from(height) * 4,
            ))
        } else {
            CountsReadback::Target(Readback::new(device, label, width, height))
        }
    }

    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &Targets,
        counters: &wgpu::Buffer,
    ) {
        match self {
            CountsReadback::Target(r) => {
                r.encode(encoder, &targets.counts_texture, wgpu::TextureAspect::All)
            }
            CountsReadback::Pixels(r) => {
                r.encode_from(encoder, counters, crate::gpu::COUNTER_BYTES)
            }
        }
    }

    /// Per pixel, the lighting computations (waits for the GPU).
    fn read(&self, device: &wgpu::Device) -> Result<Vec<u32>> {
        Ok(match self {
            CountsReadback::Target(r) => r.read_f32(device)?.iter().map(|&c| c as u32).collect(),
            CountsReadback::Pixels(r) => r.read(device)?,
        })
    }
}

/// Where the depth of every sample is read from: the depth target, or with MSAA a copy of
/// every sample.
enum DepthReadback {
    Target(Readback),
    Samples(DepthSamples),
    /// Drawn into a copyable target first (GL: `DepthBits`).
    Drawn(DepthBits),
}

/// The staging buffers an analysis frame copies its image, counts and depth into.
pub(crate) struct AnalysisReadbacks {
    image: Readback,
    counts: CountsReadback,
    /// The counts before the transparent pass (frames with transparent objects).
    opaque_counts: CountsReadback,
    depth: DepthReadback,
}

impl AnalysisReadbacks {
    /// Depth is drawn into a copyable target first where the device cannot copy depth
    /// textures to buffers (`DownlevelFlags::DEPTH_TEXTURE_AND_BUFFER_COPIES`; not GL).
    pub fn new(ctx: &crate::gpu::GpuContext, (width, height): (u32, u32), samples: u32) -> Self {
        let device = &ctx.device;
        let depth_copies = ctx
            .downlevel()
            .contains(wgpu::DownlevelFlags::DEPTH_TEXTURE_AND_BUFFER_COPIES);
        let size = (width, height);
        AnalysisReadbacks {
            image: Readback::new(device, "image readback", width, height),
            counts: CountsReadback::new(device, "counts readback", size, samples),
            opaque_counts: CountsReadback::new(device, "opaque counts readback", size, samples),
            depth: if samples > 1 {
                DepthReadback::Samples(DepthSamples::new(device, size, samples))
            } else if !depth_copies {
                DepthReadback::Drawn(DepthBits::new(device, size))
            } else {
                DepthReadback::Target(Readback::new(device, "depth readback", width, height))
            },
        }
    }

    /// Record the copy of the counts the opaque passes made (before the transparent pass),
    /// so the transparent pass's share of the lighting computations is known.
    pub fn encode_opaque_counts(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &Targets,
        counters: &wgpu::Buffer,
    ) {
        self.opaque_counts.encode(encoder, targets, counters);
    }

    /// Record the copies (after the tonemap).
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        targets: &Targets,
        counters: &wgpu::Buffer,
    ) {
        let all = wgpu::TextureAspect::All;
        self.image.encode(encoder, &targets.ldr_texture, all);
        self.counts.encode(encoder, targets, counters);
        match &self.depth {
            DepthReadback::Target(r) => r.encode(
                encoder,
                &targets.depth_texture,
                wgpu::TextureAspect::DepthOnly,
            ),
            DepthReadback::Samples(d) => d.encode(device, encoder, &targets.depth),
            DepthReadback::Drawn(d) => d.encode(device, encoder, &targets.depth),
        }
    }

    /// One plane of depth-buffer values per sample (waits for the GPU).
    fn read_depth(&self, device: &wgpu::Device) -> Result<Vec<Vec<f32>>> {
        match &self.depth {
            DepthReadback::Target(r) => Ok(vec![r.read_f32(device)?]),
            DepthReadback::Samples(d) => d.read(device),
            DepthReadback::Drawn(d) => Ok(vec![d.read(device)?]),
        }
    }
}

/// The memory section of the stats: the pipeline's model applied to this frame.
fn frame_memory(
    model: MemoryModel,
    (width, height): (u32, u32),
    lighting_computations: Option<u64>,
    grid: Option<&LightGrid>,
    culled: bool,
) -> FrameMemory {
    let pixels = u64::from(width) * u64::from(height);
    let t = model.traffic;
    let modelled = |per_pixel: u32, per_lit: u32| {
        lighting_computations.map(|n| u64::from(per_pixel) * pixels + u64::from(per_lit) * n)
    };
    FrameMemory {
        bytes_per_pixel: model.bytes_per_pixel(),
        target_bytes: model.target_bytes(width, height),
        // With 2.5D masks or tight boxes, each cell's culling record is part of the grid.
        grid_bytes: grid.map(|g| {
            let record = if culled {
                std::mem::size_of::<crate::culling::CellCull>()
            } else {
                0
            };
            g.stored_bytes() + (g.cells.len() * record) as u64
        }),
        modelled_write_bytes: modelled(t.write_per_pixel, t.write_per_lit),
        modelled_read_bytes: modelled(t.read_per_pixel, t.read_per_lit),
        forward_plus_table1: grid
            .map(|g| ForwardPlusTable1::new(pixels, g.average_lights_per_cell(), g.dims.tile_size)),
        targets: model.targets,
        traffic: t,
    }
}

impl FrameOutput {
    /// The view distance of every pixel's visible sample (infinite for none).
    pub fn view_distances(&self) -> Vec<f32> {
        self.setup.view_distances(&self.depth)
    }
}

/// What [`analyze`] works from: a finished, waited-for analysis frame.
pub(crate) struct AnalysisInput<'r> {
    pub device: &'r wgpu::Device,
    /// `GpuContext::count_blend`: forward pipelines count lighting where it is true.
    pub count_blend: bool,
    /// `GpuContext::adapter_label`.
    pub adapter: &'r str,
    pub size: (u32, u32),
    pub dims: GridDims,
    pub settings: RenderSettings,
    pub readbacks: &'r AnalysisReadbacks,
    pub scene_name: &'r str,
    pub info: &'static PipelineInfo,
    pub up_state: &'r FrameState,
    /// The frame's transparent triangles (world space), drawn after the opaque image.
    pub transparent: Vec<[Vec3; 3]>,
    pub setup: ViewSetup,
    pub triangles: u32,
    pub finished: FinishedFrame,
    pub grid: Option<BuiltGrid>,
    pub io: FrameIo,
    pub reruns: u32,
    pub wall_ms: f64,
    /// The technique resolved MSAA inside its kernel (wrote the display target itself).
    pub resolved_in_kernel: bool,
    /// Lights lit without shadows (`--shadow-lights`).
    pub unshadowed: u32,
    /// With `--shadows maps`: the maps' texture bytes, a face's side, re-used or not.
    pub shadow_maps: Option<crate::stats::ShadowMapStats>,
}

impl AnalysisInput<'_> {
    /// The frame's GPU time: its timestamps, or the wall clock where there are none.
    fn timing(&self) -> (f64, TimingSource) {
        match self.finished.gpu_ms {
            Some(ms) => (ms, TimingSource::GpuTimestamps),
            None => (self.wall_ms, TimingSource::WallClock),
        }
    }

    /// Where an MSAA deferred kernel resolved, for frames shaded per sample.
    fn msaa_resolve(&self) -> Option<crate::frame::MsaaResolve> {
        self.finished.msaa_shading.map(|_| {
            if self.resolved_in_kernel {
                crate::frame::MsaaResolve::Kernel
            } else {
                crate::frame::MsaaResolve::Separate
            }
        })
    }

    /// The frame's memory: the targets, the traffic of `opaque` lighting computations, the
    /// pipeline's own grid (and its cells' culling records where 2.5D masks or boxes are on).
    fn memory(&self, opaque: Option<u64>, grid: Option<&LightGrid>) -> FrameMemory {
        let grid_settings = self.settings.grid;
        frame_memory(
            self.info.memory_model(&self.settings),
            self.size,
            opaque,
            grid,
            self.info.depth_bounds
                && self.info.assign
                && (grid_settings.depth_mask == crate::frame::DepthMask::On
                    || grid_settings.cell_box == crate::frame::CellBox::On),
        )
    }
}

/// A pipeline's grid as its culler built it (read back after the frame's report).
pub(crate) struct BuiltGrid {
    pub grid: LightGrid,
    /// The cell bounds the assignment read (view distance, `[min, max]`, min > max = empty).
    pub cell_bounds: Vec<[f32; 2]>,
    /// Each cell's 2.5D depth mask and tight box (neither unless `--depth-mask on` /
    /// `--cell-box on`).
    pub cell_culls: Vec<crate::culling::CellCull>,
    /// The strategy that ran (`auto` resolved).
    pub assign: crate::frame::Assign,
    /// CPU time of the assignment itself: `assign_cpu`, or the BVH build.
    pub cpu_ms: f64,
}

impl BuiltGrid {
    /// The last frame of `culler`, whose report is `report` (waits for the GPU).
    pub(crate) fn read(
        culler: &crate::culling::LightCuller,
        report: &crate::culling::CullReport,
    ) -> crate::error::Result<Self> {
        let error = |e: crate::culling::CullError| crate::error::Error::Gpu {
            stage: "grid download".into(),
            message: e.to_string(),
        };
        Ok(BuiltGrid {
            grid: culler.read_grid().map_err(error)?,
            cell_bounds: culler.read_cell_bounds().map_err(error)?,
            cell_culls: culler.read_cell_culls().map_err(error)?,
            assign: report.assign,
            cpu_ms: report.cpu_ms,
        })
    }
}

/// What the frame's grid statistics describe: the pipeline's own grid, its cell bounds and
/// culling records, the strategy that ran and its CPU time; or, for a pipeline without a
/// grid, the depth-bounded CPU grid of the ideal count.
#[allow(clippy::type_complexity)]
fn shaded_grid(
    built: Option<BuiltGrid>,
    bounded: LightGrid,
) -> (
    LightGrid,
    Option<Vec<[f32; 2]>>,
    Option<Vec<crate::culling::CellCull>>,
    Option<String>,
    Option<f64>,
) {
    match built {
        Some(b) => (
            b.grid,
            Some(b.cell_bounds),
            Some(b.cell_culls),
            Some(b.assign.name().to_string()),
            Some(b.cpu_ms),
        ),
        None => (bounded, None, None, None, None),
    }
}

/// Per pixel, the lighting computations of every pass (None where not countable), their
/// sum, and the opaque passes' and the transparent pass's shares.
struct Counts {
    counts: Option<Vec<u32>>,
    all: Option<u64>,
    opaque: Option<u64>,
    transparent: Option<u64>,
}

impl Counts {
    fn read(a: &AnalysisInput, samples: u64) -> Result<Counts> {
        let sum = |counts: &[u32]| counts.iter().map(|&c| u64::from(c)).sum::<u64>();
        // Counted by the count target where it can blend, always with MSAA (the per-pixel counts after the frame counters).
        let countable = a.count_blend || samples > 1;
        let counts = if countable {
            Some(a.readbacks.counts.read(a.device)?)
        } else {
            None
        };
        let lighting_computations = counts.as_deref().map(sum);
        // The opaque passes' share (the counts before the transparent pass) and the transparent
        // pass's (the rest). The traffic models describe the opaque pipeline (a lit pixel is a
        // lighting computation of its deferred or forward pass); the transparent pass,
        // forward-shaded by every pipeline, is outside them.
        let opaque_lighting_computations = match lighting_computations {
            Some(all) if !a.transparent.is_empty() => {
                Some(sum(&a.readbacks.opaque_counts.read(a.device)?).min(all))
            }
            all => all,
        };
        let transparent_lighting_computations = lighting_computations
            .zip(opaque_lighting_computations)
            .map(|(all, opaque)| all - opaque);
        Ok(Counts {
            counts,
            all: lighting_computations,
            opaque: opaque_lighting_computations,
            transparent: transparent_lighting_computations,
        })
    }
}

/// The ideal of a frame: for each visible sample and each transparent fragment in front of
/// it, the lights reaching it. The depth-bounded CPU grid (with transparent lists when there
/// are transparent fragments) narrows the search: it provably contains every such light.
/// With MSAA the ideal is still one computation per light per pixel (MSAA shades once per
/// pixel and surface): the average over the pixel's samples of the lights reaching each (at
/// the pixel's centre ray, the sample's depth).
struct Ideal {
    /// The depth-bounded CPU grid the search went through.
    bounded: LightGrid,
    /// The transparent fragments, rasterized on the CPU.
    fragments: Vec<crate::scene::Fragment>,
    /// Per pixel: the opaque ideal averaged over the samples, plus the transparent fragments'.
    counts: Vec<f32>,
    /// The frame's ideal lighting computations, and the transparent fragments' share.
    total: u64,
    transparent: u64,
}

impl Ideal {
    fn of(
        setup: &ViewSetup,
        dims: GridDims,
        lights: &[Light],
        transparent: &[[Vec3; 3]],
        depth_samples: &[Vec<f32>],
    ) -> Ideal {
        let samples = depth_samples.len() as u64;
        // The ideal: for each visible sample and each transparent fragment in front of it, the
        // lights reaching it. The depth-bounded CPU grid (with transparent lists when there are
        // transparent fragments) narrows the search: it provably contains every such light.
        // With MSAA the ideal is still one computation per light per pixel (MSAA shades once per
        // pixel and surface): the average over the pixel's samples of the lights reaching each
        // (at the pixel's centre ray, the sample's depth).
        // Per sample plane, each pixel's view distance (plane 0: the pixel's visible sample).
        let distances: Vec<Vec<f32>> = depth_samples
            .iter()
            .map(|plane| setup.view_distances(plane))
            .collect();
        let fragments = rasterize(setup, transparent, &distances[0]);
        let ideal_dims = if fragments.is_empty() {
            dims
        } else {
            dims.with_lists(GridLists::Separate)
        };
        let planes: Vec<&[f32]> = depth_samples.iter().map(Vec::as_slice).collect();
        let bounds = cell_bounds_cpu_samples(setup, &ideal_dims, &planes);
        let bounded = assign_cpu(setup, &ideal_dims, lights, DepthRange::Cells(&bounds));
        let fragment_ideal = ideal_fragment_counts(setup, &bounded, lights, &fragments);
        let ideal_transparent: u64 = fragment_ideal.iter().map(|&n| u64::from(n)).sum();
        // Per pixel: the opaque ideal averaged over the samples, plus the transparent fragments'.
        let mut ideal_counts = vec![0f32; (setup.width * setup.height) as usize];
        let mut ideal_opaque = 0u64;
        for d in &distances {
            for (acc, n) in ideal_counts
                .iter_mut()
                .zip(ideal_pixel_counts(setup, &bounded, lights, d))
            {
                ideal_opaque += u64::from(n);
                *acc += n as f32 / samples as f32;
            }
        }
        for (f, &n) in fragments.iter().zip(&fragment_ideal) {
            ideal_counts[(f.y * setup.width + f.x) as usize] += n as f32;
        }
        Ideal {
            bounded,
            fragments,
            counts: ideal_counts,
            total: (ideal_opaque + samples / 2) / samples + ideal_transparent,
            transparent: ideal_transparent,
        }
    }
}

/// Read the frame's copies back and compute its statistics.
pub(crate) fn analyze(mut a: AnalysisInput) -> Result<FrameOutput> {
    let (device, (width, height)) = (a.device, a.size);
    let (dims, settings) = (a.dims, a.settings);
    let lights = &a.up_state.lights;
    let image = a.readbacks.image.read(device)?;
    let image = RgbaImage::from_raw(width, height, image).expect("size matches");
    let depth_samples = a.readbacks.read_depth(device)?;
    let depth = depth_samples[0].clone();
    let samples = depth_samples.len() as u64;
    let Counts {
        counts,
        all: lighting_computations,
        opaque: opaque_lighting_computations,
        transparent: transparent_lighting_computations,
    } = Counts::read(&a, samples)?;
    let setup = a.setup;
    let Ideal {
        bounded,
        fragments,
        counts: ideal_counts,
        total: ideal,
        transparent: ideal_transparent,
    } = Ideal::of(&setup, dims, lights, &a.transparent, &depth_samples);
    let passes = std::mem::take(&mut a.finished.passes);
    let (gpu_ms, timing) = a.timing();
    let grid_is_pipelines = a.grid.is_some();
    let assign_gpu_ms = a.finished.assign_gpu_ms.filter(|_| grid_is_pipelines);
    let (grid, cell_bounds, cell_culls, assign, assign_cpu_ms) =
        shaded_grid(a.grid.take(), bounded);
    // The strategy's cost: its GPU passes and its CPU work (a wait for the GPU, which `cpu`
    // with depth bounds makes, is the frame's `cpu_wait_ms`: it also covers the passes before).
    let assign_ms = assign_cpu_ms.map(|cpu| cpu + assign_gpu_ms.unwrap_or(0.0));
    let memory = a.memory(
        opaque_lighting_computations,
        grid_is_pipelines.then_some(&grid),
    );
    Ok(FrameOutput {
        image,
        stats: FrameStats {
            scene: a.scene_name.to_string(),
            pipeline: a.info.id.to_string(),
            adapter: a.adapter.to_string(),
            width,
            height,
            frame: a.up_state.frame,
            lights: lights.len() as u32,
            triangles: a.triangles,
            gpu_ms,
            timing,
            wall_ms: a.wall_ms,
            cpu_wait_ms: a.io.cpu_wait_ms,
            submits: a.io.submits,
            readback_bytes: a.io.readback_bytes,
            truncated_loops: a.finished.truncated_loops,
            passes,
            tile_size: settings.grid.tile_size,
            gbuffer_bits: settings.gbuffer.bits(),
            msaa: settings.grid.samples,
            msaa_shading: a.finished.msaa_shading,
            fragments_off_bounds: a.finished.fragments_off_bounds,
            shadow_rays: (settings.shadows != crate::scene::Shadows::Off)
                .then_some(a.finished.shadow_rays),
            unshadowed_lights: (settings.shadows != crate::scene::Shadows::Off)
                .then_some(a.unshadowed),
            shadow_maps: a.shadow_maps,
            msaa_resolve: a.msaa_resolve(),
            lighting_computations,
            ideal_lighting_computations: ideal,
            transparent_fragments: fragments.len() as u64,
            transparent_lighting_computations,
            ideal_transparent_computations: ideal_transparent,
            efficiency: lighting_computations
                .filter(|&n| n > 0)
                .map(|n| ideal as f64 / n as f64),
            lights_per_tile_avg: grid_is_pipelines.then(|| grid.average_lights_per_cell()),
            lights_per_tile_max: grid_is_pipelines.then(|| grid.max_lights_per_cell()),
            tile_area_computations: grid.tile_area_computations().filter(|_| grid_is_pipelines),
            grid_indices: grid_is_pipelines.then_some(grid.indices.len() as u64),
            grid_cells: grid_is_pipelines.then_some(grid.cells.len() as u64),
            grid_cells_occupied: cell_bounds
                .as_ref()
                .map(|b| b.iter().filter(|[lo, hi]| lo <= hi).count() as u64),
            assign,
            assign_gpu_ms,
            assign_cpu_ms,
            assign_ms,
            assign_reruns: grid_is_pipelines.then_some(a.reruns),
            memory,
        },
        grid,
        grid_is_pipelines,
        cell_bounds,
        cell_culls,
        depth,
        depth_samples,
        counts,
        ideal_counts,
        setup,
    })
}
