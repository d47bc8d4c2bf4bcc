//! Cell bounds: for every cell of the grid (a tile, or a tile × view-depth slice), the
//! view-distance `[min, max]` of the samples in it. This is the one input every light
//! assignment strategy (CPU, gather, scatter, BVH) reads besides the lights and the camera; a
//! cell without samples has `min > max` (`[+inf, 0]`) and receives no lights. For a tiled grid
//! these are the tile depth bounds of tiled-shading §6.3; for a clustered grid they are the
//! bounds of the samples inside each cluster (tighter than the slice's own range, and empty
//! for clusters holding no samples: tiled-forward-shading §4.8's "only occupied clusters").
//!
//! GPU kernel: `cell_bounds.wgsl`, one workgroup per tile. CPU twin: [`cell_bounds_cpu`].
//! Without a depth pre-pass (`tiled_forward`) every cell gets `[near, far]` instead.
//! `--depth-bounds` (`DepthBounds`) then opens one side of each occupied cell's bounds, or
//! both sides of every cell, to the cell's slice: twin [`open_bounds`].

use crate::consts::ASSIGN_DEPTH_SLACK;
use crate::culling::bounds::cell_box::{CellCull, NO_CULL};
use crate::culling::frame::CullFrame;
use crate::culling::grid::{GridDims, GridLists};
use crate::error::{Error, Result};
use crate::frame::{CellBox, DepthBounds, DepthMask, DepthReduction, FrameEncoder};
use crate::gpu::{bind_resources, download, grow_storage, storage_buffer};
use crate::scene::ViewSetup;
use crate::shader::{
    compute_pipeline, compute_pipeline_with, every_sample_count, msaa_defs, overrides, parts, src,
    Def, ShaderKey,
};

/// The cell-bounds kernel's variants: the depth target's samples, `--depth-bounds`
/// (`DEPTH_BOUNDS`) and `--depth-reduction` (`SUBGROUP_REDUCTION`: tiled-shading §8's
/// warp-level reduction, each invocation's samples in registers, one subgroup min/max, one
/// atomic per subgroup; the subgroup code is compiled in only then, as it is only composed for
/// an adapter with subgroups: the device feature; WGSL's `enable subgroups;` is left out,
/// which naga rejects).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct CellBoundsKey {
    pub samples: u32,
    pub depth_bounds: DepthBounds,
    pub reduction: DepthReduction,
    pub depth_mask: DepthMask,
    pub cell_box: CellBox,
}

impl CellBoundsKey {
    /// Does the kernel write culling records (`--depth-mask on` or `--cell-box on`)?
    pub fn culled(self) -> bool {
        self.depth_mask == DepthMask::On || self.cell_box == CellBox::On
    }
}

impl ShaderKey for CellBoundsKey {
    const STAGE: &'static str = "cell_bounds";

    fn all() -> Vec<Self> {
        let mut out = Vec::new();
        for samples in every_sample_count() {
            for depth_bounds in DepthBounds::ALL {
                for reduction in DepthReduction::ALL {
                    for depth_mask in DepthMask::ALL {
                        for cell_box in CellBox::ALL {
                            out.push(CellBoundsKey {
                                samples,
                                depth_bounds,
                                reduction,
                                depth_mask,
                                cell_box,
                            });
                        }
                    }
                }
            }
        }
        out
    }

    fn defs(self) -> Vec<Def> {
        let mut defs = msaa_defs(self.samples);
        defs.push(Def::U32("DEPTH_BOUNDS", self.depth_bounds.id()));
        defs.push(Def::Bool(
            "SUBGROUP_REDUCTION",
            self.reduction == DepthReduction::Subgroup,
        ));
        defs.push(Def::Bool("DEPTH_MASK", self.depth_mask == DepthMask::On));
        defs.push(Def::Bool("CELL_BOX", self.cell_box == CellBox::On));
        defs.push(Def::Bool("CELL_CULLS", self.culled()));
        defs
    }

    fn parts(self) -> Vec<&'static str> {
        parts![
            src::TYPES,
            src::GRID_PARAMS,
            src::SCENE_BINDINGS,
            src::GRID_CELL,
            src::MSAA,
            crate::culling::bounds::CELL_CULL_WGSL,
            include_str!("cell_bounds.wgsl"),
        ]
    }
}

