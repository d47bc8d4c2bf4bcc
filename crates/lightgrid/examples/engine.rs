//! A second renderer culling through lightgrid, written the way an engine is (README,
//! "Embedding"): its own 64-byte light struct read in place (`LightLayout`), a VR eye's
//! off-centre frustum with TAA jitter that changes every frame, glass over an opaque scene
//! (lists for transparent surfaces), reversed-Z, and a mode without a depth pre-pass (froxels).
//! It keeps the culler's bind group and rebuilds nothing until the group's generation moves.
//! Every frame is also shaded by looping over every light; the program prints both images'
//! difference per frame and exits non-zero beyond the tolerance lightgrid's tests hold
//! `tiled_forward` to (mean 0.01, p99 1, no pixel over 4 levels), or when a frame lacks lights.
//! `cargo run --release -p lightgrid --example engine -- [--frames N (60)] [--no-prepass] [--out F.png]`

use glam::{Mat4, Vec3, Vec4};
use lightgrid::{CullConfig, CullInputs, LightCuller, LightLayout};
use wgpu::util::DeviceExt;

/// A multiple of 64 pixels: rows of the read-back images are 256-byte aligned.
const W: u32 = 512;
const H: u32 = 288;
const NEAR: f32 = 0.1;
const FAR: f32 = 150.0;
const LIGHTS: u32 = 300;
/// The VR eye's principal point: 10% of the width right of the image centre (NDC +0.2).
const EYE_SHIFT: f32 = -0.2;

/// The engine's light, 64 bytes (`engine.wgsl`'s `EngineLight`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct EngineLight {
    color: [f32; 3],
    intensity: f32,
    direction: [f32; 3],
    cos_outer: f32,
    position: [f32; 3],
    kind: u32,
    range: f32,
    shadow_index: i32,
    pad: [f32; 2],
}

/// Where the culler finds what it reads in an `EngineLight` (byte offsets).
const LAYOUT: LightLayout =
    LightLayout { stride: 64, position: 32, range: 48, direction: Some(16), cos_outer: Some(28) };

/// How the example runs.
pub struct Options {
    /// Frames to render and check.
    pub frames: u32,
    /// A depth pre-pass (the culler bounds cells by it; glass gets its own lists), or none
    /// (froxels: every cell spans its slice).
    pub prepass: bool,
    /// Where to write the last frame's grid image.
    pub out: Option<String>,
}

fn main() {
    let mut options = Options { frames: 60, prepass: true, out: None };
    let mut args = std::env::args().skip(1);
    let parsed: Result<(), String> = (|| {
        while let Some(a) = args.next() {
            match a.as_str() {
                "--no-prepass" => options.prepass = false,
                "--frames" => {
                    let n = args.next().ok_or("--frames needs a number")?;
                    options.frames = n
                        .parse()
                        .ok()
                        .filter(|&n| (1..=10_000).contains(&n))
                        .ok_or(format!("--frames takes 1 to 10000, not {n}"))?;
                }
                "--out" => options.out = Some(args.next().ok_or("--out needs a file name")?),
                other => return Err(format!("unknown argument {other}; see the file's header")),
            }
        }
        Ok(())
    })();
    if let Err(e) = parsed.and_then(|()| run(&options).map_err(|e| e.to_string())) {
        eprintln!("engine: {e}");
        std::process::exit(1);
    }
}

type Error = Box<dyn std::error::Error>;

/// Render and check `options.frames` frames.
pub fn run(options: &Options) -> Result<(), Error> {
    // Setup: the engine's device and scene; the culler, told the engine's light layout, with
    // room for its window and 64k list entries up front (so the bind group stays put).
    let (device, queue) = open_device()?;
    let config = CullConfig { tile_size: 16, slices: 16, index_capacity: 1 << 16, ..Default::default() };
    let mut culler = LightCuller::new(&device, &queue, config)?;
    culler.set_light_layout(LAYOUT)?;
    culler.reserve([W, H])?;
    let mut engine = Engine::new(&device, &culler, options.prepass);
    let mut last = Vec::new();
    for k in 0..options.frames {
        let (frame, bytes) = engine.frame(&device, &queue, &mut culler, k)?;
        // The culler's report of this frame (the engine waited for its images anyway).
        let report = culler.wait()?.into_iter().find(|r| r.frame == frame).ok_or("no culling report")?;
        check(k, &bytes, &report, engine.rebuilt)?;
        last = bytes;
    }
    if let Some(path) = &options.out {
        let grid_image = last[..last.len() / 2].to_vec();
        let image = image::RgbaImage::from_raw(W, H, grid_image).ok_or("image size")?;
        lightgrid::image_io::save_png(&image, std::path::Path::new(path))?;
        println!("wrote {path}");
    }
    Ok(())
}

