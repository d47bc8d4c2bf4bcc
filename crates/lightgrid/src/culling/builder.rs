//! [`GridBuilder`]: how every grid-reading pipeline gets its light grid. One frame:
//! 1. the cell bounds (`cell_bounds.rs`): from the depth buffer on the GPU, or `[near, far]`
//!    for a pipeline without a depth pre-pass;
//! 2. light assignment by the strategy `--assign` names (resolved per frame for `auto`):
//!    - `cpu`: bounds read back, [`assign_cpu`], grid uploaded;
//!    - `gather`: one workgroup per cell tests every light (`gpu_assign.rs`);
//!    - `scatter`: one invocation per light emits (cell, light) pairs, radix sort by cell
//!      (`scatter.rs`);
//!    - `bvh`: the light hierarchy built on the CPU (`bvh.rs`), one workgroup per cell walks it;
//!    - `bvh-gpu`: the same hierarchy built on the GPU (`bvh_gpu.rs`), walked the same way;
//! 3. the grid is left in [`GridBuffers`] (group 1 of the shading pass) and read back for
//!    statistics and tests.

use super::bvh::{build_bvh, BvhBuffers};
use super::bvh_gpu::GpuBvhBuild;
use super::cell_bounds::CellBoundsPass;
use super::gpu_assign::{
    bvh_shader, gather_shader, read_grid, AssignCommon, AssignFrame, CellKernels, CellRun,
};
use super::scatter::ScatterPass;
use super::{assign_cpu, DepthRange, GridBuffers, GridDims, LightGrid};
use crate::error::Result;
use crate::gpu::bind_resources;
use crate::pipelines::{FrameEncoder, FrameInputs};
use std::time::Instant;

/// Who builds the light grid (`--assign`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Assign {
    /// On the CPU (`assign_cpu.rs`): projected sphere rectangles, per-cell depth test.
    Cpu,
    /// GPU gather: one workgroup per cell tests every light against the cell's frustum.
    Gather,
    /// GPU scatter: one invocation per light emits (cell, light) pairs, radix-sorted by cell.
    Scatter,
    /// Light BVH rebuilt each frame on the CPU, traversed on the GPU per cell.
    Bvh,
    /// Light BVH rebuilt each frame on the GPU (Morton codes, radix sort, node boxes),
    /// traversed as `Bvh`.
    #[serde(rename = "bvh-gpu")]
    BvhGpu,
    /// By light count: see [`Assign::resolve`].
    #[default]
    Auto,
}

/// On a hardware GPU, `auto` gathers up to this many lights and walks a GPU-built BVH above
/// (tiled-forward-shading §4.4: brute force holds to about 10k lights).
pub const AUTO_GATHER_MAX_LIGHTS: usize = 8192;

impl Assign {
    pub const ALL: [Assign; 6] = [
        Assign::Cpu,
        Assign::Gather,
        Assign::Scatter,
        Assign::Bvh,
        Assign::BvhGpu,
        Assign::Auto,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Assign::Cpu => "cpu",
            Assign::Gather => "gather",
            Assign::Scatter => "scatter",
            Assign::Bvh => "bvh",
            Assign::BvhGpu => "bvh-gpu",
            Assign::Auto => "auto",
        }
    }

    /// One line on how the strategy works (`lightgrid list`).
    pub fn description(self) -> &'static str {
        match self {
            Assign::Cpu => "CPU: projected sphere rectangles, per-cell depth test (rayon); grid uploaded",
            Assign::Gather => "GPU: one workgroup per occupied cell tests every light (forward-plus §4)",
            Assign::Scatter => "GPU: one thread per light emits (cell, light) pairs, radix-sorted by cell (forward-plus §4)",
            Assign::Bvh => "light BVH built on the CPU each frame, walked per occupied cell on the GPU (tiled-forward-shading §4.4)",
            Assign::BvhGpu => "the same BVH built on the GPU (Morton codes, radix sort), walked the same way",
            Assign::Auto => "software adapter: cpu; hardware GPU: gather up to 8192 lights, bvh-gpu above",
        }
    }

    /// The strategy used for a frame with `lights` lights. `auto` on a software adapter
    /// (lavapipe, which shares the CPU's cores) is `cpu` at every count: measured fastest from
    /// 1k to 1M lights (README, "Light assignment scaling"). On a hardware GPU it is `gather`
    /// up to [`AUTO_GATHER_MAX_LIGHTS`] and `bvh-gpu` above, which keeps the grid on the GPU
    /// (the paper's crossover; no hardware GPU was available to measure it).
    pub fn resolve(self, lights: usize, software_adapter: bool) -> Assign {
        match self {
            Assign::Auto if software_adapter => Assign::Cpu,
            Assign::Auto if lights <= AUTO_GATHER_MAX_LIGHTS => Assign::Gather,
            Assign::Auto => Assign::BvhGpu,
            other => other,
        }
    }
}