/// `--depth-bounds` applied to the opaque cells' `bounds` (as the kernel's `open_bounds`
/// does): `Min` opens an occupied cell's far side to its slice's far end, `Max` its near
/// side to the slice's near end, `None` gives every cell (occupied or not) its slice's
/// whole range. Bounds only widen, so no light a cell's samples need is lost.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub fn open_bounds(
    setup: &ViewSetup,
    dims: &GridDims,
    depth_bounds: DepthBounds,
    bounds: &mut [[f32; 2]],
) {
    if depth_bounds == DepthBounds::Both {
        return;
    }
    for (cell, b) in bounds.iter_mut().enumerate().take(dims.layer_cells()) {
        let [lo, hi] = dims.slice_range(dims.slice_of_cell(cell));
        let span = [lo.max(setup.near), hi.min(setup.far)];
        *b = match depth_bounds {
            DepthBounds::Both => *b,
            DepthBounds::None => bounds_union(*b, span),
            _ if b[0] > b[1] => *b,
            DepthBounds::Min => [b[0], b[1].max(span[1])],
            DepthBounds::Max => [b[0].min(span[0]), b[1]],
        };
    }
}

/// Bytes of one cell's culling record (`CellCull`: mask and box).
const CULL_BYTES: usize = std::mem::size_of::<CellCull>();

/// The records of a grid without masks or boxes: one [`NO_CULL`], which every cell
/// reads (`cell_cull` in assign_bindings.wgsl clamps the index to the buffer), so such a grid
/// spends 48 bytes on them, not 48 per cell.
fn no_culls(device: &wgpu::Device) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("cell culls (none)"),
        contents: bytemuck::bytes_of(&NO_CULL),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
    })
}

/// The bounds of a cell without samples.
pub const EMPTY_CELL: [f32; 2] = [f32::INFINITY, 0.0];

/// CPU twin of the kernel: the same inputs (depth-buffer values in [0, 1], 1 = no sample,
/// row-major) and the same output.
pub fn cell_bounds_cpu(setup: &ViewSetup, dims: &GridDims, depth: &[f32]) -> Vec<[f32; 2]> {
    cell_bounds_cpu_samples(setup, dims, &[depth])
}

/// As [`cell_bounds_cpu`] over every sample of an MSAA depth buffer: `planes[s]` holds
/// sample `s` of every pixel (row-major).
pub fn cell_bounds_cpu_samples(
    setup: &ViewSetup,
    dims: &GridDims,
    planes: &[&[f32]],
) -> Vec<[f32; 2]> {
    let mut bounds = vec![EMPTY_CELL; dims.cell_count()];
    let mut tile_max = vec![0.0f32; dims.tile_count()];
    let mut include = |cell: usize, w: f32| {
        let b = &mut bounds[cell];
        b[0] = b[0].min(w);
        b[1] = b[1].max(w);
    };
    for (y, x, depth) in (0..dims.height)
        .flat_map(|y| (0..dims.width).map(move |x| (y, x)))
        .flat_map(|(y, x)| planes.iter().map(move |p| (y, x, p)))
    {
        {
            let d = depth[(y * dims.width + x) as usize];
            let tile = dims.tile_of(x, y);
            if crate::depth::is_background(d) {
                tile_max[tile] = tile_max[tile].max(setup.far);
                continue;
            }
            let w = setup.view_distance(d);
            tile_max[tile] = tile_max[tile].max(w);
            let k0 = dims.slice_of(w * (1.0 - ASSIGN_DEPTH_SLACK));
            let k1 = dims.slice_of(w * (1.0 + ASSIGN_DEPTH_SLACK));
            include(k0 as usize * dims.tile_count() + tile, w);
            if k1 != k0 {
                include(k1 as usize * dims.tile_count() + tile, w);
            }
        }
    }
    if dims.lists != GridLists::Opaque {
        let layer = dims.layer_cells();
        for cell in 0..layer {
            let tile = cell % dims.tile_count();
            let t = transparent_bounds(setup, dims, dims.slice_of_cell(cell), tile_max[tile]);
            match dims.lists {
                GridLists::Shared => bounds[cell] = bounds_union(bounds[cell], t),
                _ => bounds[layer + cell] = t,
            }
        }
    }
    bounds
}

