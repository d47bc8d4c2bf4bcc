//! `--assign zbin`: z-binning (Drobot 2017, "Improved culling for tiled and clustered
//! rendering"). Each frame the lights are sorted by view depth; each depth bin (the grid's
//! slices, so `--slices` sets their number) keeps the first and last sorted index of the
//! lights whose bounding sphere's depth span meets it; each screen tile keeps a bit mask over
//! the sorted lights whose bounding volume reaches its frustum over the depth range of its
//! cells' bounds. A sample shades the set bits of its tile's mask inside its bin's range
//! (`light_grid.wgsl`'s `zbin_shade`).
//!
//! Memory is `lights + tiles × ⌈lights/32⌉` words plus two per bin, whatever the number of
//! bins: a clustered grid's lists grow with its cells instead. The bins hold any view distance
//! (the first and last bins reach to 0 and infinity), so transparent fragments read the same
//! structure: no second list. GPU build: `zbin.wgsl` (keys, the radix sort shared with
//! scatter and the GPU BVH, bins, masks); CPU twin: [`zbins_cpu`], in the same f32 arithmetic.

use crate::consts::{ASSIGN_DEPTH_SLACK, ASSIGN_THREADS};
use crate::culling::frame::check_index_capacity;
use crate::culling::grid::{GridBuffers, GridDims, LightGrid, ZBins};
use crate::culling::strategies::assign_cpu::project_sphere;
use crate::culling::strategies::gather::{cpu_frustum, light_margin};
use crate::culling::strategies::radix_sort::RadixSort;
use crate::culling::strategies::scan::ScanPass;
use crate::culling::strategies::{AssignFrame, AssignStrategy, StrategyContext, StrategyRun};
use crate::error::Result;
use crate::frame::FrameEncoder;
use crate::gpu::{
    bind_resources, buffer_layout, download, groups_1d, CounterValues, STORAGE_READ, STORAGE_RW,
    UNIFORM,
};
use crate::scene::Light;
use crate::scene::ViewSetup;
use crate::shader::{compose, compute_pipeline, parts, src, ComposedShader};

pub(crate) fn shader() -> ComposedShader {
    compose(
        "zbin",
        &parts![
            src::TYPES,
            src::GRID_PARAMS,
            src::SCENE_BINDINGS,
            crate::culling::strategies::LIGHT_RECORDS_WGSL,
            crate::culling::strategies::TILE_FRUSTUM_WGSL,
            src::GRID_CELL,
            include_str!("light_tiles.wgsl"),
            include_str!("zbin.wgsl"),
        ],
    )
}

/// `ordered_bits` of `cell_box.wgsl`: the sort key of a float (order-preserving as u32).
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub(crate) fn ordered_bits(x: f32) -> u32 {
    let b = x.to_bits();
    if b & 0x8000_0000 != 0 {
        !b
    } else {
        b | 0x8000_0000
    }
}

/// The union of the bounds of tile `t`'s cells (every slice and layer); `[MAX, -MAX]` when
/// none holds a sample (as `masks_main` starts from).
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
fn tile_range(dims: &GridDims, cell_bounds: &[[f32; 2]], t: usize) -> [f32; 2] {
    let tiles = dims.tile_count();
    (0..dims.cell_count() / tiles)
        .map(|k| cell_bounds[k * tiles + t])
        .filter(|b| b[0] <= b[1])
        .fold([3.4e38f32, -3.4e38f32], |r, b| {
            [r[0].min(b[0]), r[1].max(b[1])]
        })
}

