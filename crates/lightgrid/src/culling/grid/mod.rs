//! The light grid, exactly tiled-shading §6.2 / Figure 1: the global light list (the scene's
//! light buffer), the per-cell `(offset, count)` grid, and the cell light index lists. A tiled
//! grid is a clustered grid with one depth slice. Every builder produces a [`LightGrid`];
//! every grid-reading shader reads it through `culling/grid/light_grid.wgsl`.

use crate::error::{Error, Result};
pub use crate::frame::GridLists;
use crate::gpu::{bind_resources, download, grow_storage, storage_buffer};
use crate::gpu_types::GridParams;

/// The grid's shape: screen tiles, and for a clustered grid view-depth slices spaced
/// exponentially between `near` and `far` (the frame's samples' depth range, found on the GPU:
/// `depth_range.rs`). Cell index = (slice * tiles_y + ty) * tiles_x + tx.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridDims {
    /// Tile edge in pixels (tiles are square).
    pub tile_size: u32,
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Tile columns: `width / tile_size` rounded up (the last column may be partial).
    pub tiles_x: u32,
    /// Tile rows: `height / tile_size` rounded up (the last row may be partial).
    pub tiles_y: u32,
    /// 1 for a tiled grid.
    pub slices: u32,
    /// The view-distance range the slices are spread over.
    pub near: f32,
    /// Far end of that range (`near` is the near end); unused by a tiled grid.
    pub far: f32,
    /// slice = floor(ln(w) * slice_scale + slice_bias): from `near` and `far`, or exactly the
    /// GPU's values when it spread the slices ([`GridDims::with_slicing`]).
    pub slice_scale: f32,
    /// The additive term of the slice formula above; unused by a tiled grid.
    pub slice_bias: f32,
    /// Which samples the lists cover: opaque samples only, or transparent fragments too.
    pub lists: GridLists,
    /// A z-binned grid (`--assign zbin`, `zbin.rs`): the light count its tile masks have
    /// bits for; `None` for a grid of per-cell lists.
    pub zbin_lights: Option<u32>,
}

impl GridDims {
    /// A tiled grid (one slice).
    pub fn new(width: u32, height: u32, tile_size: u32) -> Result<Self> {
        crate::frame::validate_tile_size(tile_size)?;
        Ok(GridDims {
            tile_size,
            width,
            height,
            tiles_x: width.div_ceil(tile_size),
            tiles_y: height.div_ceil(tile_size),
            slices: 1,
            near: 0.0,
            far: 0.0,
            slice_scale: 0.0,
            slice_bias: 0.0,
            lists: GridLists::Opaque,
            zbin_lights: None,
        })
    }

    /// A clustered grid: `slices` view-depth slices between `near` and `far`.
    pub fn clustered(self, slices: u32, near: f32, far: f32) -> Result<Self> {
        crate::frame::validate_slices(slices)?;
        if !(near > 0.0 && far > near && far.is_finite()) {
            return Err(Error::invalid(
                "clusters",
                format!("need 0 < near < far, got {near} and {far}"),
            ));
        }
        let s = slices as f32;
        let span = (far / near).ln();
        Ok(GridDims {
            slices,
            near,
            far,
            slice_scale: s / span,
            slice_bias: -s * near.ln() / span,
            ..self
        })
    }

    /// The same grid sliced as the GPU sliced it (`depth_range.wgsl`'s `finish`): over
    /// `[near, far]` with its own scale and bias, bit for bit, so the CPU puts every sample
    /// in the slice the kernels put it in.
    pub fn with_slicing(self, [near, far]: [f32; 2], slice_scale: f32, slice_bias: f32) -> Self {
        GridDims {
            near,
            far,
            slice_scale,
            slice_bias,
            ..self
        }
    }

    /// Screen tiles (cells of one slice).
    pub fn tile_count(&self) -> usize {
        (self.tiles_x * self.tiles_y) as usize
    }

    /// The same grid with lists covering `lists`.
    pub fn with_lists(self, lists: GridLists) -> Self {
        GridDims { lists, ..self }
    }

    /// The same grid z-binned over `lights` lights (its slices are the depth bins).
    pub fn with_zbins(self, lights: u32) -> Self {
        GridDims {
            zbin_lights: Some(lights),
            ..self
        }
    }

