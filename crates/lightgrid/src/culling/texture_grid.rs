//! The texture grid: tiled forward shading without compute shaders or storage buffers
//! (`--grid-storage textures`). tiled-forward-shading §4.2: a tiled forward renderer "without
//! compute shaders … on any hardware that supports dependent texture lookups in the fragment
//! shader"; tiled-shading §6.1–6.2: the grid assigned on the CPU, the paper's three arrays
//! read through textures in its OpenGL implementation.
//!
//! Per frame:
//! 1. with depth bounds (`tiled_forward_prez`): the depth pre-pass's tile bounds drawn by a
//!    fragment shader into one texel per tile (`passes/depth_texels.wgsl`, `fs_tile_depth`: the
//!    least and greatest depth value of the tile's samples; no compute), copied and read back
//!    in the frame's one wait (as `--assign cpu` does); the CPU turns them into view distance;
//! 2. CPU assignment (`assign_cpu`, the `cpu` strategy's own code and CPU twin) into the
//!    tiles, over near..far without depth bounds (`tiled_forward`);
//! 3. the three arrays written into textures (group 1; `culling/grid/light_grid_texels.wgsl`):
//!    binding 1 `Rg32Uint`, one texel per tile: (offset, count); binding 2 `R32Uint`, the light
//!    index lists row-major, the device's widest texture edge a row; binding 3 `Rgba32Float`,
//!    the camera-relative lights themselves, `LIGHT_TEXELS` texels each. Binding 0 is the
//!    grid's `LightGridParams` uniform, as in the buffer grid.
//!
//! Capacity: the edge² index entries and (edge / `LIGHT_TEXELS`) × edge lights a 2D texture
//! holds; a frame needing more is refused with both numbers, never truncated.

use crate::consts::LIGHT_TEXELS;
use crate::culling::grid::{GridDims, LightGrid};
use crate::culling::strategies::assign_cpu::{assign_cpu, DepthRange};
use crate::error::{Error, Result};
use crate::frame::{FrameEncoder, FrameInputs};
use crate::passes::depth_texels::{DepthTexelEntry, DepthTexelPass};

/// The most index entries and lights textures of edge `edge` hold.
pub(crate) fn capacity(edge: u32) -> (u64, u64) {
    let edge = u64::from(edge);
    (edge * edge, edge / u64::from(LIGHT_TEXELS) * edge)
}

/// Refuse a frame of `lights` lights and `indices` index entries beyond [`capacity`].
pub(crate) fn check_capacity(edge: u32, lights: u64, indices: u64) -> Result<()> {
    let (max_indices, max_lights) = capacity(edge);
    let over = |what: &str, n: u64, max: u64| {
        Error::invalid(
            "grid-storage",
            format!(
                "the texture grid holds at most {max} {what} with this device's \
                 max_texture_dimension_2d of {edge}; this frame needs {n} (use --grid-storage \
                 buffers, fewer lights or a larger --tile)"
            ),
        )
    };
    if lights > max_lights {
        return Err(over("lights", lights, max_lights));
    }
    if indices > max_indices {
        return Err(over("light index entries", indices, max_indices));
    }
    Ok(())
}

/// One list in a 2D texture, row-major, `edge` texels a row; rows grow, never shrink.
struct TexelRows {
    label: &'static str,
    format: wgpu::TextureFormat,
    edge: u32,
    rows: u32,
    texture: wgpu::Texture,
}

impl TexelRows {
    fn new(
        device: &wgpu::Device,
        label: &'static str,
        format: wgpu::TextureFormat,
        edge: u32,
    ) -> Self {
        TexelRows {
            label,
            format,
            edge,
            rows: 1,
            texture: texel_texture(device, label, format, (edge, 1)),
        }
    }

    /// Write `data` (`texels` texels of the format's size), growing the rows to hold it.
    /// Returns whether the texture was replaced (the bind group must follow).
    fn write(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        data: &[u8],
        texels: u32,
    ) -> bool {
        let texel = self.format.block_copy_size(None).expect("a colour format");
        let rows = texels.div_ceil(self.edge).max(1);
        let grown = rows > self.rows;
        if grown {
            self.rows = rows.next_power_of_two().min(self.edge);
            let size = (self.edge, self.rows);
            self.texture = texel_texture(device, self.label, self.format, size);
        }
        let row_bytes = (self.edge * texel) as usize;
        let full = texels / self.edge;
        let rest = texels % self.edge;
        let put = |y: u32, width: u32, height: u32, bytes: &[u8]| {
            if width == 0 || height == 0 {
                return;
            }
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &self.texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y, z: 0 },
                    aspect: wgpu::TextureAspect::All,
                },
                bytes,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(width * texel),
                    rows_per_image: Some(height),
                },
                wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
            );
        };
        let split = full as usize * row_bytes;
        put(0, self.edge, full, &data[..split]);
        put(full, rest, 1, &data[split..]);
        grown
    }
}

