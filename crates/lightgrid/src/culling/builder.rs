//! [`GridBuilder`]: how every grid-reading pipeline gets its light grid. One frame:
//! 1. the cell bounds (`cell_bounds.rs`): from the depth buffer on the GPU, or `[near, far]`
//!    for a pipeline without a depth pre-pass;
//! 2. light assignment by the strategy `--assign` names (resolved per frame for `auto`), one
//!    [`AssignStrategy`] per registry row in `strategy.rs`: `cpu` (`assign_cpu.rs`, reads the
//!    bounds back: the papers' CPU pipeline), `gather` (`gather.rs`), `scatter` (`scatter.rs`),
//!    `bvh` (`bvh.rs`), `bvh-gpu` (`bvh_gpu.rs`); the GPU ones record into the frame's one
//!    submission;
//! 3. the grid is left in [`GridBuffers`] (group 1 of the shading pass). Analysis downloads it
//!    ([`GridBuilder::download`]); rendering alone never does.

use super::cell_bounds::CellBoundsPass;
use super::gpu_assign::read_grid;
use super::strategy::{find_strategy, AssignFrame, AssignStrategy, StrategyContext};
use super::{GridBuffers, GridDims, LightGrid};
use crate::error::{Error, Result};
use crate::frame::{FrameEncoder, FrameInputs, PipelineContext};
use crate::gpu::CounterValues;

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

/// A built grid and what went into it (analysis).
pub struct BuiltGrid {
    pub grid: LightGrid,
    /// The cell bounds the assignment read (view distance, `[min, max]`, min > max = empty).
    pub cell_bounds: Vec<[f32; 2]>,
    /// The strategy that ran (`auto` resolved).
    pub assign: Assign,
    /// CPU time of the assignment itself: `assign_cpu`, or the BVH build.
    pub cpu_ms: f64,
}

/// What the last recorded frame's assignment was.
struct LastFrame {
    dims: GridDims,
    assign: Assign,
    cpu_ms: f64,
    cpu_grid: Option<LightGrid>,
    cell_bounds: Option<Vec<[f32; 2]>>,
    /// The camera's `[near, far]` (every cell's bounds without a depth pre-pass).
    near_far: [f32; 2],
}

pub struct GridBuilder {
    tiles: GridDims,
    slices: u32,
    source: CellSource,
    assign: Assign,
    software_adapter: bool,
    scene_layout: wgpu::BindGroupLayout,
    bounds: CellBoundsPass,
    buffers: GridBuffers,
    /// Strategies created so far (on first use).
    strategies: Vec<(Assign, Box<dyn AssignStrategy>)>,
    last: Option<LastFrame>,
}

impl GridBuilder {
    /// `slices` 1 builds a tiled grid, more a clustered one (slices between the camera's near
    /// and far planes each frame).
    pub fn new(ctx: &PipelineContext, slices: u32, source: CellSource) -> Self {
        let (device, scene_layout) = (ctx.device, ctx.scene_layout);
        GridBuilder {
            tiles: ctx.dims,
            slices,
            source,
            assign: ctx.settings.assign,
            software_adapter: ctx.software_adapter,
            scene_layout: scene_layout.clone(),
            bounds: CellBoundsPass::new(device, scene_layout),
            buffers: GridBuffers::new(device),
            strategies: Vec::new(),
            last: None,
        }
    }

    /// Group 1 of the shading pass (`culling/light_grid.wgsl`).
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.buffers.layout
    }

    pub fn bind_group(&self) -> &wgpu::BindGroup {
        self.buffers.bind_group()
    }

    fn strategy(
        &mut self,
        device: &wgpu::Device,
        assign: Assign,
    ) -> Result<&mut dyn AssignStrategy> {
        let i = match self.strategies.iter().position(|(a, _)| *a == assign) {
            Some(i) => i,
            None => {
                let info = find_strategy(assign).ok_or_else(|| {
                    Error::invalid(
                        "--assign",
                        format!("no strategy registered for {}", assign.name()),
                    )
                })?;
                let ctx = StrategyContext {
                    device,
                    scene_layout: &self.scene_layout,
                };
                let created = crate::gpu::scoped(
                    device,
                    &format!("creating the {} strategy", assign.name()),
                    || (info.create)(&ctx),
                )?;
                self.strategies.push((assign, created));
                self.strategies.len() - 1
            }
        };
        Ok(self.strategies[i].1.as_mut())
    }

    /// Record this frame's grid. With `CellSource::Depth`, `f.targets.depth` must hold the
    /// frame's depth in what `enc` has recorded so far.
    pub fn build(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<()> {
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
                    .fill(f.device, f.queue, &dims, [f.setup.near, f.setup.far])
            }
        }
        let assign = self.assign.resolve(f.lights.len(), self.software_adapter);
        let source = self.source;
        // Disjoint borrows: the strategy list, the grid buffers and the bounds.
        self.strategy(f.device, assign)?;
        let strategy = self
            .strategies
            .iter_mut()
            .find(|(a, _)| *a == assign)
            .map(|(_, s)| s.as_mut())
            .expect("created above");
        let run = strategy.encode(
            AssignFrame {
                f,
                grid: &mut self.buffers,
                bounds: &self.bounds,
                dims: &dims,
                source,
            },
            enc,
        )?;
        self.last = Some(LastFrame {
            dims,
            assign,
            cpu_ms: run.cpu_ms,
            cpu_grid: run.cpu_grid,
            cell_bounds: run.cell_bounds,
            near_far: [f.setup.near, f.setup.far],
        });
        Ok(())
    }

    /// A finished frame's counters: the strategy that built its grid sizes its lists from
    /// them.
    /// Every strategy created sees them (each reads only its own slots), so one that the
    /// frame did not use only grows harmlessly.
    pub fn observe(&mut self, device: &wgpu::Device, values: &CounterValues) -> Result<()> {
        for (_, s) in &mut self.strategies {
            s.observe(device, values)?;
        }
        Ok(())
    }

    /// The last recorded frame's grid and cell bounds (analysis; waits for the GPU). `values`
    /// are that frame's counters.
    pub fn download(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        values: &CounterValues,
    ) -> Result<BuiltGrid> {
        let last = self.last.as_ref().ok_or_else(|| Error::Gpu {
            stage: "grid download".into(),
            message: "no frame was recorded".into(),
        })?;
        let grid = match &last.cpu_grid {
            Some(g) => g.clone(),
            None => {
                let strategy = self
                    .strategies
                    .iter()
                    .find(|(a, _)| *a == last.assign)
                    .map(|(_, s)| s)
                    .expect("the last frame's strategy exists");
                read_grid(
                    device,
                    queue,
                    &self.buffers,
                    &last.dims,
                    strategy.grid_entries(values),
                )?
            }
        };
        let cell_bounds = match (&last.cell_bounds, self.source) {
            (Some(b), _) => b.clone(),
            (None, CellSource::NearFar) => {
                vec![last.near_far; last.dims.cell_count()]
            }
            (None, CellSource::Depth) => self.bounds.read(device, queue)?,
        };
        Ok(BuiltGrid {
            grid,
            cell_bounds,
            assign: last.assign,
            cpu_ms: last.cpu_ms,
        })
    }
}