    /// Cells of one layer: tiles × slices.
    pub fn layer_cells(&self) -> usize {
        self.tile_count() * self.slices as usize
    }

    /// All cells: tiles × slices × layers.
    pub fn cell_count(&self) -> usize {
        self.layer_cells() * self.lists.layers() as usize
    }

    /// Depth slice of cell `c` (any layer).
    pub fn slice_of_cell(&self, c: usize) -> u32 {
        ((c % self.layer_cells()) / self.tile_count()) as u32
    }

    /// Layer of cell `c` (0: opaque samples; 1: transparent fragments, separate lists).
    pub fn layer_of_cell(&self, c: usize) -> u32 {
        (c / self.layer_cells()) as u32
    }

    /// Screen tile of pixel (x, y): `ty * tiles_x + tx`, also its cell in slice 0.
    pub fn tile_of(&self, x: u32, y: u32) -> usize {
        ((y / self.tile_size) * self.tiles_x + x / self.tile_size) as usize
    }

    fn slice_params(&self) -> (f32, f32) {
        if self.slices <= 1 {
            return (0.0, 0.0);
        }
        (self.slice_scale, self.slice_bias)
    }

    /// Slice of view distance `w` (the same formula as `light_grid_slice` in light_grid.wgsl).
    pub fn slice_of(&self, w: f32) -> u32 {
        if self.slices <= 1 {
            return 0;
        }
        let (scale, bias) = self.slice_params();
        ((w.max(1e-6).ln() * scale + bias)
            .floor()
            .clamp(0.0, (self.slices - 1) as f32)) as u32
    }

    /// View-distance range `[lo, hi]` of slice `k`.
    pub fn slice_range(&self, k: u32) -> [f32; 2] {
        if self.slices <= 1 {
            return [0.0, f32::INFINITY];
        }
        // `slice_span` in cell_bounds.wgsl computes the same.
        let at = |i: u32| ((i as f32 - self.slice_bias) / self.slice_scale).exp();
        [
            if k == 0 { 0.0 } else { at(k) },
            if k + 1 == self.slices {
                f32::INFINITY
            } else {
                at(k + 1)
            },
        ]
    }

    /// Cell of the opaque sample at pixel (x, y) with view distance `w`.
    pub fn cell_of(&self, x: u32, y: u32, w: f32) -> usize {
        self.slice_of(w) as usize * self.tile_count() + self.tile_of(x, y)
    }

    /// Cell of a transparent fragment at pixel (x, y) with view distance `w`
    /// (`light_grid_cell_transparent` in grid_cell.wgsl).
    pub fn transparent_cell_of(&self, x: u32, y: u32, w: f32) -> usize {
        self.lists.transparent_layer() as usize * self.layer_cells() + self.cell_of(x, y, w)
    }

    /// Pixel rectangle [x0, x1) × [y0, y1) of tile `t`, clipped to the frame.
    pub fn tile_rect(&self, t: usize) -> (u32, u32, u32, u32) {
        let (tx, ty) = (t as u32 % self.tiles_x, t as u32 / self.tiles_x);
        let (x0, y0) = (tx * self.tile_size, ty * self.tile_size);
        (
            x0,
            y0,
            (x0 + self.tile_size).min(self.width),
            (y0 + self.tile_size).min(self.height),
        )
    }

    /// The shape as the shaders' `LightGridParams` uniform (slicing zeroed for a tiled grid;
    /// z-bin words and mask offset 0 unless z-binned).
    pub fn params(&self) -> GridParams {
        let (slice_scale, slice_bias) = self.slice_params();
        GridParams {
            tile_size: self.tile_size,
            tiles_x: self.tiles_x,
            tiles_y: self.tiles_y,
            slices: self.slices,
            slice_scale,
            slice_bias,
            lists: self.lists.gpu(),
            layer_cells: self.layer_cells() as u32,
            zbin_words: self.zbin_lights.map_or(0, |n| n.div_ceil(32)),
            zbin_masks: self.zbin_lights.unwrap_or(0),
            pad_a: 0,
            pad_b: 0,
        }
    }
}

