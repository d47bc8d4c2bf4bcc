//! Embedding lightgrid's light grid in a wgpu renderer of your own (README, "Embedding").
//!
//! Everything here is this program's: the device, the mesh (a floor and a field of boxes),
//! the depth pre-pass, the lights in a buffer of `CullLight`s (colour in the payload), and
//! the forward shader with its own light function. lightgrid only culls: `LightCuller::encode`
//! after the depth pre-pass, `LightCuller::wgsl` in the shader, `bind_group` at group 1.
//! The same frame is then shaded by looping over every light; the program prints how far the
//! two images are apart and exits non-zero beyond the tolerance lightgrid's tests hold
//! `tiled_forward` to (mean 0.01, p99 1, no pixel over 4 levels).
//!
//! `cargo run --release -p lightgrid --example embed -- --out embed.png`

use glam::{Mat4, Vec3, Vec4};
use lightgrid::{CullConfig, CullGrid, CullInputs, CullLight, LightCuller};
use wgpu::util::DeviceExt;

const W: u32 = 640;
const H: u32 = 360;
const NEAR: f32 = 0.1;
const FAR: f32 = 200.0;
const LIGHTS: usize = 400;

const SHADER: &str = r#"
struct Camera { view_proj: mat4x4<f32>, view: mat4x4<f32>, eye: vec3<f32>, count: u32 }
struct MyLight { position: vec3<f32>, range: f32, color: vec4<f32>, direction: vec3<f32>, cos_outer: f32 }
@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<storage, read> lights: array<MyLight>;

struct V { @builtin(position) clip: vec4<f32>, @location(0) world: vec3<f32>, @location(1) normal: vec3<f32>, @location(2) dist: f32 }

@vertex fn vs(@location(0) p: vec3<f32>, @location(1) n: vec3<f32>) -> V {
    let view = camera.view * vec4<f32>(p, 1.0);
    return V(camera.view_proj * vec4<f32>(p, 1.0), p, n, -view.z);
}

// This program's light function: Lambert, a smooth range falloff, a spot cone.
fn light(l: MyLight, v: V) -> vec3<f32> {
    let d = l.position - v.world;
    let dist = length(d);
    if (dist >= l.range) { return vec3<f32>(0.0); }
    var k = pow(1.0 - dist / l.range, 2.0) * max(dot(normalize(v.normal), d / dist), 0.0);
    if (l.cos_outer > -1.5) {
        k *= smoothstep(l.cos_outer, l.cos_outer + 0.05, dot(-d / dist, l.direction));
    }
    return l.color.rgb * l.color.a * k;
}

fn tone(c: vec3<f32>) -> vec4<f32> { return vec4<f32>(1.0 - exp(-(c + 0.02)), 1.0); }

@fragment fn fs_grid(v: V) -> @location(0) vec4<f32> {
    let cell = light_grid_cell(v.clip.xy, v.dist);
    var c = vec3<f32>(0.0);
    for (var i = 0u; i < light_grid_count(cell); i++) {
        c += light(lights[light_grid_light(cell, i)], v);
    }
    return tone(c);
}

@fragment fn fs_all(v: V) -> @location(0) vec4<f32> {
    var c = vec3<f32>(0.0);
    for (var i = 0u; i < camera.count; i++) {
        c += light(lights[i], v);
    }
    return tone(c);
}
"#;

/// A floor and 7 × 7 boxes of varied heights: positions and normals, and indices.
fn mesh() -> (Vec<[f32; 6]>, Vec<u32>) {
    let (mut v, mut idx) = (Vec::new(), Vec::new());
    let mut quad = |c: [Vec3; 4], n: Vec3| {
        let base = v.len() as u32;
        v.extend(c.map(|p| [p.x, p.y, p.z, n.x, n.y, n.z]));
        idx.extend([0, 1, 2, 0, 2, 3].map(|i| base + i));
    };
    let s = 30.0;
    quad([Vec3::new(-s, 0.0, s), Vec3::new(s, 0.0, s), Vec3::new(s, 0.0, -s), Vec3::new(-s, 0.0, -s)], Vec3::Y);
    for i in 0..49 {
        let c = Vec3::new((i % 7) as f32 * 6.0 - 18.0, 0.0, (i / 7) as f32 * 6.0 - 18.0);
        let (h, e) = (1.0 + (i * 7 % 5) as f32, 1.2);
        let p = |x: f32, y: f32, z: f32| c + Vec3::new(x * e, y * h, z * e);
        quad([p(-1., 1., 1.), p(1., 1., 1.), p(1., 1., -1.), p(-1., 1., -1.)], Vec3::Y);
        quad([p(-1., 0., 1.), p(1., 0., 1.), p(1., 1., 1.), p(-1., 1., 1.)], Vec3::Z);
        quad([p(1., 0., -1.), p(-1., 0., -1.), p(-1., 1., -1.), p(1., 1., -1.)], -Vec3::Z);
        quad([p(1., 0., 1.), p(1., 0., -1.), p(1., 1., -1.), p(1., 1., 1.)], Vec3::X);
        quad([p(-1., 0., -1.), p(-1., 0., 1.), p(-1., 1., 1.), p(-1., 1., -1.)], -Vec3::X);
    }
    (v, idx)
}

