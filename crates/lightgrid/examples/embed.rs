//! Embedding lightgrid's light grid in a wgpu renderer of your own (README, "Embedding").
//!
//! Everything here is this program's: the device, the mesh (a floor and a field of boxes),
//! the depth pre-pass, the lights in a buffer of `CullLight`s (colour in the payload), and
//! the forward shader with its own light function (`embed.wgsl`). lightgrid only culls:
//! `LightCuller::encode` after the depth pre-pass, `LightCuller::wgsl` in front of the
//! shader, `bind_group` at group 1. The same frame is also shaded by looping over every
//! light; the program prints how far the two images are apart and exits non-zero beyond the
//! tolerance lightgrid's tests hold `tiled_forward` to (mean 0.01, p99 1, no pixel over 4
//! levels). `cargo run --release -p lightgrid --example embed -- --out embed.png`

use glam::{Mat4, Vec3, Vec4};
use lightgrid::{CullConfig, CullInputs, CullLight, LightCuller};
use wgpu::util::DeviceExt;

const W: u32 = 640;
const H: u32 = 360;
const NEAR: f32 = 0.1;
const FAR: f32 = 200.0;
const LIGHTS: u32 = 400;

/// A floor and 7 × 7 boxes of varied heights: (position, normal) vertices and indices.
fn mesh() -> (Vec<[f32; 6]>, Vec<u32>) {
    let (mut v, mut idx) = (Vec::new(), Vec::new());
    let mut quad = |c: [Vec3; 4], n: Vec3| {
        idx.extend([0, 1, 2, 0, 2, 3].map(|i| v.len() as u32 + i));
        v.extend(c.map(|p| [p.x, p.y, p.z, n.x, n.y, n.z]));
    };
    let floor = |x: f32, z: f32| Vec3::new(x * 30.0, 0.0, z * 30.0);
    quad([floor(-1., 1.), floor(1., 1.), floor(1., -1.), floor(-1., -1.)], Vec3::Y);
    for i in 0..49 {
        let c = Vec3::new((i % 7) as f32 * 6.0 - 18.0, 0.0, (i / 7) as f32 * 6.0 - 18.0);
        let h = 1.0 + (i * 7 % 5) as f32;
        let p = |x: f32, y: f32, z: f32| c + Vec3::new(x * 1.2, y * h, z * 1.2);
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
            match i % 5 {
                0 => CullLight::spot(p, 3.0 + r() * 4.0, [0.0, -1.0, 0.0], 0.75, color),
                _ => CullLight::point(p, 2.0 + r() * 3.0, color),
            }
        })
        .collect()
}

/// This renderer's camera: right-handed, standard depth (0 at `NEAR`, cleared to 1).
fn camera() -> (Mat4, Mat4) {
    let eye = Vec3::new(0.0, 14.0, 30.0);
    let f = -eye.normalize();
    let s = f.cross(Vec3::Y).normalize();
    let u = s.cross(f);
    let col = |x: f32, y: f32, z: f32, w: f32| Vec4::new(x, y, z, w);
    let rotation = Mat4::from_cols(
        col(s.x, u.x, -f.x, 0.0),
        col(s.y, u.y, -f.y, 0.0),
        col(s.z, u.z, -f.z, 0.0),
        Vec4::W,
    );
    let h = 1.0 / 0.45f32.tan();
    let (a, b) = (NEAR * FAR / (NEAR - FAR), FAR / (NEAR - FAR));
    let proj = Mat4::from_cols(
        col(h * H as f32 / W as f32, 0.0, 0.0, 0.0),
        col(0.0, h, 0.0, 0.0),
        col(0.0, 0.0, b, -1.0),
        col(0.0, 0.0, a, 0.0),
    );
    (rotation * Mat4::from_translation(-eye), proj)
}