/// The grid: `cells[c] = [offset, count]` into `indices`, which hold light indices.
#[derive(Clone, Debug, PartialEq)]
pub struct LightGrid {
    /// The shape: cell count and cell index convention ([`GridDims`]).
    pub dims: GridDims,
    /// Per cell, `[offset, count]`: its list is `indices[offset..offset + count]`.
    pub cells: Vec<[u32; 2]>,
    /// Every cell's list back to back: indices into the scene's light buffer.
    pub indices: Vec<u32>,
    /// A z-binned grid's compact form (what the GPU holds); `cells` and `indices` are then
    /// the lists it stands for.
    pub zbins: Option<ZBins>,
}

impl LightGrid {
    /// Pack per-cell lists into the offset/count grid and one index array.
    pub fn from_lists(dims: GridDims, lists: &[Vec<u32>]) -> Self {
        let mut cells = Vec::with_capacity(lists.len());
        let total = lists.iter().map(Vec::len).sum();
        let mut indices = Vec::with_capacity(total);
        for l in lists {
            cells.push([indices.len() as u32, l.len() as u32]);
            indices.extend_from_slice(l);
        }
        LightGrid {
            dims,
            cells,
            indices,
            zbins: None,
        }
    }

    /// The lights listed for cell `c`.
    pub fn cell(&self, c: usize) -> &[u32] {
        let [offset, count] = self.cells[c];
        &self.indices[offset as usize..(offset + count) as usize]
    }

    /// Bytes the GPU holds for the grid (not counting the cells' culling records): the
    /// `(offset, count)` cells and the index lists, or a z-binned grid's compact form.
    pub fn stored_bytes(&self) -> u64 {
        match &self.zbins {
            Some(z) => z.bytes(),
            None => (self.cells.len() * 8 + self.indices.len() * 4) as u64,
        }
    }

    /// Mean list length: index entries over all cells (empty cells and every layer counted).
    pub fn average_lights_per_cell(&self) -> f64 {
        self.indices.len() as f64 / self.cells.len().max(1) as f64
    }

    /// tiled-shading Fig. 3's count for tiled techniques: every tile's pixel area times its
    /// list length, summed (the opaque lists; `None` for clustered grids, which the figure
    /// does not have). It counts the sky and the partial tiles' pixels too, as the figure
    /// does; the ideal-relative count counts visible samples only.
    pub fn tile_area_computations(&self) -> Option<u64> {
        let d = &self.dims;
        if d.slices != 1 {
            return None;
        }
        let area = |t: usize| {
            let (tx, ty) = (
                (t % d.tiles_x as usize) as u32,
                (t / d.tiles_x as usize) as u32,
            );
            let w = d.tile_size.min(d.width - tx * d.tile_size);
            let h = d.tile_size.min(d.height - ty * d.tile_size);
            u64::from(w) * u64::from(h)
        };
        Some(
            self.cells
                .iter()
                .take(d.tile_count())
                .enumerate()
                .map(|(t, c)| area(t) * u64::from(c[1]))
                .sum(),
        )
    }

    /// Longest list of any cell (0 for a grid without cells).
    pub fn max_lights_per_cell(&self) -> u32 {
        self.cells.iter().map(|c| c[1]).max().unwrap_or(0)
    }

    /// Per screen tile, the longest list over its slices (the tile's own count for a tiled
    /// grid): what the heatmap shows.
    pub fn tile_max_counts(&self) -> Vec<u32> {
        let t = self.dims.tile_count();
        (0..t)
            .map(|i| {
                (0..self.dims.slices as usize)
                    .map(|k| self.cells[k * t + i][1])
                    .max()
                    .unwrap_or(0)
            })
            .collect()
    }
}

/// The grid on the GPU: group 1 of every grid-reading shader (`culling/grid/light_grid.wgsl`).
pub struct GridBuffers {
    /// The layout of group 1 ([`Self::layout`]'s), for the shading pipelines' layouts.
    pub layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    cells: wgpu::Buffer,
    indices: wgpu::Buffer,
    /// The cell bounds the lists were built for (`light_grid.wgsl`'s `grid_bounds`).
    bounds: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    /// How many times `bind_group` was replaced (a buffer grew).
    generation: u64,
}

#[cfg_attr(not(feature = "testing"), allow(dead_code))]
impl GridBuffers {
    /// Index entries a new grid's buffer holds; it grows (never shrinks) to fit.
    #[cfg_attr(not(feature = "testing"), allow(dead_code))]
    pub const INITIAL_INDEX_CAPACITY: u32 = crate::consts::INITIAL_INDEX_CAPACITY;