/// The first adapter, with the limits `LightCuller` asks for.
fn open_device() -> Result<(wgpu::Device, wgpu::Queue), Error> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))?;
    println!("adapter: {}", adapter.get_info().name);
    Ok(pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_limits: LightCuller::required_limits(&adapter),
        ..Default::default()
    }))?)
}

/// A floor and 6 × 6 boxes (opaque), then 5 glass panes in front of them: (position, normal)
/// vertices, indices, and where the glass's indices start.
fn mesh() -> (Vec<[f32; 6]>, Vec<u32>, u32) {
    let (mut v, mut idx) = (Vec::new(), Vec::new());
    let mut quad = |c: [Vec3; 4], n: Vec3| {
        idx.extend([0, 1, 2, 0, 2, 3].map(|i| v.len() as u32 + i));
        v.extend(c.map(|p| [p.x, p.y, p.z, n.x, n.y, n.z]));
    };
    let floor = |x: f32, z: f32| Vec3::new(x * 25.0, 0.0, z * 25.0);
    quad([floor(-1., 1.), floor(1., 1.), floor(1., -1.), floor(-1., -1.)], Vec3::Y);
    for i in 0..36 {
        let c = Vec3::new((i % 6) as f32 * 6.0 - 15.0, 0.0, (i / 6) as f32 * 6.0 - 20.0);
        let h = 1.0 + (i * 7 % 5) as f32;
        let p = |x: f32, y: f32, z: f32| c + Vec3::new(x * 1.3, y * h, z * 1.3);
        quad([p(-1., 1., 1.), p(1., 1., 1.), p(1., 1., -1.), p(-1., 1., -1.)], Vec3::Y);
        quad([p(-1., 0., 1.), p(1., 0., 1.), p(1., 1., 1.), p(-1., 1., 1.)], Vec3::Z);
        quad([p(1., 0., -1.), p(-1., 0., -1.), p(-1., 1., -1.), p(1., 1., -1.)], -Vec3::Z);
        quad([p(1., 0., 1.), p(1., 0., -1.), p(1., 1., -1.), p(1., 1., 1.)], Vec3::X);
        quad([p(-1., 0., -1.), p(-1., 0., 1.), p(-1., 1., 1.), p(-1., 1., -1.)], -Vec3::X);
    }
    // The glass after the 1 + 36 × 5 opaque quads.
    let glass = 6 * (1 + 36 * 5);
    for i in 0..5 {
        let (x, z) = (i as f32 * 7.0 - 14.0, 8.0 - (i % 2) as f32 * 5.0);
        let p = |dx: f32, y: f32| Vec3::new(x + dx * 2.5, y * 4.0, z);
        quad([p(-1., 0.), p(1., 0.), p(1., 1.), p(-1., 1.)], Vec3::Z);
    }
    (v, idx, glass)
}

/// Lights over the floor and among the panes, a fifth of them spots pointing down.
fn lights() -> Vec<EngineLight> {
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
    let mut r = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 40) as f32 / (1u64 << 24) as f32
    };
    (0..LIGHTS)
        .map(|i| {
            let spot = i % 5 == 0;
            EngineLight {
                color: [0.3 + r(), 0.3 + r(), 0.3 + r()],
                intensity: 2.0,
                direction: [0.0, -1.0, 0.0],
                cos_outer: if spot { 0.75 } else { -2.0 },
                position: [r() * 50.0 - 25.0, 0.3 + r() * 4.0, r() * 40.0 - 25.0],
                kind: u32::from(spot),
                range: if spot { 3.0 + r() * 4.0 } else { 2.0 + r() * 3.0 },
                shadow_index: -1,
                pad: [0.0; 2],
            }
        })
        .collect()
}