/// Every cell's bounds without a depth buffer (froxels): its slice's view-distance range,
/// widened by twice the slack as [`transparent_bounds`] widens it (the shaders' slice of a
/// distance may round into the next), within near..far. A tiled grid's cells span near..far.
pub(crate) fn slice_bounds(dims: &GridDims, [near, far]: [f32; 2]) -> Vec<[f32; 2]> {
    (0..dims.cell_count())
        .map(|c| widened_slice(dims, dims.slice_of_cell(c), near, far))
        .collect()
}

/// Slice `k`'s view-distance range widened by twice the slack, within `near..hi`
/// (`EMPTY_CELL` when nothing is left).
fn widened_slice(dims: &GridDims, k: u32, near: f32, hi: f32) -> [f32; 2] {
    let [slice_lo, slice_hi] = dims.slice_range(k);
    let lo = near.max(slice_lo * (1.0 - 2.0 * ASSIGN_DEPTH_SLACK));
    let hi = hi.min(slice_hi * (1.0 + 2.0 * ASSIGN_DEPTH_SLACK));
    if lo > hi {
        EMPTY_CELL
    } else {
        [lo, hi]
    }
}

/// Where transparent fragments of slice `k` can lie in a tile whose opaque maximum is
/// `tile_max` (an empty pixel counts as the far plane): in front of it, behind the near
/// plane, inside the slice's range widened by twice the slack (tiled-forward-shading §4.5:
/// the transparent list spans near..max). Twin of `transparent_bounds` in the kernel.
fn transparent_bounds(setup: &ViewSetup, dims: &GridDims, k: u32, tile_max: f32) -> [f32; 2] {
    widened_slice(dims, k, setup.near, tile_max)
}

/// The smallest range holding both (either may be empty: min > max).
fn bounds_union(a: [f32; 2], b: [f32; 2]) -> [f32; 2] {
    match (a[0] <= a[1], b[0] <= b[1]) {
        (false, _) => b,
        (_, false) => a,
        _ => [a[0].min(b[0]), a[1].max(b[1])],
    }
}

/// The GPU kernel and the bounds buffer it fills.
pub(crate) struct CellBoundsPass {
    /// With MSAA: the forward fragments' view distances, folded into the bounds first when
    /// the frame draws them ([`CullFrame::fragments`]).
    fragments: Option<crate::culling::bounds::fragment_bounds::FragmentBounds>,
    /// Binding 5 without MSAA (unread).
    no_fragments: wgpu::Buffer,
    /// `main` for tiles of `.0` pixels: a workgroup of one invocation per row (the override
    /// CELL_THREADS; lavapipe runs every invocation of a workgroup through its barriers, idle
    /// or not, so 64 for a 16-pixel tile cost a third more than 16).
    pipeline: (u32, wgpu::ComputePipeline),
    args: wgpu::ComputePipeline,
    shader: crate::shader::ComposedShader,
    cull_layout: wgpu::BindGroupLayout,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    bounds: wgpu::Buffer,
    /// The cell lists (`cell_bounds.wgsl`): a 4-word header (the occupied cells' number and
    /// their dispatch arguments), the occupied cells, and as the second half of the rest the
    /// assignment kernels' spill list (`assign_bindings.wgsl`).
    lists: wgpu::Buffer,
    /// The header's dispatch arguments, copied out after the kernel (the lists are bound
    /// read-write where they feed an indirect dispatch).
    dispatch_args: wgpu::Buffer,
    /// Each cell's 2.5D depth mask and tight box (`cell_box.rs`: `CellCull`, 48 bytes; neither
    /// without `--depth-mask on` / `--cell-box on`).
    culls: wgpu::Buffer,
    /// `--depth-mask on` or `--cell-box on`: the kernel fills `culls` with something to read.
    culled: bool,
    cells: usize,
}

/// The kernel's `main` for tiles of `tile_size` pixels: one invocation per row.
fn main_pipeline(
    device: &wgpu::Device,
    shader: &crate::shader::ComposedShader,
    layouts: &[Option<&wgpu::BindGroupLayout>],
    tile_size: u32,
) -> wgpu::ComputePipeline {
    let threads = [(overrides::CELL_THREADS, f64::from(tile_size))];
    compute_pipeline_with(device, "cell bounds", shader, "main", layouts, &threads)
}

