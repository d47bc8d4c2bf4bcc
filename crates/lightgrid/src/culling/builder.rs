//! [`GridBuilder`]: how every grid-reading pipeline gets its light grid. One frame:
//! 0. for a clustered grid over the depth buffer, the depth range its slices are spread over
//!    (`depth_range.rs`: the samples' view distances, not near..far);
//! 1. the cell bounds (`cell_bounds.rs`): from the depth buffer on the GPU, or `[near, far]`
//!    for a pipeline without a depth pre-pass;
//! 2. light assignment by the strategy `--assign` names (resolved per frame for `auto`), one
//!    [`AssignStrategy`] per row of `registry.rs`: `cpu` (`assign_cpu.rs`, reads the
//!    bounds back: the papers' CPU pipeline), `gather` (`gather.rs`), `scatter` (`scatter.rs`),
//!    `bvh` (`bvh.rs`), `bvh-gpu` (`bvh_gpu.rs`), `zbin` (`zbin.rs`: the grid z-binned, sorted
//!    lights with per-slice ranges and per-tile masks, instead of per-cell lists; the
//!    strategy's `shape` marks the grid so); the GPU ones record into the frame's one
//!    submission;
//! 3. the grid is left in [`GridBuffers`] (group 1 of the shading pass). Analysis downloads it
//!    ([`GridBuilder::download`]); rendering alone never does.

use crate::culling::bounds::cell_bounds::CellBoundsPass;
use crate::culling::bounds::depth_range::DepthRangePass;
pub use crate::culling::frame::CellSource;
use crate::culling::frame::CullFrame;
use crate::culling::grid::{GridBuffers, GridDims, GridLists, LightGrid};
use crate::culling::strategies::registry::find_strategy;
use crate::culling::strategies::{AssignFrame, AssignStrategy, StrategyContext};
use crate::error::{Error, Result};
use crate::frame::{Assign, CullConfig, FrameEncoder};
use crate::gpu::CounterValues;

/// The cells of the last recorded frame (analysis).
pub(crate) struct BuiltCells {
    /// The cell bounds the assignment read (view distance, `[min, max]`, min > max = empty).
    pub cell_bounds: Vec<[f32; 2]>,
    /// Each cell's 2.5D depth mask and tight box (`cell_box.rs`; neither unless
    /// `--depth-mask on` / `--cell-box on`).
    pub cell_culls: Vec<crate::culling::bounds::cell_box::CellCull>,
}

/// What the last recorded frame's assignment was.
struct LastFrame {
    dims: GridDims,
    assign: Assign,
    cpu_ms: f64,
    cpu_grid: Option<LightGrid>,
    cell_bounds: Option<Vec<[f32; 2]>>,
    cell_culls: Option<Vec<crate::culling::bounds::cell_box::CellCull>>,
    /// The camera's `[near, far]` (every cell's bounds without a depth pre-pass).
    near_far: [f32; 2],
    /// Where the frame's cell bounds came from.
    source: CellSource,
}

pub struct GridBuilder {
    tiles: GridDims,
    slices: u32,
    assign: Assign,
    lists: GridLists,
    software_adapter: bool,
    index_capacity: u64,
    cull_layout: wgpu::BindGroupLayout,
    bounds: CellBoundsPass,
    /// Step 0, for a clustered grid over the depth buffer.
    range: Option<DepthRangePass>,
    buffers: GridBuffers,
    /// Strategies created so far (on first use).
    strategies: Vec<(Assign, Box<dyn AssignStrategy>)>,
    last: Option<LastFrame>,
}