/// Frame `k`'s camera: a slow orbit; the VR eye's off-centre reversed-Z projection (1 at
/// `NEAR`, 0 at `FAR`), jittered by a Halton (2, 3) sub-pixel offset as TAA does.
fn camera(k: u32) -> (Mat4, Mat4, [f32; 2]) {
    let angle = k as f32 * 0.03;
    let eye = Vec3::new(angle.sin() * 30.0, 12.0, angle.cos() * 30.0);
    // Right-handed, looking down -z: rows s, u, -f, then the translation.
    let f = (Vec3::new(0.0, 1.0, -5.0) - eye).normalize();
    let (s, u) = (f.cross(Vec3::Y).normalize(), f.cross(Vec3::Y).normalize().cross(f));
    let col = |x: f32, y: f32, z: f32, w: f32| Vec4::new(x, y, z, w);
    let rotation = Mat4::from_cols(
        col(s.x, u.x, -f.x, 0.0),
        col(s.y, u.y, -f.y, 0.0),
        col(s.z, u.z, -f.z, 0.0),
        Vec4::W,
    );
    let view = rotation * Mat4::from_translation(-eye);
    let halton = |base: u32| {
        let (mut f, mut r, mut i) = (1.0f32, 0.0f32, k + 1);
        while i > 0 {
            f /= base as f32;
            r += f * (i % base) as f32;
            i /= base;
        }
        r - 0.5
    };
    let jitter = [halton(2), halton(3)];
    let h = 1.0 / 0.45f32.tan();
    let (a, b) = (NEAR * FAR / (FAR - NEAR), NEAR / (FAR - NEAR));
    let proj = Mat4::from_cols(
        col(h * H as f32 / W as f32, 0.0, 0.0, 0.0),
        col(0.0, h, 0.0, 0.0),
        // x_ndc = p00 x / w - proj[2][0]: the eye's shift, and the jitter in NDC (2 / W per pixel).
        col(EYE_SHIFT + jitter[0] * 2.0 / W as f32, jitter[1] * 2.0 / H as f32, b, -1.0),
        col(0.0, 0.0, a, 0.0),
    );
    (view, proj, jitter)
}

const COLOR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The engine's GPU objects, and the culler's bind group as the engine keeps it.
struct Engine {
    prepass: bool,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    /// Opaque indices `0..glass`, glass `glass..count`.
    glass: u32,
    count: u32,
    lights: wgpu::Buffer,
    frame_uniforms: wgpu::Buffer,
    group0: wgpu::BindGroup,
    depth_only: wgpu::RenderPipeline,
    opaque: wgpu::RenderPipeline,
    glass_pipeline: wgpu::RenderPipeline,
    depth: wgpu::TextureView,
    images: [wgpu::Texture; 2],
    /// The culler's group and its generation when taken; taken again only when it moves.
    grid: (wgpu::BindGroup, u64),
    /// Times the engine took the group again.
    rebuilt: u32,
}