    /// The grid's group layout: params (uniform), cells, indices and cell bounds (storage,
    /// read), visible to fragment and compute stages.
    pub fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let storage = wgpu::BufferBindingType::Storage { read_only: true };
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("light grid (group 1)"),
            entries: &[
                entry(0, wgpu::BufferBindingType::Uniform),
                entry(1, storage),
                entry(2, storage),
                entry(3, storage),
            ],
        })
    }

    /// Buffers whose index list starts at `index_capacity` entries.
    pub fn new(device: &wgpu::Device, index_capacity: u64) -> Self {
        let layout = Self::layout(device);
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("grid params"),
            size: std::mem::size_of::<crate::gpu_types::GridParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let cells = storage_buffer(device, "grid cells", 1 << 14);
        let indices = storage_buffer(device, "grid indices", index_capacity.max(1) * 4);
        let bounds = storage_buffer(device, "grid cell bounds", 1 << 14);
        let bind_group = Self::bind(device, &layout, [&params, &cells, &indices, &bounds]);
        GridBuffers {
            layout,
            params,
            cells,
            indices,
            bounds,
            bind_group,
            generation: 0,
        }
    }

    /// A new group over the buffers (one grew): the generation moves on.
    fn rebind(&mut self, device: &wgpu::Device) {
        self.bind_group = Self::bind(
            device,
            &self.layout,
            [&self.params, &self.cells, &self.indices, &self.bounds],
        );
        self.generation += 1;
    }

    /// How many times [`Self::bind_group`] has been replaced since the buffers were made.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Grow the buffers now to hold `cells` cells and `indices` index entries, so frames
    /// within them replace no group.
    pub fn reserve(&mut self, device: &wgpu::Device, cells: usize, indices: u64) {
        let cb = (cells * 8) as u64;
        let grown_cells = grow_storage(device, &mut self.cells, "grid cells", cb);
        let grown_indices = grow_storage(
            device,
            &mut self.indices,
            "grid indices",
            indices.max(1) * 4,
        );
        let grown_bounds = grow_storage(device, &mut self.bounds, "grid cell bounds", cb);
        if grown_cells || grown_indices || grown_bounds {
            self.rebind(device);
        }
    }

    fn bind(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        buffers: [&wgpu::Buffer; 4],
    ) -> wgpu::BindGroup {
        bind_resources(
            device,
            "light grid",
            layout,
            &buffers.map(|b| b.as_entire_binding()),
        )
    }

    /// Upload a grid; buffers grow (never truncate) to fit its index list.
    pub fn upload(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, grid: &LightGrid) {
        self.ensure(
            device,
            queue,
            &grid.dims,
            grid.cells.len(),
            grid.indices.len(),
        );
        let cells: &[u8] = bytemuck::cast_slice(&grid.cells);
        let indices: &[u8] = bytemuck::cast_slice(&grid.indices);
        queue.write_buffer(&self.cells, 0, cells);
        if !indices.is_empty() {
            queue.write_buffer(&self.indices, 0, indices);
        }
    }

    /// Group 1 of the shading passes: the grid's four buffers.
    pub fn bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_group
    }

    /// Write the shape and make sure `cells` and `indices` hold at least the given counts
    /// (growing, never truncating). A grid built on the GPU calls this directly; `upload`
    /// calls it before writing a CPU grid.
    pub fn ensure(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        dims: &GridDims,
        cells: usize,
        indices: usize,
    ) {
        let (cb, ib) = ((cells * 8) as u64, (indices.max(1) * 4) as u64);
        let grown_cells = grow_storage(device, &mut self.cells, "grid cells", cb);
        let grown_indices = grow_storage(device, &mut self.indices, "grid indices", ib);
        let grown_bounds = grow_storage(device, &mut self.bounds, "grid cell bounds", cb);
        if grown_cells || grown_indices || grown_bounds {
            self.rebind(device);
        }
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&dims.params()));
    }

    /// Record the copy of the frame's cell bounds (`cells` of them) next to the lists, for
    /// the shading passes' check that a fragment lies in its cell (`light_grid_cell_holds`).
    pub fn encode_bounds(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        bounds: &wgpu::Buffer,
        cells: usize,
    ) {
        let bytes = (cells * 8) as u64;
        if grow_storage(device, &mut self.bounds, "grid cell bounds", bytes) {
            self.rebind(device);
        }
        if bytes > 0 {
            encoder.copy_buffer_to_buffer(bounds, 0, &self.bounds, 0, bytes);
        }
    }

    /// The `GridParams` uniform.
    pub fn params_buffer(&self) -> &wgpu::Buffer {
        &self.params
    }

    /// Each cell's (offset, count) into the index list.
    pub fn cells_buffer(&self) -> &wgpu::Buffer {
        &self.cells
    }

    /// The index list: light indices, each cell's run at its offset.
    pub fn indices_buffer(&self) -> &wgpu::Buffer {
        &self.indices
    }

    /// The per-cell lists as the GPU left them, `total` index entries, read back (statistics,
    /// heatmaps, the tests; waits).
    pub fn read_lists(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        dims: &GridDims,
        total: u32,
    ) -> Result<LightGrid> {
        let cells = download(device, queue, &self.cells, (dims.cell_count() * 8) as u64)?;
        let indices = download(device, queue, &self.indices, u64::from(total) * 4)?;
        Ok(LightGrid {
            dims: *dims,
            cells: bytemuck::pod_collect_to_vec(&cells),
            indices: bytemuck::pod_collect_to_vec(&indices),
            zbins: None,
        })
    }
}

