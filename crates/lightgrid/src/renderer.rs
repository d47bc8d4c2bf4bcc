//! The renderer: owns the targets and scene buffers, runs one registry pipeline for one frame
//! of a scene, tonemaps, reads the image back and collects the frame's statistics.

use crate::consts::{MAX_FRAME_EDGE, MAX_LIGHTS, TILE_LIGHT_BATCH};
use crate::culling::{
    assign_cpu, cell_bounds_cpu, ideal_lighting_computations, DepthRange, GridDims, LightGrid,
    ViewSetup,
};
use crate::error::{Error, Result};
use crate::gpu::{scoped, wait_idle, GpuContext, PassTimer};
use crate::gpu_types::{FrameUniforms, GpuLight};
use crate::memory::{ForwardPlusTable1, FrameMemory, MemoryModel, INDEX_BYTES};
use crate::passes::{scene_layout, Readback, Targets, Tonemap};
use crate::pipelines::{
    self, FrameEncoder, FrameInputs, PipelineContext, RenderSettings, Technique,
};
use crate::scene::Scene;
use crate::stats::{FrameStats, TimingSource};
use image::RgbaImage;
use std::collections::HashMap;
use std::time::Instant;

/// Most passes one frame may record (timestamp slots).
const MAX_PASSES: u32 = 128;

/// An image, its statistics, and what the analysis saw.
pub struct FrameOutput {
    pub image: RgbaImage,
    pub stats: FrameStats,
    /// The grid the pipeline shaded with; for pipelines that build none, the depth-bounded
    /// CPU tile grid used for the ideal count (see `grid_is_pipelines`).
    pub grid: LightGrid,
    pub grid_is_pipelines: bool,
    /// The cell bounds the pipeline's light assignment read (`culling::cell_bounds_cpu` is
    /// their CPU twin); None for pipelines without a grid.
    pub cell_bounds: Option<Vec<[f32; 2]>>,
    /// The frame's depth buffer (row-major, [0, 1], 1 = no geometry).
    pub depth: Vec<f32>,
}

/// A storage/vertex/index buffer that grows to fit.
struct GrowBuffer {
    buffer: wgpu::Buffer,
    usage: wgpu::BufferUsages,
    label: &'static str,
}

impl GrowBuffer {
    fn new(
        device: &wgpu::Device,
        label: &'static str,
        usage: wgpu::BufferUsages,
        size: u64,
    ) -> Self {
        let usage = usage | wgpu::BufferUsages::COPY_DST;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(16),
            usage,
            mapped_at_creation: false,
        });
        GrowBuffer {
            buffer,
            usage,
            label,
        }
    }

    /// Upload `bytes`, reallocating when too small. Returns true when the buffer was replaced.
    fn upload(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, bytes: &[u8]) -> bool {
        let grown = bytes.len() as u64 > self.buffer.size();
        if grown {
            *self = GrowBuffer::new(
                device,
                self.label,
                self.usage,
                (bytes.len() as u64).next_power_of_two(),
            );
        }
        queue.write_buffer(&self.buffer, 0, bytes);
        grown
    }
}

/// Renders frames at one size on one device.
pub struct Renderer<'c> {
    ctx: &'c GpuContext,
    targets: Targets,
    scene_layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
    lights: GrowBuffer,
    materials: GrowBuffer,
    vertices: GrowBuffer,
    indices: GrowBuffer,
    scene_bind_group: wgpu::BindGroup,
    tonemap: Tonemap,
    timer: PassTimer,
    techniques: HashMap<&'static str, Box<dyn Technique>>,
    settings: RenderSettings,
    dims: GridDims,
    readback: Readback,
    counts_readback: Readback,
    depth_readback: Readback,
}

