//! The light grid, exactly tiled-shading §6.2 / Figure 1: the global light list (the scene's
//! light buffer), the per-cell `(offset, count)` grid, and the cell light index lists. A tiled
//! grid is a clustered grid with one depth slice. Every builder produces a [`LightGrid`];
//! every grid-reading shader reads it through `culling/light_grid.wgsl`.

use crate::consts::{MAX_TILE_SIZE, MIN_TILE_SIZE};
use crate::error::{Error, Result};
use crate::gpu_types::GridParams;

/// The grid's shape for a frame size and tile size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GridDims {
    pub tile_size: u32,
    pub width: u32,
    pub height: u32,
    pub tiles_x: u32,
    pub tiles_y: u32,
}

impl GridDims {
    pub fn new(width: u32, height: u32, tile_size: u32) -> Result<Self> {
        if !(MIN_TILE_SIZE..=MAX_TILE_SIZE).contains(&tile_size) {
            return Err(Error::invalid(
                "tile size",
                format!("{tile_size}: must be between {MIN_TILE_SIZE} and {MAX_TILE_SIZE} pixels"),
            ));
        }
        Ok(GridDims {
            tile_size,
            width,
            height,
            tiles_x: width.div_ceil(tile_size),
            tiles_y: height.div_ceil(tile_size),
        })
    }

    pub fn tile_count(&self) -> usize {
        (self.tiles_x * self.tiles_y) as usize
    }

    pub fn tile_of(&self, x: u32, y: u32) -> usize {
        ((y / self.tile_size) * self.tiles_x + x / self.tile_size) as usize
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

    pub fn params(&self) -> GridParams {
        GridParams {
            tile_size: self.tile_size,
            tiles_x: self.tiles_x,
            tiles_y: self.tiles_y,
            slices: 1,
        }
    }
}

/// The grid: `cells[c] = [offset, count]` into `indices`, which hold light indices.
#[derive(Clone, Debug, PartialEq)]
pub struct LightGrid {
    pub dims: GridDims,
    pub cells: Vec<[u32; 2]>,
    pub indices: Vec<u32>,
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
        }
    }

    /// The lights listed for cell `c`.
    pub fn cell(&self, c: usize) -> &[u32] {
        let [offset, count] = self.cells[c];
        &self.indices[offset as usize..(offset + count) as usize]
    }

    pub fn average_lights_per_cell(&self) -> f64 {
        self.indices.len() as f64 / self.cells.len().max(1) as f64
    }

    pub fn max_lights_per_cell(&self) -> u32 {
        self.cells.iter().map(|c| c[1]).max().unwrap_or(0)
    }
}

/// The grid on the GPU: group 1 of every grid-reading shader (`culling/light_grid.wgsl`).
pub struct GridBuffers {
    pub layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    cells: wgpu::Buffer,
    indices: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

impl GridBuffers {
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
            ],
        })
    }

    pub fn new(device: &wgpu::Device) -> Self {
        let layout = Self::layout(device);
        let params = Self::buffer(device, "grid params", wgpu::BufferUsages::UNIFORM, 16);
        let cells = Self::buffer(device, "grid cells", wgpu::BufferUsages::STORAGE, 1 << 14);
        let indices = Self::buffer(device, "grid indices", wgpu::BufferUsages::STORAGE, 1 << 16);
        let bind_group = Self::bind(device, &layout, &params, &cells, &indices);
        GridBuffers {
            layout,
            params,
            cells,
            indices,
            bind_group,
        }
    }

    fn buffer(
        device: &wgpu::Device,
        label: &str,
        usage: wgpu::BufferUsages,
        size: u64,
    ) -> wgpu::Buffer {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(16),
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    fn bind(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        params: &wgpu::Buffer,
        cells: &wgpu::Buffer,
        indices: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("light grid"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: cells.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: indices.as_entire_binding(),
                },
            ],
        })
    }

    /// Upload a grid; buffers grow (never truncate) to fit its index list.
    pub fn upload(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, grid: &LightGrid) {
        let cells: &[u8] = bytemuck::cast_slice(&grid.cells);
        let indices: &[u8] = bytemuck::cast_slice(&grid.indices);
        let mut rebind = false;
        if cells.len() as u64 > self.cells.size() {
            self.cells = Self::buffer(
                device,
                "grid cells",
                wgpu::BufferUsages::STORAGE,
                (cells.len() as u64).next_power_of_two(),
            );
            rebind = true;
        }
        if indices.len() as u64 > self.indices.size() {
            self.indices = Self::buffer(
                device,
                "grid indices",
                wgpu::BufferUsages::STORAGE,
                (indices.len() as u64).next_power_of_two(),
            );
            rebind = true;
        }
        if rebind {
            self.bind_group = Self::bind(
                device,
                &self.layout,
                &self.params,
                &self.cells,
                &self.indices,
            );
        }
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&grid.dims.params()));
        queue.write_buffer(&self.cells, 0, cells);
        if !indices.is_empty() {
            queue.write_buffer(&self.indices, 0, indices);
        }
    }

    pub fn bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_group
    }
}