/// Lights over the floor, a fifth of them spots pointing down; colour and intensity in the
/// payload.
fn lights() -> Vec<CullLight> {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut r = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 40) as f32 / (1u64 << 24) as f32
    };
    (0..LIGHTS)
        .map(|i| {
            let p = [r() * 56.0 - 28.0, 0.3 + r() * 3.0, r() * 56.0 - 28.0];
            let color = [0.3 + r(), 0.3 + r(), 0.3 + r(), 2.0];
            if i % 5 == 0 {
                CullLight::spot(p, 3.0 + r() * 4.0, [0.0, -1.0, 0.0], 0.75, color)
            } else {
                CullLight::point(p, 2.0 + r() * 3.0, color)
            }
        })
        .collect()
}

fn target(device: &wgpu::Device, format: wgpu::TextureFormat, usage: wgpu::TextureUsages) -> wgpu::TextureView {
    let size = wgpu::Extent3d { width: W, height: H, depth_or_array_layers: 1 };
    device
        .create_texture(&wgpu::TextureDescriptor {
            label: None,
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: usage | wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("embed: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let out = match args.iter().position(|a| a == "--out") {
        Some(i) => Some(args.get(i + 1).ok_or("--out needs a file name")?.clone()),
        None => None,
    };
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_limits: LightCuller::required_limits(&adapter),
        ..Default::default()
    }))?;
    println!("adapter: {}", adapter.get_info().name);

    // This renderer's camera: right-handed, standard depth (0 at near, cleared to 1).
    let eye = Vec3::new(0.0, 14.0, 30.0);
    let f = (Vec3::ZERO - eye).normalize();
    let (s, u) = (f.cross(Vec3::Y).normalize(), f.cross(Vec3::Y).normalize().cross(f));
    let rot = Mat4::from_cols(Vec4::new(s.x, u.x, -f.x, 0.), Vec4::new(s.y, u.y, -f.y, 0.), Vec4::new(s.z, u.z, -f.z, 0.), Vec4::W);
    let view = rot * Mat4::from_translation(-eye);
    let (h, a, b) = (1.0 / 0.45f32.tan(), NEAR * FAR / (NEAR - FAR), FAR / (NEAR - FAR));
    let proj = Mat4::from_cols(Vec4::new(h * H as f32 / W as f32, 0., 0., 0.), Vec4::new(0., h, 0., 0.), Vec4::new(0., 0., b, -1.), Vec4::new(0., 0., a, 0.));

    let (vertices, indices) = mesh();
    let lights = lights();
    let init = |contents: &[u8], usage| device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents, usage });
    let vbuf = init(bytemuck::cast_slice(&vertices), wgpu::BufferUsages::VERTEX);
    let ibuf = init(bytemuck::cast_slice(&indices), wgpu::BufferUsages::INDEX);
    let light_buf = init(bytemuck::cast_slice(&lights), wgpu::BufferUsages::STORAGE);
    let mut cam = (proj * view).to_cols_array().to_vec();
    cam.extend(view.to_cols_array());
    cam.extend([eye.x, eye.y, eye.z, f32::from_bits(LIGHTS as u32)]);
    let cam_buf = init(bytemuck::cast_slice(&cam), wgpu::BufferUsages::UNIFORM);

    // lightgrid: the culler, and its WGSL in front of this program's shader.
    let mut culler = LightCuller::new(&device, &queue, CullConfig { grid: CullGrid::Clusters { tile_size: 16, slices: 24 }, ..CullConfig::default() })?;
    let source = format!("{}\n{}", LightCuller::wgsl(1), SHADER);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor { label: None, source: wgpu::ShaderSource::Wgsl(source.into()) });

    let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
        count: None,
    };
    let own = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &[entry(0, wgpu::BufferBindingType::Uniform), entry(1, wgpu::BufferBindingType::Storage { read_only: true })],
    });
    let group0 = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &own,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: cam_buf.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: light_buf.as_entire_binding() },
        ],
    });
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &[Some(&own), Some(culler.bind_group_layout())],
        immediate_size: 0,
    });
    let color = wgpu::TextureFormat::Rgba8Unorm;
    let pipeline = |fs: Option<&str>, write: bool| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: fs,
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[wgpu::VertexBufferLayout {
                    array_stride: 24,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3],
                }],
            },
            fragment: fs.map(|fs| wgpu::FragmentState {
                module: &module,
                entry_point: Some(fs),
                compilation_options: Default::default(),
                targets: &[Some(color.into())],
            }),
            primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Back), ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(write),
                depth_compare: Some(if write { wgpu::CompareFunction::Less } else { wgpu::CompareFunction::LessEqual }),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        })
    };
    let (prepass, grid, all) = (pipeline(None, true), pipeline(Some("fs_grid"), false), pipeline(Some("fs_all"), false));
    let depth = target(&device, wgpu::TextureFormat::Depth32Float, wgpu::TextureUsages::TEXTURE_BINDING);
    let images = [target(&device, color, wgpu::TextureUsages::COPY_SRC), target(&device, color, wgpu::TextureUsages::COPY_SRC)];

    let mut encoder = device.create_command_encoder(&Default::default());
    // 1. This program's depth pre-pass; 2. lightgrid culls; 3. shading from the grid, and
    // every light for comparison.
    let draw = |encoder: &mut wgpu::CommandEncoder, pipeline: &wgpu::RenderPipeline, color: Option<&wgpu::TextureView>| {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &[color.map(|view| wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth,
                depth_ops: Some(wgpu::Operations {
                    load: if color.is_none() { wgpu::LoadOp::Clear(1.0) } else { wgpu::LoadOp::Load },
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &group0, &[]);
        pass.set_bind_group(1, culler.bind_group(), &[]);
        pass.set_vertex_buffer(0, vbuf.slice(..));
        pass.set_index_buffer(ibuf.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..indices.len() as u32, 0, 0..1);
    };
    draw(&mut encoder, &prepass, None);
    culler.encode(&mut encoder, &CullInputs {
        depth: &depth,
        lights: &light_buf,
        light_count: LIGHTS as u32,
        view: view.to_cols_array_2d(),
        proj: proj.to_cols_array_2d(),
        near: NEAR,
        far: FAR,
        viewport: [W, H],
    })?;
    draw(&mut encoder, &grid, Some(&images[0]));
    draw(&mut encoder, &all, Some(&images[1]));
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(W * H * 8),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    for (i, image) in images.iter().enumerate() {
        encoder.copy_texture_to_buffer(
            image.texture().as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &readback,
                layout: wgpu::TexelCopyBufferLayout { offset: u64::from(W * H * 4) * i as u64, bytes_per_row: Some(W * 4), rows_per_image: None },
            },
            image.texture().size(),
        );
    }
    queue.submit([encoder.finish()]);
    readback.map_async(wgpu::MapMode::Read, .., |r| r.expect("map"));
    device.poll(wgpu::PollType::wait_indefinitely())?;
    let bytes = readback.get_mapped_range(..)?.to_vec();
    let report = culler.wait()?.pop().ok_or("no culling report")?;

    // The grid against every light: per pixel the largest channel difference, in levels.
    let (a, b) = bytes.split_at(bytes.len() / 2);
    let mut diffs: Vec<u8> = a.chunks(4).zip(b.chunks(4)).map(|(p, q)| (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap_or(0)).collect();
    let mean = diffs.iter().map(|&d| f64::from(d)).sum::<f64>() / diffs.len() as f64;
    let over = diffs.iter().filter(|&&d| d > 4).count();
    diffs.sort_unstable();
    let (p99, max) = (diffs[diffs.len() * 99 / 100], diffs[diffs.len() - 1]);
    println!("culled {LIGHTS} lights into {} index entries: {report:?}", report.index_entries);
    println!("grid vs every light: mean {mean:.4}, p99 {p99}, max {max}, {over} pixels over 4 levels");
    if let Some(path) = out {
        image::save_buffer(&path, a, W, H, image::ExtendedColorType::Rgba8)?;
        println!("wrote {path}");
    }
    if !report.is_complete() || mean > 0.01 || p99 > 1 || over > 0 {
        return Err("the grid's image differs from the brute-force loop's beyond the tolerance".into());
    }
    Ok(())
}