/// CPU twin of the GPU build: the same sort, bins and masks. `dims` is the grid's shape
/// (its slices are the bins), `cell_bounds` the bounds the cells were built with.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub fn zbins_cpu(
    setup: &ViewSetup,
    dims: &GridDims,
    lights: &[Light],
    cell_bounds: &[[f32; 2]],
) -> ZBins {
    let view: Vec<_> = lights.iter().map(|l| setup.to_view(l)).collect();
    let mut order: Vec<u32> = (0..lights.len() as u32).collect();
    order.sort_by_key(|&l| ordered_bits(-view[l as usize].center.z));
    let mut bins = vec![[u32::MAX, 0u32]; dims.slices as usize];
    let mut in_depth = vec![false; order.len()];
    for (i, &l) in order.iter().enumerate() {
        let v = &view[l as usize];
        let w = -v.center.z;
        let lo = (w - v.radius) * (1.0 - ASSIGN_DEPTH_SLACK);
        let hi = (w + v.radius) * (1.0 + ASSIGN_DEPTH_SLACK);
        if hi < setup.near * (1.0 - ASSIGN_DEPTH_SLACK)
            || lo > setup.far * (1.0 + ASSIGN_DEPTH_SLACK)
        {
            continue;
        }
        in_depth[i] = true;
        for b in &mut bins[dims.slice_of(lo) as usize..=dims.slice_of(hi) as usize] {
            b[0] = b[0].min(i as u32);
            b[1] = b[1].max(i as u32 + 1);
        }
    }
    // Each sorted light's tile rectangle (none for a light outside near..far), the masks'
    // pre-filter.
    let tile = dims.tile_size;
    let rects: Vec<Option<[u32; 4]>> = order
        .iter()
        .zip(&in_depth)
        .map(|(&l, &inside)| {
            let r = project_sphere(setup, &view[l as usize]).filter(|_| inside)?;
            Some([r.x0 / tile, r.x1 / tile, r.y0 / tile, r.y1 / tile])
        })
        .collect();
    let words = lights.len().div_ceil(32);
    let mut masks = vec![0u32; dims.tile_count() * words];
    for (t, mask) in masks.chunks_mut(words.max(1)).enumerate() {
        let f = cpu_frustum(setup, dims, t, tile_range(dims, cell_bounds, t));
        let (tx, ty) = (t as u32 % dims.tiles_x, t as u32 / dims.tiles_x);
        for (i, &l) in order.iter().enumerate() {
            let in_rect = rects[i]
                .is_some_and(|[x0, x1, y0, y1]| (x0..=x1).contains(&tx) && (y0..=y1).contains(&ty));
            if in_rect && light_margin(&f, &view[l as usize]) >= 0.0 {
                mask[i / 32] |= 1 << (i % 32);
            }
        }
    }
    ZBins {
        order,
        bins,
        words,
        masks,
    }
}

/// Index entries a z-binned grid of `lights` lights over `tiles` tiles holds.
fn entries(lights: u32, tiles: u32) -> u64 {
    u64::from(lights) + u64::from(tiles) * u64::from(lights.div_ceil(32))
}

struct ZBinStrategy {
    layout: wgpu::BindGroupLayout,
    keys: wgpu::ComputePipeline,
    bins: wgpu::ComputePipeline,
    masks: wgpu::ComputePipeline,
    sort: RadixSort,
    scan: ScanPass,
}

pub(super) fn create_strategy(ctx: &StrategyContext) -> Box<dyn AssignStrategy> {
    let device = ctx.device;
    let layout = buffer_layout(
        device,
        "zbin (group 1)",
        &[
            UNIFORM,
            STORAGE_READ,
            STORAGE_RW,
            STORAGE_RW,
            STORAGE_RW,
            STORAGE_RW,
        ],
    );
    let s = shader();
    let layouts = [Some(ctx.cull_layout), Some(&layout)];
    let pipeline =
        |entry: &str| compute_pipeline(device, &format!("zbin {entry}"), &s, entry, &layouts);
    Box::new(ZBinStrategy {
        keys: pipeline("keys_main"),
        bins: pipeline("bins_main"),
        masks: pipeline("masks_main"),
        layout,
        sort: RadixSort::new(device),
        scan: ScanPass::new(device),
    })
}

impl AssignStrategy for ZBinStrategy {
    fn shape(&self, dims: GridDims, lights: usize) -> GridDims {
        dims.with_zbins(lights as u32)
    }

