//! GPU gather (forward-plus §4): one workgroup per tile tests every light against the tile's
//! frustum (side planes + the depth bounds from `DepthBoundsPass`), and its CPU twin
//! [`assign_gather_cpu`], which runs the same test in the same f32 arithmetic.
//!
//! Inputs: group 0 (frame, lights), the per-tile depth bounds buffer. Outputs: the grid's
//! `cells` and `indices` buffers in `GridBuffers` (the shading passes bind them as group 1).
//! Steps, one workgroup of TILE_THREADS² per tile unless noted:
//! 1. `count_main`: lights per tile;
//! 2. `scan_main` (one workgroup): exclusive prefix sum → offsets and the total, read back so
//!    the index buffer is grown to fit before
//! 3. `write_main`: the same test again, hits appended at the tile's offset.
//!    The grid is then read back for statistics and tests.

use super::{DepthBoundsPass, GridBuffers, GridDims, LightGrid, ViewSetup};
use crate::error::{Error, Result};
use crate::gpu::read_buffer;
use crate::pipelines::{FrameEncoder, FrameInputs};
use crate::scene::PointLight;
use crate::shader::{compose, compute_pipeline, src, ComposedShader};
use glam::Vec3;

pub(crate) fn shader() -> ComposedShader {
    compose(
        "gather",
        &[
            src::TYPES,
            src::SCENE_BINDINGS,
            super::TILE_FRUSTUM_WGSL,
            include_str!("gather.wgsl"),
        ],
    )
}

/// Relative slack of the depth test, as in `tile_frustum.wgsl`.
const DEPTH_SLACK: f32 = 1e-4;

/// A tile's frustum on the CPU, computed exactly as `tile_frustum` in WGSL.
struct CpuFrustum {
    planes: [Vec3; 4],
    w_min: f32,
    w_max: f32,
}

fn cpu_frustum(setup: &ViewSetup, dims: &GridDims, t: usize, ndc_bounds: [f32; 2]) -> CpuFrustum {
    let (x0, y0, _, _) = dims.tile_rect(t);
    let size = (setup.width as f32, setup.height as f32);
    let ts = dims.tile_size as f32;
    let lo = (x0 as f32, y0 as f32);
    let hi = ((lo.0 + ts).min(size.0), (lo.1 + ts).min(size.1));
    let ndc_lo = (lo.0 / size.0 * 2.0 - 1.0, 1.0 - lo.1 / size.1 * 2.0);
    let ndc_hi = (hi.0 / size.0 * 2.0 - 1.0, 1.0 - hi.1 / size.1 * 2.0);
    CpuFrustum {
        planes: [
            Vec3::new(1.0, 0.0, ndc_lo.0 / setup.p00).normalize(),
            Vec3::new(-1.0, 0.0, -ndc_hi.0 / setup.p00).normalize(),
            Vec3::new(0.0, 1.0, ndc_hi.1 / setup.p11).normalize(),
            Vec3::new(0.0, -1.0, -ndc_lo.1 / setup.p11).normalize(),
        ],
        w_min: setup.view_distance(ndc_bounds[0]),
        w_max: setup.view_distance(ndc_bounds[1]),
    }
}

/// How far inside the tile's frustum the light is (≥ 0: inside, as `light_in_tile` decides);
/// `-inf` for a tile without samples. Tests use its size to recognise round-off cases.
fn margin(f: &CpuFrustum, center: Vec3, r: f32) -> f32 {
    if f.w_min > f.w_max {
        return f32::NEG_INFINITY;
    }
    let w = -center.z;
    let mut m =
        (w + r - f.w_min * (1.0 - DEPTH_SLACK)).min(f.w_max * (1.0 + DEPTH_SLACK) - (w - r));
    for p in &f.planes {
        m = m.min(p.dot(center) + r);
    }
    m
}

/// Per tile and light, the gather test's margin (row-major tiles, lights in order).
pub fn gather_margins(
    setup: &ViewSetup,
    dims: &GridDims,
    lights: &[PointLight],
    ndc_bounds: &[[f32; 2]],
) -> Vec<Vec<f32>> {
    let centers: Vec<(Vec3, f32)> = lights
        .iter()
        .map(|l| (setup.view.transform_point3(l.position), l.range))
        .collect();
    (0..dims.tile_count())
        .map(|t| {
            let f = cpu_frustum(setup, dims, t, ndc_bounds[t]);
            centers.iter().map(|(c, r)| margin(&f, *c, *r)).collect()
        })
        .collect()
}

/// CPU twin of the GPU gather: the same inputs (tile depth bounds as depth-buffer values) and
/// the same grid (lists in light order; the GPU's order varies).
pub fn assign_gather_cpu(
    setup: &ViewSetup,
    dims: &GridDims,
    lights: &[PointLight],
    ndc_bounds: &[[f32; 2]],
) -> LightGrid {
    let lists: Vec<Vec<u32>> = gather_margins(setup, dims, lights, ndc_bounds)
        .into_iter()
        .map(|m| {
            m.iter()
                .enumerate()
                .filter(|(_, &x)| x >= 0.0)
                .map(|(i, _)| i as u32)
                .collect()
        })
        .collect();
    LightGrid::from_lists(*dims, &lists)
}

/// The GPU gather stage.
pub struct GatherPass {
    layout: wgpu::BindGroupLayout,
    count: wgpu::ComputePipeline,
    scan: wgpu::ComputePipeline,
    write: wgpu::ComputePipeline,
    totals: wgpu::Buffer,
    totals_readback: wgpu::Buffer,
    cells_readback: wgpu::Buffer,
    indices_readback: wgpu::Buffer,
    dims: GridDims,
}