/// A 2D texture the CPU writes and shaders `textureLoad`.
fn texel_texture(
    device: &wgpu::Device,
    label: &str,
    format: wgpu::TextureFormat,
    size: (u32, u32),
) -> wgpu::Texture {
    use wgpu::TextureUsages as U;
    crate::frame::targets::render_texture(
        device,
        label,
        format,
        size,
        U::TEXTURE_BINDING | U::COPY_DST,
    )
}

/// Step 1: the tile depth bounds drawn by a fragment shader and the buffer they are read from.
struct TileDepth {
    pass: DepthTexelPass,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    buffer: wgpu::Buffer,
    padded_row: u32,
}

impl TileDepth {
    fn new(device: &wgpu::Device, dims: &GridDims) -> Self {
        let entry = DepthTexelEntry::TileDepth;
        use wgpu::TextureUsages as U;
        let texture = crate::frame::targets::render_texture(
            device,
            "tile depth",
            entry.format(),
            (dims.tiles_x, dims.tiles_y),
            U::RENDER_ATTACHMENT | U::COPY_SRC,
        );
        let padded_row = (dims.tiles_x * 16).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("tile depth"),
            size: u64::from(padded_row) * u64::from(dims.tiles_y),
            usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        TileDepth {
            pass: DepthTexelPass::new(device, entry, dims.tile_size),
            view: texture.create_view(&Default::default()),
            texture,
            buffer,
            padded_row,
        }
    }

    /// Per tile, the view-distance `[min, max]` of its samples (min > max: none), after the
    /// frame's one wait.
    fn bounds(
        &self,
        f: &FrameInputs,
        enc: &mut FrameEncoder,
        dims: &GridDims,
    ) -> Result<Vec<[f32; 2]>> {
        let (encoder, timer) = enc.parts();
        let label = "assign: tile depth (fragment)";
        self.pass.draw(
            f.device,
            encoder,
            &f.targets.depth,
            &self.view,
            timer.render_pass(label),
        );
        encoder.copy_texture_to_buffer(
            self.texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &self.buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row),
                    rows_per_image: Some(dims.tiles_y),
                },
            },
            wgpu::Extent3d {
                width: dims.tiles_x,
                height: dims.tiles_y,
                depth_or_array_layers: 1,
            },
        );
        let bytes = enc.download_all(&[(&self.buffer, self.buffer.size())])?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes[0]);
        let row = (self.padded_row / 4) as usize;
        let (near, far) = (f.setup.near, f.setup.far);
        let mut out = Vec::with_capacity(dims.tile_count());
        for ty in 0..dims.tiles_y as usize {
            for tx in 0..dims.tiles_x as usize {
                let at = ty * row + tx * 4;
                let (lo, hi) = (f32::from_bits(words[at]), f32::from_bits(words[at + 1]));
                // Reversed-Z: the greatest depth is the nearest sample.
                out.push(match lo <= hi {
                    true => [
                        crate::depth::view_distance(hi, near, far),
                        crate::depth::view_distance(lo, near, far),
                    ],
                    false => [f32::INFINITY, 0.0],
                });
            }
        }
        Ok(out)
    }
}

/// The last frame's grid as the CPU built it (what analysis reports and the tests check
/// against the oracle; the textures hold exactly these arrays).
pub(crate) struct BuiltTextureGrid {
    pub grid: LightGrid,
    /// Per tile, the view-distance bounds it was built for (`[near, far]` without a pre-pass).
    pub bounds: Vec<[f32; 2]>,
    /// CPU time of `assign_cpu`.
    pub cpu_ms: f64,
}

/// A tiled grid in textures, built on the CPU (see the module docs).
pub(crate) struct TextureGrid {
    last: Option<BuiltTextureGrid>,
    dims: GridDims,
    edge: u32,
    params: wgpu::Buffer,
    cells: wgpu::Texture,
    indices: TexelRows,
    lights: TexelRows,
    layout: wgpu::BindGroupLayout,
    bind_group: wgpu::BindGroup,
    tile_depth: Option<TileDepth>,
}

