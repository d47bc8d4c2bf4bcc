//! One description, one grid: the renderer's grid for a `CullConfig` and a caller's
//! `LightCuller::new` with the same config, handed the renderer's depth, lights and camera,
//! hold the same lists, cell for cell, on robots-many with and without glass (transparent
//! lists), tiles and clusters, every strategy (`cpu` and `bvh` given the lights on the CPU).
//! Public API only: `Renderer`, `LightCuller`, `CullConfig`.
//!
//! The offsets into the index list and the order of a cell's lights follow the order the
//! GPU's workgroups finish in (an atomic cursor), so two runs of the same grid differ there;
//! the cells' slicing and each cell's set of lights do not, and are compared exactly.

mod common;

use lightgrid::culling::LightGrid;
use lightgrid::pipelines::ids;
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::{Assign, CullConfig, CullInputs, FrameOutput, LightCuller, RenderSettings};
use lightgrid::{DepthBounds, Renderer};

const SIZE: (u32, u32) = (160, 90);
const FRAME: u32 = 200;

/// Each cell's lights, sorted.
fn lists(g: &LightGrid) -> Vec<Vec<u32>> {
    (0..g.dims.cell_count())
        .map(|c| {
            let mut l = g.cell(c).to_vec();
            l.sort_unstable();
            l
        })
        .collect()
}

/// A depth texture holding exactly `values` (row-major), written by a full-screen pass
/// (a depth texture is not a copy destination).
fn depth_texture(device: &wgpu::Device, queue: &wgpu::Queue, values: &[f32]) -> wgpu::Texture {
    use wgpu::util::DeviceExt;
    let (w, h) = SIZE;
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("caller depth"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let source = format!(
        "@group(0) @binding(0) var<storage, read> depth: array<f32>;
         @vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {{
             let p = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
             return vec4<f32>(p * 2.0 - 1.0, 0.0, 1.0);
         }}
         @fragment fn fs(@builtin(position) pos: vec4<f32>) -> @builtin(frag_depth) f32 {{
             return depth[u32(pos.y) * {w}u + u32(pos.x)];
         }}"
    );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("depth writer"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("depth writer"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[],
        }),
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        multiview_mask: None,
        cache: None,
    });
    let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("depth values"),
        contents: bytemuck::cast_slice(values),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("depth values"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: buffer.as_entire_binding(),
        }],
    });
    let view = texture.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("depth writer"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
    }
    queue.submit([encoder.finish()]);
    texture
}

/// What a caller's culler built for `config` from the renderer's frame `out`: its depth, the
/// scene's lights moved camera-relative as the renderer uploads them, and its camera (the
/// view a rotation, the eye at the origin).
fn callers_grid(
    ctx: &lightgrid::gpu::GpuContext,
    scene: &lightgrid::scene::Scene,
    out: &FrameOutput,
    config: CullConfig,
    transparent: bool,
) -> LightGrid {
    let (device, queue) = (&ctx.device, &ctx.queue);
    let setup = out.setup;
    let depth = depth_texture(device, queue, &out.depth);
    let depth_view = depth.create_view(&Default::default());
    let state = scene.frame(FRAME);
    let lights: Vec<lightgrid::testing::gpu_types::GpuLight> = state
        .lights
        .iter()
        .map(|l| l.relative_to(setup.eye).to_gpu())
        .collect();
    let buffer = {
        use wgpu::util::DeviceExt;
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("caller lights"),
            contents: bytemuck::cast_slice(&lights),
            usage: wgpu::BufferUsages::STORAGE,
        })
    };
    let proj = state.camera.proj(SIZE.0 as f32 / SIZE.1 as f32);
    assert_eq!(
        (proj.x_axis.x, proj.y_axis.y),
        (setup.p00, setup.p11),
        "the renderer's projection"
    );
    let mut culler = LightCuller::new(device, queue, config).expect("the same config");
    let inputs = CullInputs {
        depth: Some(&depth_view),
        transparent,
        // The same lights on the CPU (`cpu` and `bvh` assign there).
        cpu_lights: Some(bytemuck::cast_slice(&lights)),
        lights: &buffer,
        light_count: lights.len() as u32,
        view: setup.view.to_cols_array_2d(),
        proj: proj.to_cols_array_2d(),
        near: setup.near,
        far: setup.far,
        viewport: [SIZE.0, SIZE.1],
    };
    // A frame whose lists did not fit is culled again (they grew from its report), as the
    // renderer re-renders one.
    let mut reports = Vec::new();
    for _ in 0..2 {
        let mut encoder = device.create_command_encoder(&Default::default());
        culler
            .encode(&mut encoder, &inputs)
            .expect("the renderer's frame is a caller's frame");
        queue.submit([encoder.finish()]);
        reports = culler.wait().unwrap();
        if !reports.iter().any(|r| r.overflowed) {
            break;
        }
    }
    assert!(reports.iter().all(|r| r.is_complete()), "{reports:?}");
    culler.read_grid().unwrap()
}

#[test]
fn the_renderers_grid_is_a_callers_with_the_same_config() {
    let ctx = common::gpu();
    // Every strategy (`cpu` and `bvh` given the lights on the CPU as well); with glass, the
    // caller asks for transparent lists (`CullInputs::transparent`) as the renderer builds them.
    let offered: Vec<Assign> = lightgrid::testing::STRATEGIES
        .iter()
        .map(|s| s.assign)
        .collect();
    for transparency in [false, true] {
        let params = SceneParams {
            transparency,
            ..SceneParams::default()
        };
        let scene = catalog::build("robots-many", &params).unwrap();
        parity(&ctx, &scene, &offered, transparency);
    }
}

/// The renderer's grid and a caller's for every strategy in `offered`, tiles and clusters.
fn parity(
    ctx: &lightgrid::gpu::GpuContext,
    scene: &lightgrid::scene::Scene,
    offered: &[Assign],
    transparency: bool,
) {
    for (pipeline, slices) in [(ids::TILED_DEFERRED, 1), (ids::CLUSTERED_DEFERRED, 16)] {
        for &strategy in offered {
            let config = CullConfig {
                strategy,
                slices,
                ..CullConfig::default()
            };
            let settings = RenderSettings {
                grid: config,
                ..RenderSettings::default()
            };
            let mut renderer = Renderer::new(ctx, SIZE.0, SIZE.1, settings).unwrap();
            let out = renderer.render(scene, FRAME, pipeline).unwrap();
            assert!(out.grid_is_pipelines, "{pipeline}");
            let what = format!("{pipeline} {strategy:?} transparency {transparency}");
            let ours = lists(&out.grid);
            assert!(ours.iter().any(|l| !l.is_empty()), "{what}: an empty grid");
            let callers = callers_grid(ctx, scene, &out, config, transparency);
            assert_eq!(callers.dims, out.grid.dims, "{what}: the cells");
            assert_eq!(lists(&callers), ours, "{what}: the lists");
            // The comparison can fail: a caller's grid with another description differs.
            if strategy == Assign::Gather {
                let other = CullConfig {
                    depth_bounds: DepthBounds::None,
                    ..config
                };
                let theirs = callers_grid(ctx, scene, &out, other, transparency);
                assert_ne!(
                    lists(&theirs),
                    ours,
                    "{what}: near..far bounds change nothing"
                );
            }
        }
    }
}