/// A z-binned grid in its compact form, as the GPU holds it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ZBins {
    /// Light indices sorted by view depth (the bounding sphere's centre; ties by index).
    pub order: Vec<u32>,
    /// Per depth bin, the sorted range `[first, end)` of the lights meeting it (`first >=
    /// end`: none).
    pub bins: Vec<[u32; 2]>,
    /// 32-bit words of each tile's mask.
    pub words: usize,
    /// Per tile, `words` words: bit `i % 32` of word `i / 32` is sorted light `i`.
    pub masks: Vec<u32>,
}

impl ZBins {
    /// Bytes the GPU holds: the order, the masks and two words per bin.
    pub fn bytes(&self) -> u64 {
        ((self.order.len() + self.masks.len() + 2 * self.bins.len()) * 4) as u64
    }

    /// Does tile `t`'s mask hold sorted light `i`?
    pub fn tile_has(&self, t: usize, i: usize) -> bool {
        self.masks[t * self.words + i / 32] & (1 << (i % 32)) != 0
    }

    /// The lights a sample of cell `c` (any layer) shades, in sorted order.
    pub fn cell_lights(&self, dims: &GridDims, c: usize) -> Vec<u32> {
        let lc = c % dims.layer_cells();
        let (t, k) = (lc % dims.tile_count(), lc / dims.tile_count());
        let [first, end] = self.bins[k];
        (first..end.max(first))
            .filter(|&i| self.tile_has(t, i as usize))
            .map(|i| self.order[i as usize])
            .collect()
    }

    /// The per-cell lists this structure stands for (analysis, the heatmap, the oracle
    /// tests), with the compact form kept beside them.
    pub fn into_grid(self, dims: GridDims) -> LightGrid {
        let lists: Vec<Vec<u32>> = (0..dims.cell_count())
            .map(|c| self.cell_lights(&dims, c))
            .collect();
        let mut grid = LightGrid::from_lists(dims, &lists);
        grid.zbins = Some(self);
        grid
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tile_area_counts_partial_tiles_by_their_pixels() {
        // 20x10 with 8-pixel tiles: 3x2 tiles of 8x8, 8x8, 4x8 / 8x2, 8x2, 4x2 pixels.
        let dims = GridDims::new(20, 10, 8).unwrap();
        let lists: Vec<Vec<u32>> = [1usize, 0, 3, 2, 0, 5]
            .iter()
            .map(|&n| (0..n as u32).collect())
            .collect();
        let grid = LightGrid::from_lists(dims, &lists);
        assert_eq!(
            grid.tile_area_computations(),
            Some(64 + 3 * 32 + 2 * 16 + 5 * 8)
        );
        let clustered =
            LightGrid::from_lists(dims.clustered(4, 1.0, 100.0).unwrap(), &vec![vec![0]; 24]);
        assert_eq!(clustered.tile_area_computations(), None);
    }
}