impl TextureGrid {
    /// Group 1 of the shaders reading it: the uniform, then three unfilterable textures.
    pub fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
        let texture = |binding, sample_type| crate::passes::texture_entry(binding, sample_type);
        let fragment = |mut e: wgpu::BindGroupLayoutEntry| {
            e.visibility = wgpu::ShaderStages::FRAGMENT;
            e
        };
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("texture grid"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                fragment(texture(1, wgpu::TextureSampleType::Uint)),
                fragment(texture(2, wgpu::TextureSampleType::Uint)),
                fragment(texture(
                    3,
                    wgpu::TextureSampleType::Float { filterable: false },
                )),
            ],
        })
    }

    /// `dims`: the tiles (one slice), written into the grid's uniform once; `depth`: bounded
    /// by the pre-pass's depth.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, dims: GridDims, depth: bool) -> Self {
        let edge = device.limits().max_texture_dimension_2d;
        let layout = Self::layout(device);
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("texture grid params"),
            size: std::mem::size_of::<crate::gpu_types::GridParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(&params, 0, bytemuck::bytes_of(&dims.params()));
        let cells = texel_texture(
            device,
            "texture grid cells",
            wgpu::TextureFormat::Rg32Uint,
            (dims.tiles_x, dims.tiles_y),
        );
        let indices = TexelRows::new(
            device,
            "texture grid indices",
            wgpu::TextureFormat::R32Uint,
            edge,
        );
        let lights = TexelRows::new(
            device,
            "texture grid lights",
            wgpu::TextureFormat::Rgba32Float,
            edge,
        );
        let bind_group = Self::bind(device, &layout, &params, &cells, &indices, &lights);
        TextureGrid {
            last: None,
            dims,
            edge,
            params,
            cells,
            indices,
            lights,
            layout,
            bind_group,
            tile_depth: depth.then(|| TileDepth::new(device, &dims)),
        }
    }

    fn bind(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        params: &wgpu::Buffer,
        cells: &wgpu::Texture,
        indices: &TexelRows,
        lights: &TexelRows,
    ) -> wgpu::BindGroup {
        let views =
            [cells, &indices.texture, &lights.texture].map(|t| t.create_view(&Default::default()));
        crate::gpu::bind_resources(
            device,
            "texture grid",
            layout,
            &[
                params.as_entire_binding(),
                wgpu::BindingResource::TextureView(&views[0]),
                wgpu::BindingResource::TextureView(&views[1]),
                wgpu::BindingResource::TextureView(&views[2]),
            ],
        )
    }

    /// Steps 1–3 for frame `f` (after its depth pre-pass, when bounded by depth).
    pub fn encode(&mut self, f: &FrameInputs, enc: &mut FrameEncoder) -> Result<()> {
        let bounds = match &self.tile_depth {
            Some(t) => Some(t.bounds(f, enc, &self.dims)?),
            None => None,
        };
        let range = bounds
            .as_deref()
            .map_or(DepthRange::NearFar, DepthRange::Cells);
        // The world-space lights with the frame's camera (`ViewSetup::to_view` moves them
        // to the eye); the texture gets the camera-relative ones, in the same order.
        let start = web_time::Instant::now();
        let grid = assign_cpu(&f.setup, &self.dims, f.lights, range);
        let cpu_ms = start.elapsed().as_secs_f64() * 1e3;
        check_capacity(self.edge, f.lights.len() as u64, grid.indices.len() as u64)?;
        let (device, queue) = (f.device, f.queue);
        queue.write_texture(
            self.cells.as_image_copy(),
            bytemuck::cast_slice(&grid.cells),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(self.dims.tiles_x * 8),
                rows_per_image: Some(self.dims.tiles_y),
            },
            self.cells.size(),
        );
        let n = grid.indices.len() as u32;
        let mut grown = self
            .indices
            .write(device, queue, bytemuck::cast_slice(&grid.indices), n);
        // The lights, LIGHT_TEXELS texels each, whole lights per row; only the texels used.
        let per_row = self.edge / LIGHT_TEXELS;
        let count = f.gpu_lights.len() as u32;
        let texels = (count / per_row) * self.edge + (count % per_row) * LIGHT_TEXELS;
        let mut data = vec![[0f32; 4]; texels as usize];
        for (i, l) in f.gpu_lights.iter().enumerate() {
            let i = i as u32;
            let at = ((i / per_row) * self.edge + (i % per_row) * LIGHT_TEXELS) as usize;
            let words: &[[f32; 4]] = bytemuck::cast_slice(std::slice::from_ref(l));
            data[at..at + LIGHT_TEXELS as usize].copy_from_slice(words);
        }
        grown |= self
            .lights
            .write(device, queue, bytemuck::cast_slice(&data), texels);
        if grown {
            self.bind_group = Self::bind(
                device,
                &self.layout,
                &self.params,
                &self.cells,
                &self.indices,
                &self.lights,
            );
        }
        let bounds = bounds.unwrap_or_else(|| {
            crate::culling::bounds::cell_bounds::slice_bounds(
                &self.dims,
                [f.setup.near, f.setup.far],
            )
        });
        self.last = Some(BuiltTextureGrid {
            grid,
            bounds,
            cpu_ms,
        });
        Ok(())
    }

    /// The last frame's grid.
    pub fn last(&self) -> Option<&BuiltTextureGrid> {
        self.last.as_ref()
    }

    /// Group 1 of the shading pass.
    pub fn bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_group
    }

    pub fn bind_group_layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }
}