/// The memory section of the stats: the pipeline's model applied to this frame.
fn frame_memory(
    model: MemoryModel,
    (width, height): (u32, u32),
    lighting_computations: Option<u64>,
    grid: Option<&LightGrid>,
) -> FrameMemory {
    let pixels = u64::from(width) * u64::from(height);
    let t = model.traffic;
    let modelled = |per_pixel: u32, per_lit: u32| {
        lighting_computations.map(|n| u64::from(per_pixel) * pixels + u64::from(per_lit) * n)
    };
    FrameMemory {
        bytes_per_pixel: model.bytes_per_pixel(),
        target_bytes: model.target_bytes(width, height),
        grid_bytes: grid
            .map(|g| (g.cells.len() * 8 + g.indices.len() * INDEX_BYTES as usize) as u64),
        modelled_write_bytes: modelled(t.write_per_pixel, t.write_per_lit),
        modelled_read_bytes: modelled(t.read_per_pixel, t.read_per_lit),
        forward_plus_table1: grid
            .map(|g| ForwardPlusTable1::new(pixels, g.average_lights_per_cell(), g.dims.tile_size)),
        targets: model.targets,
        traffic: t,
    }
}

/// Check a frame size against lightgrid's and the adapter's limits.
pub fn validate_size(ctx: &GpuContext, width: u32, height: u32) -> Result<()> {
    let limit = ctx.max_texture_edge().min(MAX_FRAME_EDGE);
    if width == 0 || height == 0 {
        return Err(Error::invalid(
            "size",
            format!("{width}x{height}: both edges must be at least 1"),
        ));
    }
    if width > limit || height > limit {
        return Err(Error::invalid(
            "size",
            format!("{width}x{height}: edges above {limit} are not supported by this adapter"),
        ));
    }
    Ok(())
}

impl<'c> Renderer<'c> {
    pub fn new(
        ctx: &'c GpuContext,
        width: u32,
        height: u32,
        settings: RenderSettings,
    ) -> Result<Self> {
        validate_size(ctx, width, height)?;
        let dims = GridDims::new(width, height, settings.tile_size)?;
        let device = &ctx.device;
        let on_gl = ctx.info.backend == wgpu::Backend::Gl;
        let created = scoped(device, "creating render targets", || {
            let targets = Targets::new(device, width, height);
            let scene_layout = scene_layout(device);
            let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("frame uniforms"),
                size: std::mem::size_of::<FrameUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            use wgpu::BufferUsages as U;
            let lights = GrowBuffer::new(device, "lights", U::STORAGE, 1 << 16);
            let materials = GrowBuffer::new(device, "materials", U::STORAGE, 1 << 12);
            let vertices = GrowBuffer::new(device, "vertices", U::VERTEX, 1 << 20);
            let indices = GrowBuffer::new(device, "indices", U::INDEX, 1 << 20);
            let scene_bind_group =
                Self::bind_scene(device, &scene_layout, &uniforms, &lights, &materials);
            Renderer {
                ctx,
                targets,
                tonemap: Tonemap::new(device),
                timer: PassTimer::new(ctx, MAX_PASSES),
                scene_layout,
                uniforms,
                lights,
                materials,
                vertices,
                indices,
                scene_bind_group,
                techniques: HashMap::new(),
                settings,
                dims,
                readback: Readback::new(device, "image readback", width, height),
                counts_readback: Readback::new(device, "counts readback", width, height),
                depth_readback: Readback::new(device, "depth readback", width, height),
            }
        });
        created.map_err(|e| match e {
            Error::Gpu { stage, message } if on_gl => Error::Gpu {
                stage,
                message: format!(
                    "{message}\nThe GL backend (llvmpipe GL) lacks features lightgrid's render targets need; \
                     use a Vulkan adapter (`sudo apt-get install -y mesa-vulkan-drivers libvulkan1`, then --adapter vulkan)"
                ),
            },
            e => e,
        })
    }