impl CellBoundsPass {
    /// The kernel `key` names (over a depth target of `key.samples` samples per pixel).
    /// `tile_size`: the grid's tiles (another size later builds the kernel again).
    pub(crate) fn new(
        device: &wgpu::Device,
        cull_layout: &wgpu::BindGroupLayout,
        key: CellBoundsKey,
        tile_size: u32,
    ) -> Self {
        let samples = key.samples;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("cell bounds (group 1)"),
            entries: &[
                crate::passes::sampled_texture_entry(0, wgpu::TextureSampleType::Depth, samples),
                crate::gpu::buffer_entry(1, crate::gpu::UNIFORM),
                crate::gpu::buffer_entry(2, crate::gpu::STORAGE_RW),
                crate::gpu::buffer_entry(3, crate::gpu::STORAGE_RW),
                crate::gpu::buffer_entry(4, crate::gpu::STORAGE_READ),
                crate::gpu::buffer_entry(5, crate::gpu::STORAGE_RW),
            ],
        });
        let s = key.shader();
        let layouts = [Some(cull_layout), Some(&layout)];
        let pipeline = (tile_size, main_pipeline(device, &s, &layouts, tile_size));
        let args = compute_pipeline(device, "cell bounds args", &s, "args_main", &layouts);
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("cell bounds params"),
            size: std::mem::size_of::<crate::gpu_types::GridParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        CellBoundsPass {
            fragments: (samples > 1)
                .then(|| crate::culling::bounds::fragment_bounds::FragmentBounds::new(device)),
            no_fragments: storage_buffer(device, "no fragment bounds", 16),
            pipeline,
            args,
            shader: s,
            cull_layout: cull_layout.clone(),
            layout,
            params,
            bounds: storage_buffer(device, "cell bounds", 1 << 14),
            lists: storage_buffer(device, "cell lists", 1 << 13),
            dispatch_args: crate::gpu::indirect_args_buffer(
                device,
                "occupied cells dispatch arguments",
            ),
            culls: no_culls(device),
            culled: key.culled(),
            cells: 0,
        }
    }

    /// A grid whose per-cell records (bounds, or the 48-byte mask and box records) need more
    /// bytes than one storage binding of this device holds is refused with the numbers,
    /// before any buffer is made (measured: `--slices 256 --tile 4` at 2000x1200 is 38
    /// million cells, whose 307 MB of bounds lavapipe cannot bind: a wgpu validation error).
    pub fn check_capacity(&self, device: &wgpu::Device, dims: &GridDims) -> Result<()> {
        let per_cell = if self.culled { CULL_BYTES } else { 8 } as u64;
        let cells = dims.cell_count() as u64;
        let max = crate::culling::frame::max_index_entries(device) * 4;
        if cells * per_cell > max {
            return Err(Error::invalid(
                "--slices",
                format!(
                    "the light grid's {cells} cells ({} x {} tiles of {} px, {} slices{}) need {} bytes of per-cell records, more than the {max} this device binds; use a larger --tile, fewer --slices or a smaller frame",
                    dims.tiles_x,
                    dims.tiles_y,
                    dims.tile_size,
                    dims.slices,
                    if dims.lists.layers() > 1 { ", 2 layers" } else { "" },
                    cells * per_cell
                ),
            ));
        }
        Ok(())
    }

    fn ensure(&mut self, device: &wgpu::Device, dims: &GridDims) {
        self.cells = dims.cell_count();
        grow_storage(
            device,
            &mut self.bounds,
            "cell bounds",
            (self.cells * 8) as u64,
        );
        if self.culled {
            grow_storage(
                device,
                &mut self.culls,
                "cell culls",
                (self.cells * CULL_BYTES) as u64,
            );
        }
        // The header, then room for every cell twice (occupied, spilled).
        grow_storage(
            device,
            &mut self.lists,
            "cell lists",
            (16 + self.cells * 8) as u64,
        );
    }

    /// Record the kernel over the frame's depth target (`f.targets.depth`, as recorded in
    /// `enc` so far).
    pub fn encode(&mut self, f: &CullFrame, enc: &mut FrameEncoder, dims: &GridDims) {
        let (device, queue, cull, depth) = (f.device, f.queue, f.bind_group, f.depth());
        self.ensure(device, dims);
        if self.pipeline.0 != dims.tile_size {
            let layouts = [Some(&self.cull_layout), Some(&self.layout)];
            let main = main_pipeline(device, &self.shader, &layouts, dims.tile_size);
            self.pipeline = (dims.tile_size, main);
        }
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&dims.params()));
        let fragment_bounds = match (&mut self.fragments, f.fragments) {
            (Some(fragments), Some(draw)) => {
                fragments.encode(f, enc, dims, &self.params, draw);
                fragments.buffer()
            }
            _ => &self.no_fragments,
        };
        let (encoder, timer) = enc.parts();
        let group = bind_resources(
            device,
            "cell bounds",
            &self.layout,
            &[
                wgpu::BindingResource::TextureView(depth),
                self.params.as_entire_binding(),
                self.bounds.as_entire_binding(),
                self.lists.as_entire_binding(),
                fragment_bounds.as_entire_binding(),
                self.culls.as_entire_binding(),
            ],
        );
        encoder.clear_buffer(&self.lists, 0, Some(16));
        let mut pass = timer.begin_compute(encoder, crate::consts::pass_labels::CELL_BOUNDS);
        pass.set_pipeline(&self.pipeline.1);
        pass.set_bind_group(0, cull, &[]);
        pass.set_bind_group(1, &group, &[]);
        pass.dispatch_workgroups(dims.tiles_x, dims.tiles_y, 1);
        pass.set_pipeline(&self.args);
        pass.dispatch_workgroups(1, 1, 1);
        drop(pass);
        encoder.copy_buffer_to_buffer(&self.lists, 4, &self.dispatch_args, 0, 12);
    }

    /// The layout of the fragment-bounds group (MSAA only).
    pub(crate) fn fragments_layout(&self) -> Option<&wgpu::BindGroupLayout> {
        self.fragments.as_ref().map(|f| f.layout())
    }

    /// Without depth: every cell spans its slice of `[near, far]` (`slice_bounds`) and counts
    /// as occupied.
    pub fn fill(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        dims: &GridDims,
        range: [f32; 2],
    ) {
        self.ensure(device, dims);
        let all = slice_bounds(dims, range);
        queue.write_buffer(&self.bounds, 0, bytemuck::cast_slice(&all));
        if self.culled {
            let culls = vec![NO_CULL; self.cells];
            queue.write_buffer(&self.culls, 0, bytemuck::cast_slice(&culls));
        }
        let n = self.cells as u32;
        let (x, y) = crate::gpu::groups_1d(n);
        let list: Vec<u32> = [n, x, y, 1].into_iter().chain(0..n).collect();
        queue.write_buffer(&self.lists, 0, bytemuck::cast_slice(&list));
        queue.write_buffer(&self.dispatch_args, 0, bytemuck::cast_slice(&[x, y, 1]));
    }

    /// The grid's parameters the kernel reads (a uniform buffer).
    pub(crate) fn params_buffer(&self) -> &wgpu::Buffer {
        &self.params
    }

    /// The bounds on the GPU (`array<vec2<f32>>`, one per cell).
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.bounds
    }

    /// Whether the kernel computes depth masks or boxes (`--depth-mask on`, `--cell-box on`).
    pub fn culled(&self) -> bool {
        self.culled
    }

    /// The cells' culling records (`array<CellCull>`, one per cell: `cell_box.rs`).
    pub fn cull_buffer(&self) -> &wgpu::Buffer {
        &self.culls
    }

    /// The cell lists (`array<u32>`): the occupied-cell count, 3 words, the occupied cells
    /// (in no particular order), and the spill list's room.
    pub fn lists_buffer(&self) -> &wgpu::Buffer {
        &self.lists
    }

    /// Indirect dispatch arguments of one workgroup per occupied cell.
    pub fn dispatch_args(&self) -> &wgpu::Buffer {
        &self.dispatch_args
    }

    /// The bounds of the last recorded frame (submits nothing itself: call after the frame's
    /// work is submitted).
    pub fn read(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Vec<[f32; 2]>> {
        let bytes = download(device, queue, &self.bounds, (self.cells * 8) as u64)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// The culling records of the last recorded frame (as [`CellBoundsPass::read`]; every
    /// cell [`NO_CULL`] without masks or boxes).
    pub fn read_culls(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Vec<CellCull>> {
        if !self.culled {
            return Ok(vec![NO_CULL; self.cells]);
        }
        let bytes = download(device, queue, &self.culls, (self.cells * CULL_BYTES) as u64)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}