impl Engine {
    fn new(device: &wgpu::Device, culler: &LightCuller, prepass: bool) -> Engine {
        let (vertices, indices, glass) = mesh();
        let init = |contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents, usage })
        };
        let lights = init(bytemuck::cast_slice(&lights()), wgpu::BufferUsages::STORAGE);
        let frame_uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame"),
            size: 144,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
            count: None,
        };
        let storage = wgpu::BufferBindingType::Storage { read_only: true };
        let own = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: None,
            entries: &[entry(0, wgpu::BufferBindingType::Uniform), entry(1, storage)],
        });
        let group0 = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &own,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: frame_uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: lights.as_entire_binding() },
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: &[Some(&own), Some(culler.bind_group_layout())],
            immediate_size: 0,
        });
        let source = format!("{}\n{}", LightCuller::wgsl(1), include_str!("engine.wgsl"));
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: None,
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline = |fs, depth_write, compare, blend| {
            render_pipeline(device, &layout, &module, fs, depth_write, compare, blend)
        };
        use wgpu::CompareFunction as C;
        let texture = |format| {
            use wgpu::TextureUsages as U;
            device.create_texture(&wgpu::TextureDescriptor {
                label: None,
                size: wgpu::Extent3d { width: W, height: H, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC,
                view_formats: &[],
            })
        };
        Engine {
            prepass,
            vertices: init(bytemuck::cast_slice(&vertices), wgpu::BufferUsages::VERTEX),
            indices: init(bytemuck::cast_slice(&indices), wgpu::BufferUsages::INDEX),
            glass,
            count: indices.len() as u32,
            lights,
            frame_uniforms,
            group0,
            depth_only: pipeline(None, true, C::Greater, None),
            // Reversed-Z: nearer is greater. After a pre-pass the opaque pass tests against
            // it without writing; without one it writes its own depth.
            opaque: pipeline(
                Some("fs_opaque"),
                !prepass,
                if prepass { C::GreaterEqual } else { C::Greater },
                None,
            ),
            glass_pipeline: pipeline(
                Some("fs_glass"),
                false,
                C::Greater,
                Some(wgpu::BlendState::ALPHA_BLENDING),
            ),
            depth: texture(DEPTH).create_view(&Default::default()),
            images: [texture(COLOR), texture(COLOR)],
            grid: (culler.bind_group().clone(), culler.bind_group_generation()),
            rebuilt: 0,
        }
    }

    /// Frame `k`: the engine's uniforms, its depth pre-pass (if it has one), lightgrid's
    /// culling, the opaque and glass passes into both images; read back (the grid's image,
    /// then every light's). Returns the culler's frame number and the pixels.
    fn frame(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        culler: &mut LightCuller,
        k: u32,
    ) -> Result<(u64, Vec<u8>), Error> {
        let (view, proj, _) = camera(k);
        let eye = view.inverse().w_axis;
        let mut uniforms = [(proj * view).to_cols_array(), view.to_cols_array()].concat();
        uniforms.extend([eye.x, eye.y, eye.z, f32::from_bits(LIGHTS)]);
        queue.write_buffer(&self.frame_uniforms, 0, bytemuck::cast_slice(&uniforms));
        let mut encoder = device.create_command_encoder(&Default::default());
        if self.prepass {
            self.pass(&mut encoder, &self.depth_only, 0..self.glass, true);
        }
        let frame = culler.encode(
            &mut encoder,
            &CullInputs {
                depth: self.prepass.then_some(&self.depth),
                // Glass lies in front of the pre-pass depth: lists for it too.
                transparent: self.prepass,
                cpu_lights: None,
                lights: &self.lights,
                light_count: LIGHTS,
                view: view.to_cols_array_2d(),
                proj: proj.to_cols_array_2d(),
                near: NEAR,
                far: FAR,
                viewport: [W, H],
            },
        )?;
        // The group stays until its generation moves (only ever inside `encode`).
        if culler.bind_group_generation() != self.grid.1 {
            self.grid = (culler.bind_group().clone(), culler.bind_group_generation());
            self.rebuilt += 1;
        }
        self.pass(&mut encoder, &self.opaque, 0..self.glass, !self.prepass);
        self.pass(&mut encoder, &self.glass_pipeline, self.glass..self.count, false);
        let bytes = read_back(device, queue, encoder, &self.images)?;
        Ok((frame, bytes))
    }

    /// One render pass drawing `range` of the indices with `pipeline`; `clear`: the first pass
    /// of the frame (clears depth, and the images if it has colour targets).
    fn pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pipeline: &wgpu::RenderPipeline,
        range: std::ops::Range<u32>,
        clear: bool,
    ) {
        let views = self.images.each_ref().map(|t| t.create_view(&Default::default()));
        let depth_only = std::ptr::eq(pipeline, &self.depth_only);
        let first_colour = clear || (self.prepass && std::ptr::eq(pipeline, &self.opaque));
        let load = if first_colour { wgpu::LoadOp::Clear(wgpu::Color::BLACK) } else { wgpu::LoadOp::Load };
        let attachment = |view| {
            let ops = wgpu::Operations { load, store: wgpu::StoreOp::Store };
            Some(wgpu::RenderPassColorAttachment { view, depth_slice: None, resolve_target: None, ops })
        };
        let colors = if depth_only { vec![] } else { views.each_ref().map(attachment).to_vec() };
        let depth_load = if clear { wgpu::LoadOp::Clear(0.0) } else { wgpu::LoadOp::Load };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &colors,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth,
                depth_ops: Some(wgpu::Operations { load: depth_load, store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.group0, &[]);
        pass.set_bind_group(1, &self.grid.0, &[]);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(range, 0, 0..1);
    }
}