    fn bind_scene(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        uniforms: &wgpu::Buffer,
        lights: &GrowBuffer,
        materials: &GrowBuffer,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene (group 0)"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: lights.buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: materials.buffer.as_entire_binding(),
                },
            ],
        })
    }

    pub fn size(&self) -> (u32, u32) {
        (self.targets.width, self.targets.height)
    }

    pub fn settings(&self) -> RenderSettings {
        self.settings
    }

    fn prepare_technique(&mut self, id: &str) -> Result<()> {
        let info = pipelines::find(id)?;
        if !self.techniques.contains_key(info.id) {
            let device = &self.ctx.device;
            let ctx = PipelineContext {
                device,
                scene_layout: &self.scene_layout,
                dims: self.dims,
                settings: self.settings,
                count_blend: self.ctx.count_blend,
                software_adapter: self.ctx.is_software(),
                loop_budget: self.ctx.loop_budget(),
            };
            let t = scoped(device, &format!("creating pipeline {}", info.id), || {
                (info.create)(&ctx)
            })?;
            self.techniques.insert(info.id, t);
        }
        Ok(())
    }

    /// Render `frame` of `scene` with pipeline `pipeline_id`.
    pub fn render(&mut self, scene: &Scene, frame: u32, pipeline_id: &str) -> Result<FrameOutput> {
        let frames = scene.frame_count();
        if frame >= frames {
            return Err(Error::invalid(
                "frame",
                format!(
                    "{frame} is past the end of {} (frames 0..={})",
                    scene.name,
                    frames - 1
                ),
            ));
        }
        let state = scene.frame(frame);
        if state.lights.len() > MAX_LIGHTS as usize {
            return Err(Error::invalid(
                "lights",
                format!(
                    "{} lights exceed the maximum of {MAX_LIGHTS}",
                    state.lights.len()
                ),
            ));
        }
        for (i, l) in state.lights.iter().enumerate() {
            l.validate(i)?;
        }
        let (vertices, indices) = scene.geometry(&state);
        let (width, height) = self.size();
        let view = state.camera.view();
        let proj = state.camera.proj(width as f32 / height as f32);
        let view_proj = proj * view;
        let uniforms = FrameUniforms {
            view: view.to_cols_array_2d(),
            proj: proj.to_cols_array_2d(),
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            camera_pos: state.camera.eye.to_array(),
            light_count: state.lights.len() as u32,
            viewport: [width as f32, height as f32],
            near: state.camera.near,
            far: state.camera.far,
        };
        let gpu_lights: Vec<GpuLight> = state.lights.iter().map(|l| l.to_gpu()).collect();
        let materials = scene.materials_gpu();

        self.prepare_technique(pipeline_id)?;
        let device = &self.ctx.device;
        let queue = &self.ctx.queue;
        let mut rebind = self
            .lights
            .upload(device, queue, bytemuck::cast_slice(&gpu_lights));
        rebind |= self
            .materials
            .upload(device, queue, bytemuck::cast_slice(&materials));
        if rebind {
            self.scene_bind_group = Self::bind_scene(
                device,
                &self.scene_layout,
                &self.uniforms,
                &self.lights,
                &self.materials,
            );
        }
        self.vertices
            .upload(device, queue, bytemuck::cast_slice(&vertices));
        self.indices
            .upload(device, queue, bytemuck::cast_slice(&indices));
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&uniforms));

        let info = pipelines::find(pipeline_id)?;
        let budget = self.ctx.loop_budget();
        if let Some(budget) = budget {
            let lights = state.lights.len() as u64;
            if info.light_loop == pipelines::LightLoop::AllLights && lights > budget {
                return Err(Error::loop_budget(info.id, lights, budget));
            }
        }
        let setup = ViewSetup::new(&state.camera, width, height);
        let technique = self.techniques.get_mut(info.id).expect("prepared above");
        self.timer.reset();
        let start = Instant::now();
        let inputs = FrameInputs {
            device,
            queue,
            scene_bind_group: &self.scene_bind_group,
            vertices: &self.vertices.buffer,
            indices: &self.indices.buffer,
            index_count: indices.len() as u32,
            targets: &self.targets,
            setup,
            lights: &state.lights,
            count_blend: self.ctx.count_blend,
        };
        let mut enc = FrameEncoder::new(device, queue, &mut self.timer);
        let pipeline_grid = technique.render(&inputs, &mut enc)?;
        let mut encoder = enc.finish();
        self.tonemap.encode(
            device,
            &mut encoder,
            &mut self.timer,
            &self.targets.hdr,
            &self.targets.ldr,
        );
        self.readback.encode(
            &mut encoder,
            &self.targets.ldr_texture,
            wgpu::TextureAspect::All,
        );
        self.counts_readback.encode(
            &mut encoder,
            &self.targets.counts_texture,
            wgpu::TextureAspect::All,
        );
        self.depth_readback.encode(
            &mut encoder,
            &self.targets.depth_texture,
            wgpu::TextureAspect::DepthOnly,
        );
        self.timer.resolve(&mut encoder);
        scoped(device, &format!("rendering with {}", info.id), || {
            queue.submit([encoder.finish()])
        })?;
        wait_idle(device)?;
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        let (passes, span) = self.timer.read(device)?;
        let image =
            RgbaImage::from_raw(width, height, self.readback.read(device)?).expect("size matches");
        let depth: Vec<f32> = self.depth_readback.read_f32(device)?;
        let lighting_computations = if self.ctx.count_blend {
            let counts: Vec<f32> = self.counts_readback.read_f32(device)?;
            Some(counts.iter().map(|&c| c as f64).sum::<f64>().round() as u64)
        } else {
            None
        };

        // The ideal: for each visible sample, the lights reaching it. The depth-bounded CPU
        // grid narrows the search (it provably contains every such light).
        let view_distance: Vec<f32> = depth
            .iter()
            .map(|&d| {
                if d < 1.0 {
                    setup.view_distance(d)
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        let bounds = cell_bounds_cpu(&setup, &self.dims, &depth);
        let bounded = assign_cpu(
            &setup,
            &self.dims,
            &state.lights,
            DepthRange::Cells(&bounds),
        );
        let ideal = ideal_lighting_computations(&setup, &bounded, &state.lights, &view_distance);
        if let Some(budget) =
            budget.filter(|_| info.light_loop == pipelines::LightLoop::TileBatches)
        {
            // The kernel loops over its tile's list plus a few iterations per batch. Its own
            // list comes from a slightly looser test than the depth-bounded CPU grid's, so the
            // estimate keeps a 10% margin below the budget.
            let batches = (state.lights.len() as u64).div_ceil(u64::from(TILE_LIGHT_BATCH));
            let estimate = u64::from(bounded.max_lights_per_cell()) + 6 * batches;
            if estimate > budget * 9 / 10 {
                return Err(Error::loop_budget(info.id, estimate, budget));
            }
        }
        let (gpu_ms, timing) = match span {
            Some(ms) => (ms, TimingSource::GpuTimestamps),
            None => (wall_ms, TimingSource::WallClock),
        };
        let grid_is_pipelines = pipeline_grid.is_some();
        let assign_gpu_ms = passes
            .iter()
            .filter(|p| p.label.starts_with("assign:"))
            .map(|p| p.ms)
            .reduce(|a, b| a + b);
        let (grid, cell_bounds, assign, assign_cpu_ms, assign_ms, assign_reruns) =
            match pipeline_grid {
                Some(b) => (
                    b.grid,
                    Some(b.cell_bounds),
                    Some(b.assign.name().to_string()),
                    Some(b.cpu_ms),
                    Some(b.wall_ms),
                    Some(b.reruns),
                ),
                None => (bounded, None, None, None, None, None),
            };
        let occupied = cell_bounds
            .as_ref()
            .map(|b| b.iter().filter(|[lo, hi]| lo <= hi).count() as u64);
        let memory = frame_memory(
            (info.memory)(&self.settings),
            (width, height),
            lighting_computations,
            grid_is_pipelines.then_some(&grid),
        );
        Ok(FrameOutput {
            image,
            stats: FrameStats {
                scene: scene.name.clone(),
                pipeline: info.id.to_string(),
                adapter: self.ctx.adapter_label(),
                width,
                height,
                frame,
                lights: state.lights.len() as u32,
                triangles: (indices.len() / 3) as u32,
                gpu_ms,
                timing,
                wall_ms,
                passes,
                tile_size: self.settings.tile_size,
                gbuffer_bits: self.settings.gbuffer.bits(),
                lighting_computations,
                ideal_lighting_computations: ideal,
                efficiency: lighting_computations
                    .filter(|&n| n > 0)
                    .map(|n| ideal as f64 / n as f64),
                lights_per_tile_avg: grid_is_pipelines.then(|| grid.average_lights_per_cell()),
                lights_per_tile_max: grid_is_pipelines.then(|| grid.max_lights_per_cell()),
                grid_indices: grid_is_pipelines.then_some(grid.indices.len() as u64),
                grid_cells: grid_is_pipelines.then_some(grid.cells.len() as u64),
                grid_cells_occupied: occupied,
                assign,
                assign_gpu_ms: assign_gpu_ms.filter(|_| grid_is_pipelines),
                assign_cpu_ms,
                assign_ms,
                assign_reruns,
                memory,
            },
            grid,
            grid_is_pipelines,
            cell_bounds,
            depth,
        })
    }
}