fn texture(device: &wgpu::Device, format: wgpu::TextureFormat) -> wgpu::Texture {
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
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = match args.iter().position(|a| a == "--out") {
        Some(i) if i + 1 >= args.len() => Err("--out needs a file name".to_string()),
        Some(i) => Ok(Some(args[i + 1].clone())),
        None => Ok(None),
    };
    if let Err(e) = out.and_then(|out| run(out.as_deref()).map_err(|e| e.to_string())) {
        eprintln!("embed: {e}");
        std::process::exit(1);
    }
}

type Error = Box<dyn std::error::Error>;

/// Render the frame both ways, compare, and write the grid's image to `out`.
pub fn run(out: Option<&str>) -> Result<(), Error> {
    // Setup: this program's device (with the limits the culler asks for), the culler, and
    // this program's buffers and pipelines around the culler's WGSL and bind group layout.
    let (device, queue) = open_device()?;
    let config = CullConfig { tile_size: 16, slices: 24, ..Default::default() };
    let mut culler = LightCuller::new(&device, &queue, config)?;
    let program = Program::new(&device, culler.bind_group_layout());
    // One frame: the depth pre-pass, the culling, the shading (twice: from the grid and from
    // every light), read back.
    let bytes = program.frame(&device, &queue, &mut culler)?;
    let report = culler.wait()?.pop().ok_or("no culling report")?;
    // Check: the two images agree.
    check(&bytes, &report, out)
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

/// This program's GPU objects: the mesh, the lights, the camera, the pipelines of its depth
/// pre-pass and its shading (its group 0 and the culler's grid at group 1), and its targets.
struct Program {
    vertices: wgpu::Buffer,
    indices: (wgpu::Buffer, u32),
    lights: wgpu::Buffer,
    group0: wgpu::BindGroup,
    depth_only: wgpu::RenderPipeline,
    shade: wgpu::RenderPipeline,
    depth: wgpu::TextureView,
    images: [wgpu::Texture; 2],
    camera: (Mat4, Mat4),
}

const COLOR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

impl Program {
    fn new(device: &wgpu::Device, grid_layout: &wgpu::BindGroupLayout) -> Program {
        let (view, proj) = camera();
        let (vertices, indices) = mesh();
        let init = |contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents, usage })
        };
        let lights = init(bytemuck::cast_slice(&lights()), wgpu::BufferUsages::STORAGE);
        let eye = view.inverse().w_axis;
        let mut cam = [(proj * view).to_cols_array(), view.to_cols_array()].concat();
        cam.extend([eye.x, eye.y, eye.z, f32::from_bits(LIGHTS)]);
        let cam_buf = init(bytemuck::cast_slice(&cam), wgpu::BufferUsages::UNIFORM);
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
                wgpu::BindGroupEntry { binding: 0, resource: cam_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: lights.as_entire_binding() },
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: &[Some(&own), Some(grid_layout)],
            immediate_size: 0,
        });
        // lightgrid's WGSL in front of this program's shader (the grid at group 1).
        let source = format!("{}\n{}", LightCuller::wgsl(1), include_str!("embed.wgsl"));
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: None,
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        Program {
            vertices: init(bytemuck::cast_slice(&vertices), wgpu::BufferUsages::VERTEX),
            indices: (init(bytemuck::cast_slice(&indices), wgpu::BufferUsages::INDEX), indices.len() as u32),
            lights,
            group0,
            depth_only: pipeline(device, &layout, &module, None),
            shade: pipeline(device, &layout, &module, Some("fs")),
            depth: texture(device, wgpu::TextureFormat::Depth32Float).create_view(&Default::default()),
            images: [texture(device, COLOR), texture(device, COLOR)],
            camera: (view, proj),
        }
    }

    /// Record the depth pre-pass (`shade` false) or the shading pass into both images, with
    /// `grid` at group 1.
    fn draw(&self, encoder: &mut wgpu::CommandEncoder, shade: bool, grid: &wgpu::BindGroup) {
        let views = self.images.each_ref().map(|t| t.create_view(&Default::default()));
        let attachment = |view| {
            let ops = wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                store: wgpu::StoreOp::Store,
            };
            Some(wgpu::RenderPassColorAttachment { view, depth_slice: None, resolve_target: None, ops })
        };
        let load = if shade { wgpu::LoadOp::Load } else { wgpu::LoadOp::Clear(1.0) };
        let colors = if shade { views.each_ref().map(attachment).to_vec() } else { vec![] };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &colors,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth,
                depth_ops: Some(wgpu::Operations { load, store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(if shade { &self.shade } else { &self.depth_only });
        pass.set_bind_group(0, &self.group0, &[]);
        pass.set_bind_group(1, grid, &[]);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.0.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..self.indices.1, 0, 0..1);
    }

    /// One frame: the depth pre-pass, lightgrid's culling, the shading from the grid; both
    /// images read back (the grid's, then every light's).
    fn frame(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        culler: &mut LightCuller,
    ) -> Result<Vec<u8>, Error> {
        let mut encoder = device.create_command_encoder(&Default::default());
        self.draw(&mut encoder, false, culler.bind_group());
        let (view, proj) = self.camera;
        culler.encode(
            &mut encoder,
            &CullInputs {
                depth: Some(&self.depth),
                transparent: false,
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
        // The grid's bind group after `encode` (it is replaced when the lists grow).
        self.draw(&mut encoder, true, culler.bind_group());
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: u64::from(W * H * 8),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        for (i, image) in self.images.iter().enumerate() {
            let offset = u64::from(W * H * 4) * i as u64;
            let layout =
                wgpu::TexelCopyBufferLayout { offset, bytes_per_row: Some(W * 4), rows_per_image: None };
            let buffer = wgpu::TexelCopyBufferInfo { buffer: &readback, layout };
            encoder.copy_texture_to_buffer(image.as_image_copy(), buffer, image.size());
        }
        queue.submit([encoder.finish()]);
        readback.map_async(wgpu::MapMode::Read, .., |r| r.expect("map"));
        device.poll(wgpu::PollType::wait_indefinitely())?;
        let bytes = readback.get_mapped_range(..)?.to_vec();
        Ok(bytes)
    }
}

/// The depth pre-pass's pipeline (`fs` None) or the shading pipeline (`fs`, into two images).
fn pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    fs: Option<&str>,
) -> wgpu::RenderPipeline {
    let targets = [Some(COLOR.into()), Some(COLOR.into())];
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
        primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Back), ..Default::default() },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(fs.is_none()),
            depth_compare: Some(wgpu::CompareFunction::LessEqual),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        multiview_mask: None,
        cache: None,
    })
}