fn map_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

impl GatherPass {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        dims: GridDims,
    ) -> Self {
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let rw = wgpu::BufferBindingType::Storage { read_only: false };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gather (group 1)"),
            entries: &[
                entry(0, wgpu::BufferBindingType::Uniform),
                entry(1, wgpu::BufferBindingType::Storage { read_only: true }),
                entry(2, rw),
                entry(3, rw),
                entry(4, rw),
            ],
        });
        let s = shader();
        let layouts = [Some(scene_layout), Some(&layout)];
        let pipeline =
            |label: &str, entry: &str| compute_pipeline(device, label, &s, entry, &layouts);
        GatherPass {
            count: pipeline("gather count", "count_main"),
            scan: pipeline("gather scan", "scan_main"),
            write: pipeline("gather write", "write_main"),
            layout,
            totals: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("gather totals"),
                size: 8,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            totals_readback: map_buffer(device, "gather totals readback", 8),
            cells_readback: map_buffer(
                device,
                "gather cells readback",
                (dims.tile_count() * 8) as u64,
            ),
            indices_readback: map_buffer(device, "gather indices readback", 1 << 16),
            dims,
        }
    }

    fn bind(
        &self,
        device: &wgpu::Device,
        grid: &GridBuffers,
        bounds: &DepthBoundsPass,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gather"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: grid.params_buffer().as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: bounds.bounds_buffer().as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: grid.cells_buffer().as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: grid.indices_buffer().as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: self.totals.as_entire_binding(),
                },
            ],
        })
    }

    fn dispatch(
        &self,
        enc: &mut FrameEncoder,
        f: &FrameInputs,
        pipeline: &wgpu::ComputePipeline,
        group: &wgpu::BindGroup,
        label: &str,
        size: (u32, u32),
    ) {
        let (encoder, timer) = enc.parts();
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: timer.compute_pass(label),
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, f.scene_bind_group, &[]);
        pass.set_bind_group(1, group, &[]);
        pass.dispatch_workgroups(size.0, size.1, 1);
    }

    /// Build the grid on the GPU from the bounds `bounds` has computed in this frame (already
    /// recorded in `enc`). Leaves the grid in `grid` for shading and returns its CPU copy.
    pub fn run(
        &mut self,
        f: &FrameInputs,
        enc: &mut FrameEncoder,
        bounds: &DepthBoundsPass,
        grid: &mut GridBuffers,
    ) -> Result<LightGrid> {
        let d = self.dims;
        grid.ensure(f.device, f.queue, &d, d.tile_count(), 1);
        let group = self.bind(f.device, grid, bounds);
        self.dispatch(
            enc,
            f,
            &self.count,
            &group,
            "gather count",
            (d.tiles_x, d.tiles_y),
        );
        self.dispatch(enc, f, &self.scan, &group, "gather scan", (1, 1));
        enc.parts()
            .0
            .copy_buffer_to_buffer(&self.totals, 0, &self.totals_readback, 0, 8);
        enc.submit_and_wait()?;
        let total = u32::from_le_bytes(
            read_buffer(f.device, &self.totals_readback)?[..4]
                .try_into()
                .expect("4 bytes"),
        );
        // Grow the index list to the counted total (the bind group follows the buffer).
        grid.ensure(f.device, f.queue, &d, d.tile_count(), total as usize);
        let group = self.bind(f.device, grid, bounds);
        self.dispatch(
            enc,
            f,
            &self.write,
            &group,
            "gather write",
            (d.tiles_x, d.tiles_y),
        );
        let index_bytes = u64::from(total) * 4;
        if index_bytes > self.indices_readback.size() {
            self.indices_readback = map_buffer(
                f.device,
                "gather indices readback",
                index_bytes.next_power_of_two(),
            );
        }
        {
            let (encoder, _) = enc.parts();
            encoder.copy_buffer_to_buffer(&self.totals, 0, &self.totals_readback, 0, 8);
            encoder.copy_buffer_to_buffer(
                grid.cells_buffer(),
                0,
                &self.cells_readback,
                0,
                (d.tile_count() * 8) as u64,
            );
            if index_bytes > 0 {
                encoder.copy_buffer_to_buffer(
                    grid.indices_buffer(),
                    0,
                    &self.indices_readback,
                    0,
                    index_bytes,
                );
            }
        }
        enc.submit_and_wait()?;
        let totals = read_buffer(f.device, &self.totals_readback)?;
        let overflow = u32::from_le_bytes(totals[4..8].try_into().expect("4 bytes"));
        if overflow > 0 {
            return Err(Error::Gpu {
                stage: "GPU gather".into(),
                message: format!("{overflow} light indices did not fit the counted lists (count and write passes disagree)"),
            });
        }
        let cells_bytes = read_buffer(f.device, &self.cells_readback)?;
        let cells: Vec<[u32; 2]> =
            bytemuck::cast_slice(&cells_bytes[..d.tile_count() * 8]).to_vec();
        let indices: Vec<u32> = if index_bytes > 0 {
            bytemuck::cast_slice(
                &read_buffer(f.device, &self.indices_readback)?[..index_bytes as usize],
            )
            .to_vec()
        } else {
            Vec::new()
        };
        Ok(LightGrid {
            dims: d,
            cells,
            indices,
        })
    }
}