impl GridBuilder {
    /// The grid `config` describes over `tiles` (the frame's tile grid, one slice; the
    /// culler sets it per frame): `config.slices` 1 builds a tiled grid, more a clustered one
    /// (slices spread each frame over the samples' depth range, or between the camera's near
    /// and far planes without depth). `software_adapter`: `auto` picks `cpu` for frames that
    /// bring their lights on the CPU (`CullFrame::lights_on_cpu`).
    pub fn new(
        device: &wgpu::Device,
        cull_layout: &wgpu::BindGroupLayout,
        config: &CullConfig,
        tiles: GridDims,
        software_adapter: bool,
    ) -> Self {
        let index_capacity = u64::from(config.index_capacity);
        GridBuilder {
            tiles,
            slices: config.slices,
            assign: config.strategy,
            lists: config.lists,
            software_adapter,
            index_capacity,
            cull_layout: cull_layout.clone(),
            bounds: CellBoundsPass::new(
                device,
                cull_layout,
                crate::culling::bounds::cell_bounds::CellBoundsKey {
                    samples: config.samples,
                    depth_bounds: config.depth_bounds,
                    reduction: config.depth_reduction,
                    depth_mask: config.depth_mask,
                    cell_box: config.cell_box,
                },
                tiles.tile_size,
            ),
            range: (config.slices > 1)
                .then(|| DepthRangePass::new(device, cull_layout, config.samples)),
            buffers: GridBuffers::new(device, index_capacity),
            strategies: Vec::new(),
            last: None,
        }
    }

    /// Index entries of the last frame's grid where the CPU built it (`cpu`); `None` where
    /// the GPU counted them.
    pub(crate) fn last_cpu_entries(&self) -> Option<u32> {
        let grid = self.last.as_ref()?.cpu_grid.as_ref()?;
        Some(grid.indices.len() as u32)
    }

    /// The last recorded frame's strategy (`auto` resolved) and the CPU time of its
    /// assignment.
    pub(crate) fn last_assign(&self) -> Option<(Assign, f64)> {
        self.last.as_ref().map(|l| (l.assign, l.cpu_ms))
    }

    /// The layout of the MSAA fragment-bounds group (`None` without MSAA).
    pub(crate) fn fragments_layout(&self) -> Option<&wgpu::BindGroupLayout> {
        self.bounds.fragments_layout()
    }

    /// The screen size changed (`LightCuller`: a caller's viewport).
    pub(crate) fn set_tiles(&mut self, tiles: GridDims) {
        self.tiles = tiles;
    }