/// The grid's image against every light's: per pixel the largest channel difference, in
/// levels, within `tiled_forward`'s tolerance; the grid's image written to `out`.
fn check(bytes: &[u8], report: &lightgrid::CullReport, out: Option<&str>) -> Result<(), Error> {
    let (grid_image, all_image) = bytes.split_at(bytes.len() / 2);
    let pixel_diff = |(p, q): (&[u8], &[u8])| (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap();
    let mut diffs: Vec<u8> = grid_image.chunks(4).zip(all_image.chunks(4)).map(pixel_diff).collect();
    let mean = diffs.iter().map(|&d| f64::from(d)).sum::<f64>() / diffs.len() as f64;
    let over = diffs.iter().filter(|&&d| d > 4).count();
    diffs.sort_unstable();
    let (p99, max) = (diffs[diffs.len() * 99 / 100], diffs[diffs.len() - 1]);
    println!("culled {LIGHTS} lights: {report:?}");
    println!("grid vs every light: mean {mean:.4}, p99 {p99}, max {max}, {over} pixels over 4 levels");
    if let Some(path) = out {
        // Whole or not at all: a temporary file renamed over the path.
        let image = image::RgbaImage::from_raw(W, H, grid_image.to_vec()).ok_or("image size")?;
        lightgrid::image_io::save_png(&image, std::path::Path::new(path))?;
        println!("wrote {path}");
    }
    if !report.is_complete() || mean > 0.01 || p99 > 1 || over > 0 {
        return Err("the grid's image differs from the brute-force loop's beyond the tolerance".into());
    }
    Ok(())
}