    fn encode(&mut self, a: AssignFrame, enc: &mut FrameEncoder) -> Result<StrategyRun> {
        let (f, dims) = (a.f, a.dims);
        let device = f.device;
        let n = f.light_count as u32;
        let tiles = dims.tile_count() as u32;
        let total = entries(n, tiles);
        check_index_capacity(device, total, "zbin")?;
        a.grid
            .ensure(device, f.queue, dims, dims.cell_count(), total as usize);
        let (encoder, timer) = enc.parts();
        // Empty bins: (~first, end) = (0, 0). Only the bins are read (one per slice).
        encoder.clear_buffer(a.grid.cells_buffer(), 0, Some(u64::from(dims.slices) * 8));
        if n == 0 {
            return Ok(StrategyRun::default());
        }
        self.sort.ensure(device, u64::from(n));
        let group = bind_resources(
            device,
            "zbin",
            &self.layout,
            &[
                a.grid.params_buffer().as_entire_binding(),
                a.bounds.buffer().as_entire_binding(),
                a.grid.cells_buffer().as_entire_binding(),
                a.grid.indices_buffer().as_entire_binding(),
                self.sort.keys.as_entire_binding(),
                self.sort.vals.as_entire_binding(),
            ],
        );
        let run = |encoder: &mut wgpu::CommandEncoder,
                   timer: &mut crate::gpu::PassTimer,
                   pipeline: &wgpu::ComputePipeline,
                   label: &str,
                   (x, y): (u32, u32)| {
            let mut pass = timer.begin_compute(encoder, label);
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, f.bind_group, &[]);
            pass.set_bind_group(1, &group, &[]);
            pass.dispatch_workgroups(x, y, 1);
        };
        let per_light = groups_1d(n.div_ceil(ASSIGN_THREADS));
        run(encoder, timer, &self.keys, "assign: zbin keys", per_light);
        self.sort
            .encode(device, f.queue, encoder, timer, &self.scan, n, 32);
        encoder.copy_buffer_to_buffer(
            &self.sort.vals,
            0,
            a.grid.indices_buffer(),
            0,
            u64::from(n) * 4,
        );
        run(encoder, timer, &self.bins, "assign: zbin bins", per_light);
        let mask_words = u64::from(tiles) * u64::from(n.div_ceil(32));
        run(
            encoder,
            timer,
            &self.masks,
            "assign: zbin masks",
            groups_1d(mask_words.div_ceil(u64::from(ASSIGN_THREADS)) as u32),
        );
        Ok(StrategyRun::default())
    }

    fn grid_entries(&self, values: &CounterValues) -> u32 {
        values.index_needed()
    }

    fn read_grid(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        buffers: &GridBuffers,
        dims: &GridDims,
        _values: &CounterValues,
    ) -> Result<LightGrid> {
        let n = dims.zbin_lights.unwrap_or(0);
        let tiles = dims.tile_count() as u32;
        let cells = download(
            device,
            queue,
            buffers.cells_buffer(),
            u64::from(dims.slices) * 8,
        )?;
        let indices = download(
            device,
            queue,
            buffers.indices_buffer(),
            entries(n, tiles).max(1) * 4,
        )?;
        let cells: Vec<[u32; 2]> = bytemuck::pod_collect_to_vec(&cells);
        let mut indices: Vec<u32> = bytemuck::pod_collect_to_vec(&indices);
        indices.truncate(entries(n, tiles) as usize);
        let masks = indices.split_off(n as usize);
        let zbins = ZBins {
            order: indices,
            bins: cells.iter().map(|b| [!b[0], b[1]]).collect(),
            words: n.div_ceil(32) as usize,
            masks,
        };
        Ok(zbins.into_grid(*dims))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sort_keys_keep_the_order_of_floats() {
        let xs = [-1e30f32, -2.5, -0.0, 0.0, 1e-30, 0.5, 3.0, 1e30];
        for w in xs.windows(2) {
            assert!(ordered_bits(w[0]) <= ordered_bits(w[1]), "{w:?}");
        }
        assert!(ordered_bits(-2.5) < ordered_bits(-1.0));
        assert!(ordered_bits(1.0) < ordered_bits(2.0));
    }

    #[test]
    fn a_cell_reads_its_tiles_mask_within_its_bins_range() {
        // 2 tiles (16x8 at 8-px tiles), 2 bins, 40 lights: two mask words per tile.
        let dims = GridDims::new(16, 8, 8)
            .unwrap()
            .clustered(2, 1.0, 100.0)
            .unwrap()
            .with_zbins(40);
        let mut masks = vec![0u32; 4];
        masks[0] = 0b1011; // tile 0: sorted 0, 1, 3
        masks[1] = 1 << 3; // tile 0: sorted 35
        masks[2] = 0b0110; // tile 1: sorted 1, 2
        let z = ZBins {
            order: (0..40).rev().collect(),
            bins: vec![[1, 36], [u32::MAX, 0]],
            words: 2,
            masks,
        };
        // Bin 0 (cells 0, 1): sorted 1..36; bin 1 (cells 2, 3): empty.
        assert_eq!(z.cell_lights(&dims, 0), vec![38, 36, 4]);
        assert_eq!(z.cell_lights(&dims, 1), vec![38, 37]);
        assert!(z.cell_lights(&dims, 2).is_empty());
        assert!(z.cell_lights(&dims, 3).is_empty());
        assert_eq!(z.bytes(), (40 + 4 + 4) * 4);
    }
}