    /// Group 1 of the shading pass (`culling/grid/light_grid.wgsl`).
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.buffers.layout
    }

    pub fn bind_group(&self) -> &wgpu::BindGroup {
        self.buffers.bind_group()
    }

    /// How many times [`Self::bind_group`] has been replaced.
    pub(crate) fn generation(&self) -> u64 {
        self.buffers.generation()
    }

    /// Grow the grid's buffers now for `cells` cells and this grid's index capacity.
    pub(crate) fn reserve(&mut self, device: &wgpu::Device, cells: usize) -> Result<()> {
        crate::culling::frame::check_index_capacity(device, self.index_capacity, "reserve")?;
        self.buffers.reserve(device, cells, self.index_capacity);
        Ok(())
    }

    /// Create `assign`'s strategy now (`auto`: the one for few lights), so a device that
    /// cannot run it fails here rather than at the first frame.
    pub(crate) fn prepare(&mut self, device: &wgpu::Device) -> Result<()> {
        // `auto`: the strategy of small light counts; the other one at the first frame that
        // needs it (a device below WebGPU's default 8 storage buffers per stage may run
        // `gather`, 7, and not `bvh-gpu`, 8).
        let a = self.assign.resolve(0, self.software_adapter);
        self.strategy(device, a)?;
        Ok(())
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
                    cull_layout: &self.cull_layout,
                    index_capacity: self.index_capacity,
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

    /// Record this frame's grid. With `CellSource::Depth`, `f.depth` holds the frame's depth
    /// in what `enc` has recorded so far; a frame without one (a caller without a depth
    /// pre-pass) is bounded by near..far.
    pub fn build(&mut self, f: &CullFrame, enc: &mut FrameEncoder) -> Result<()> {
        let source = match f.depth {
            Some(_) => CellSource::Depth,
            None => CellSource::NearFar,
        };
        let dims = if self.slices > 1 {
            self.tiles
                .clustered(self.slices, f.setup.near, f.setup.far)?
        } else {
            self.tiles
        };
        // Cells spanning near..far already cover every transparent fragment.
        let dims = dims.with_lists(match source {
            CellSource::Depth if f.transparency => self.lists,
            _ => GridLists::Opaque,
        });
        let assign = self
            .assign
            .resolve(f.light_count, self.software_adapter && f.lights_on_cpu);
        let dims = self.strategy(f.device, assign)?.shape(dims, f.light_count);
        self.bounds.check_capacity(f.device, &dims)?;
        // The slicing range only over a depth buffer.
        let range = self.range.as_ref().filter(|_| source == CellSource::Depth);
        if let Some(range) = range {
            range.encode(
                f,
                enc,
                &dims,
                &[self.bounds.params_buffer(), self.buffers.params_buffer()],
            );
        }
        match source {
            CellSource::Depth => self.bounds.encode(f, enc, &dims),
            CellSource::NearFar => {
                self.bounds
                    .fill(f.device, f.queue, &dims, [f.setup.near, f.setup.far])
            }
        }
        // Disjoint borrows: the strategy list, the grid buffers and the bounds.
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
                range,
                dims: &dims,
                source,
            },
            enc,
        )?;
        self.buffers.encode_bounds(
            f.device,
            enc.parts().0,
            self.bounds.buffer(),
            dims.cell_count(),
        );
        self.last = Some(LastFrame {
            dims,
            assign,
            cpu_ms: run.cpu_ms,
            cpu_grid: run.cpu_grid,
            cell_bounds: run.cell_bounds,
            cell_culls: run.cell_culls,
            near_far: [f.setup.near, f.setup.far],
            source,
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

    /// The last recorded frame, or why there is none.
    fn last(&self) -> Result<&LastFrame> {
        self.last.as_ref().ok_or_else(|| Error::Gpu {
            stage: "grid download".into(),
            message: "no frame was recorded".into(),
        })
    }

    /// The last recorded frame's grid (waits for the GPU). `values` are that frame's
    /// counters.
    pub fn download(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        values: &CounterValues,
    ) -> Result<LightGrid> {
        let last = self.last()?;
        if let Some(g) = &last.cpu_grid {
            return Ok(g.clone());
        }
        let dims = match &self.range {
            // The GPU spread the slices: `last.dims` holds near..far.
            Some(range) if last.source == CellSource::Depth => {
                range.read(device, queue, &last.dims)?
            }
            _ => last.dims,
        };
        let strategy = self
            .strategies
            .iter()
            .find(|(a, _)| *a == last.assign)
            .map(|(_, s)| s)
            .expect("the last frame's strategy exists");
        strategy.read_grid(device, queue, &self.buffers, &dims, values)
    }

    /// The last recorded frame's cell bounds and culling records (analysis; waits for the
    /// GPU).
    pub fn download_cells(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<BuiltCells> {
        let last = self.last()?;
        let cell_bounds = match (&last.cell_bounds, last.source) {
            (Some(b), _) => b.clone(),
            (None, CellSource::NearFar) => {
                crate::culling::bounds::cell_bounds::slice_bounds(&last.dims, last.near_far)
            }
            (None, CellSource::Depth) => self.bounds.read(device, queue)?,
        };
        let cell_culls = match (&last.cell_culls, last.source) {
            (Some(m), _) => m.clone(),
            (None, CellSource::NearFar) => {
                vec![crate::culling::bounds::cell_box::NO_CULL; last.dims.cell_count()]
            }
            (None, CellSource::Depth) => self.bounds.read_culls(device, queue)?,
        };
        Ok(BuiltCells {
            cell_bounds,
            cell_culls,
        })
    }
}