/// A pipeline of the engine's shader: depth only (`fs` None), or into both images.
fn render_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    fs: Option<&str>,
    depth_write: bool,
    compare: wgpu::CompareFunction,
    blend: Option<wgpu::BlendState>,
) -> wgpu::RenderPipeline {
    let target = Some(wgpu::ColorTargetState { format: COLOR, blend, write_mask: wgpu::ColorWrites::ALL });
    let targets = [target.clone(), target];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: fs,
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 24,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3],
            })],
        },
        fragment: fs.map(|fs| wgpu::FragmentState {
            module,
            entry_point: Some(fs),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH,
            depth_write_enabled: Some(depth_write),
            depth_compare: Some(compare),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        multiview_mask: None,
        cache: None,
    })
}

/// Submit `encoder` with the copies of both images, wait, and return their pixels.
fn read_back(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mut encoder: wgpu::CommandEncoder,
    images: &[wgpu::Texture; 2],
) -> Result<Vec<u8>, Error> {
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(W * H * 8),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    for (i, image) in images.iter().enumerate() {
        let offset = u64::from(W * H * 4) * i as u64;
        let layout = wgpu::TexelCopyBufferLayout { offset, bytes_per_row: Some(W * 4), rows_per_image: None };
        let buffer = wgpu::TexelCopyBufferInfo { buffer: &readback, layout };
        encoder.copy_texture_to_buffer(image.as_image_copy(), buffer, image.size());
    }
    queue.submit([encoder.finish()]);
    readback.map_async(wgpu::MapMode::Read, .., |r| r.expect("map"));
    device.poll(wgpu::PollType::wait_indefinitely())?;
    let bytes = readback.get_mapped_range(..)?.to_vec();
    Ok(bytes)
}

/// Frame `k`'s grid image against its every-light image, within `tiled_forward`'s tolerance;
/// a frame whose report says it lacks lights is an error (here the lists were sized up front;
/// an engine that lets them grow would skip, or re-render, such a frame).
fn check(k: u32, bytes: &[u8], report: &lightgrid::CullReport, rebuilt: u32) -> Result<(), Error> {
    let (grid_image, all_image) = bytes.split_at(bytes.len() / 2);
    let pixel_diff = |(p, q): (&[u8], &[u8])| (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap();
    let mut diffs: Vec<u8> = grid_image.chunks(4).zip(all_image.chunks(4)).map(pixel_diff).collect();
    let mean = diffs.iter().map(|&d| f64::from(d)).sum::<f64>() / diffs.len() as f64;
    let over = diffs.iter().filter(|&&d| d > 4).count();
    diffs.sort_unstable();
    let (p99, max) = (diffs[diffs.len() * 99 / 100], diffs[diffs.len() - 1]);
    let jitter = camera(k).2;
    println!(
        "frame {k}: jitter ({:+.2}, {:+.2}) px, {} index entries, complete {}, group taken {rebuilt} more times; grid vs every light: mean {mean:.4}, p99 {p99}, max {max}, {over} pixels over 4 levels",
        jitter[0],
        jitter[1],
        report.index_entries,
        report.is_complete()
    );
    if !report.is_complete() {
        return Err(format!("frame {k} lacks lights: {report:?}").into());
    }
    if mean > 0.01 || p99 > 1 || over > 0 {
        return Err(format!("frame {k}: the grid's image differs from the brute-force loop's").into());
    }
    Ok(())
}