/// Where the cell bounds come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellSource {
    /// No depth information: every cell spans near..far (`tiled_forward`).
    NearFar,
    /// The frame's depth buffer (`targets.depth`), reduced on the GPU.
    Depth,
}

/// A built grid and what went into it.
pub struct BuiltGrid {
    pub grid: LightGrid,
    /// The cell bounds the assignment read (view distance, `[min, max]`, min > max = empty).
    pub cell_bounds: Vec<[f32; 2]>,
    /// The strategy that ran (`auto` resolved).
    pub assign: Assign,
    /// CPU time of the assignment itself: `assign_cpu`, or the BVH build.
    pub cpu_ms: f64,
    /// Wall time from the cell bounds being ready on the GPU to the grid being ready on the
    /// GPU: the whole strategy, GPU passes, CPU work and the syncs between them, but not
    /// the statistics readback.
    pub wall_ms: f64,
    /// Times a per-cell GPU strategy reran because the index buffer, sized from earlier
    /// frames, was too small (it is grown to fit first; nothing is dropped).
    pub reruns: u32,
}

pub struct GridBuilder {
    tiles: GridDims,
    slices: u32,
    source: CellSource,
    assign: Assign,
    software_adapter: bool,
    loop_budget: Option<u64>,
    pipeline: &'static str,
    scene_layout: wgpu::BindGroupLayout,
    bounds: CellBoundsPass,
    buffers: GridBuffers,
    common: Option<AssignCommon>,
    gather: Option<CellKernels>,
    bvh: Option<(CellKernels, BvhBuffers)>,
    bvh_gpu: Option<GpuBvhBuild>,
    scatter: Option<ScatterPass>,
}

impl GridBuilder {
    /// `slices` 1 builds a tiled grid, more a clustered one (slices between the camera's near
    /// and far planes each frame).
    /// `pipeline`: the id named in errors.
    pub fn new(
        ctx: &crate::pipelines::PipelineContext,
        pipeline: &'static str,
        slices: u32,
        source: CellSource,
    ) -> Self {
        let (device, scene_layout) = (ctx.device, ctx.scene_layout);
        GridBuilder {
            tiles: ctx.dims,
            slices,
            source,
            assign: ctx.settings.assign,
            software_adapter: ctx.software_adapter,
            loop_budget: ctx.loop_budget,
            pipeline,
            scene_layout: scene_layout.clone(),
            bounds: CellBoundsPass::new(device, scene_layout),
            buffers: GridBuffers::new(device),
            common: None,
            gather: None,
            bvh: None,
            bvh_gpu: None,
            scatter: None,
        }
    }

    /// Group 1 of the shading pass (`culling/light_grid.wgsl`).
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.buffers.layout
    }

    pub fn bind_group(&self) -> &wgpu::BindGroup {
        self.buffers.bind_group()
    }

    /// Refuse to shade when a cell's list is longer than the adapter lets one sample loop.
    fn check_loop_budget(&self, grid: &LightGrid) -> Result<()> {
        let longest = u64::from(grid.max_lights_per_cell());
        match self.loop_budget {
            Some(budget) if longest > budget => {
                Err(crate::Error::loop_budget(self.pipeline, longest, budget))
            }
            _ => Ok(()),
        }
    }

    /// The cell bounds this frame's assignment read: `[near, far]` everywhere, or those the
    /// GPU computed (downloaded; call after the frame's work is submitted).
    fn cell_bounds(&self, f: &FrameInputs, dims: &GridDims) -> Result<Vec<[f32; 2]>> {
        match self.source {
            CellSource::NearFar => Ok(vec![[f.setup.near, f.setup.far]; dims.cell_count()]),
            CellSource::Depth => self.bounds.read(f.device, f.queue),
        }
    }

    /// Build this frame's grid. With `CellSource::Depth`, `f.targets.depth` must hold the
    /// frame's depth in what `enc` has recorded so far.
    pub fn build(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<BuiltGrid> {
        let (device, queue) = (f.device, f.queue);
        let dims = if self.slices > 1 {
            self.tiles
                .clustered(self.slices, f.setup.near, f.setup.far)?
        } else {
            self.tiles
        };
        match self.source {
            CellSource::Depth => self.bounds.encode(f, enc, &dims),
            CellSource::NearFar => {
                self.bounds
                    .fill(device, queue, &dims, [f.setup.near, f.setup.far])
            }
        }
        let assign = self.assign.resolve(f.lights.len(), self.software_adapter);
        // Everything before assignment (the depth, the bounds) finishes outside the clock.
        enc.submit_and_wait()?;
        let wall = Instant::now();
        let mut cpu_ms = 0.0;
        let light_count = f.lights.len() as u32;
        let run = match assign {
            Assign::Cpu | Assign::Auto => {
                let bounds = self.cell_bounds(f, &dims)?;
                let start = Instant::now();
                let range = match self.source {
                    CellSource::NearFar => DepthRange::NearFar,
                    CellSource::Depth => DepthRange::Cells(&bounds),
                };
                let grid = assign_cpu(&f.setup, &dims, f.lights, range);
                cpu_ms = start.elapsed().as_secs_f64() * 1e3;
                self.check_loop_budget(&grid)?;
                self.buffers.upload(device, queue, &grid);
                enc.submit_and_wait()?;
                return Ok(BuiltGrid {
                    grid,
                    cell_bounds: bounds,
                    assign,
                    cpu_ms,
                    wall_ms: wall.elapsed().as_secs_f64() * 1e3,
                    reruns: 0,
                });
            }
            Assign::Gather | Assign::Bvh | Assign::BvhGpu => {
                let common = self.common.get_or_insert_with(|| AssignCommon::new(device));
                let scene_layout = &self.scene_layout;
                let (kernels, extra) = match assign {
                    Assign::Gather => {
                        let kernels = self.gather.get_or_insert_with(|| {
                            CellKernels::new(
                                device,
                                "gather",
                                &gather_shader(),
                                &[Some(scene_layout), Some(&common.layout)],
                            )
                        });
                        (&*kernels, None)
                    }
                    _ => {
                        let (kernels, buffers) = self.bvh.get_or_insert_with(|| {
                            let buffers = BvhBuffers::new(device);
                            let kernels = CellKernels::new(
                                device,
                                "bvh",
                                &bvh_shader(),
                                &[
                                    Some(scene_layout),
                                    Some(&common.layout),
                                    Some(&buffers.layout),
                                ],
                            );
                            (kernels, buffers)
                        });
                        let group = if assign == Assign::Bvh {
                            let start = Instant::now();
                            let bvh = build_bvh(&f.setup, f.lights);
                            cpu_ms = start.elapsed().as_secs_f64() * 1e3;
                            buffers.upload(device, queue, &bvh)
                        } else {
                            let build = self
                                .bvh_gpu
                                .get_or_insert_with(|| GpuBvhBuild::new(device, scene_layout));
                            build.encode(f, enc, &common.scan);
                            let (nodes, order) = build.buffers();
                            bind_resources(
                                device,
                                "light bvh (gpu build)",
                                &buffers.layout,
                                &[nodes.as_entire_binding(), order.as_entire_binding()],
                            )
                        };
                        (&*kernels, Some(group))
                    }
                };
                let frame = AssignFrame {
                    device,
                    queue,
                    scene: f.scene_bind_group,
                    common,
                    grid: &mut self.buffers,
                    bounds: &self.bounds,
                    dims: &dims,
                };
                kernels.run(frame, enc, &extra.iter().collect::<Vec<_>>())?
            }
            Assign::Scatter => {
                let common = self.common.get_or_insert_with(|| AssignCommon::new(device));
                let scatter = self
                    .scatter
                    .get_or_insert_with(|| ScatterPass::new(device, &self.scene_layout, common));
                let frame = AssignFrame {
                    device,
                    queue,
                    scene: f.scene_bind_group,
                    common,
                    grid: &mut self.buffers,
                    bounds: &self.bounds,
                    dims: &dims,
                };
                let total = scatter.run(frame, enc, light_count)?;
                CellRun { total, reruns: 0 }
            }
        };
        let wall_ms = wall.elapsed().as_secs_f64() * 1e3;
        let grid = read_grid(device, queue, &self.buffers, &dims, run.total)?;
        self.check_loop_budget(&grid)?;
        let cell_bounds = self.cell_bounds(f, &dims)?;
        Ok(BuiltGrid {
            grid,
            cell_bounds,
            assign,
            cpu_ms,
            wall_ms,
            reruns: run.reruns,
        })
    }
}
