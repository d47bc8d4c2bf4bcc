//! `LightCuller` through its public API only, as another wgpu renderer uses it: its own
//! device, its own depth buffer (written by its own shader, every sample its own depth), its
//! own lights. Every strategy × tiles/clusters × depth-bounds mode, 2.5D depth masks, and MSAA
//! depth, is checked
//! on the GPU against a brute-force oracle in the test's own WGSL: every light that reaches a
//! sample must be listed in the sample's cell (found with the caller-facing accessor). Then
//! the lists' growth from the culler's reports, and each kind of bad use refused with the
//! input it names.

use glam::{Mat4, Vec3};
use lightgrid::culling::GridLists;
use lightgrid::frame::FrameIo;
use lightgrid::gpu::PassTimer;
use lightgrid::{
    Assign, CellBox, CullConfig, CullError, CullExtras, CullInput, CullInputs, CullLight,
    DepthBounds, DepthMask, LightCuller, LightLayout,
};
use wgpu::util::DeviceExt;

const W: u32 = 203;
const H: u32 = 141;
const NEAR: f32 = 0.1;
const FAR: f32 = 100.0;

/// The caller's device: the first Vulkan adapter (lavapipe on CI), never a silent pass.
fn device() -> (wgpu::Device, wgpu::Queue) {
    let (device, queue, _) = device_with(false);
    (device, queue)
}

/// [`device`], with `TIMESTAMP_QUERY` when `timestamps` and the adapter has it (the last
/// value says whether it was granted).
fn device_with(timestamps: bool) -> (wgpu::Device, wgpu::Queue, bool) {
    device_limited(timestamps, None)
}

/// [`device_with`], with `storage` storage buffers per stage instead of the culler's limits'.
fn device_limited(timestamps: bool, storage: Option<u32>) -> (wgpu::Device, wgpu::Queue, bool) {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))
        .expect("LightCuller tests need a GPU adapter (CI installs mesa-vulkan-drivers)");
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        assert_eq!(adapter.get_info().backend, wgpu::Backend::Vulkan);
    }
    let features = match timestamps {
        true => adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
        false => wgpu::Features::empty(),
    };
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        // Exactly what the culler asks for: every strategy must be created within it.
        required_limits: wgpu::Limits {
            max_storage_buffers_per_shader_stage: storage.unwrap_or(
                LightCuller::required_limits(&adapter).max_storage_buffers_per_shader_stage,
            ),
            ..LightCuller::required_limits(&adapter)
        },
        required_features: features,
        ..Default::default()
    }))
    .expect("a device with the culler's limits");
    (device, queue, !features.is_empty())
}

/// A full-screen triangle (`vs`) whose fragments (`fs`) run over a Depth32Float target of
/// `samples` samples, every depth test passing; `depth_write`: they write their depth.
fn fullscreen_depth_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    layout: Option<&wgpu::PipelineLayout>,
    samples: u32,
    depth_write: bool,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("caller full-screen pass"),
        layout,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[],
        }),
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(depth_write),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: samples,
            ..Default::default()
        },
        multiview_mask: None,
        cache: None,
    })
}

/// A small deterministic generator (the test's own).
struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f()
    }
    fn unit(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            if v.length_squared() > 0.01 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

struct Camera {
    eye: Vec3,
    view: Mat4,
    proj: Mat4,
    /// depth = a / w - b.
    a: f32,
    b: f32,
    standard: bool,
}

fn camera(eye: Vec3, standard: bool) -> Camera {
    // Right-handed, looking down -z: rows s, u, -f and the translation.
    let f = Vec3::new(-0.3, -0.2, -1.0).normalize();
    let s = f.cross(Vec3::Y).normalize();
    let u = s.cross(f);
    let rotation = Mat4::from_cols(
        glam::Vec4::new(s.x, u.x, -f.x, 0.0),
        glam::Vec4::new(s.y, u.y, -f.y, 0.0),
        glam::Vec4::new(s.z, u.z, -f.z, 0.0),
        glam::Vec4::W,
    );
    let view = rotation * Mat4::from_translation(-eye);
    // clip.z = b z + a, clip.w = -z: depth = a / w - b; standard 0 at near, reversed 1.
    let (n, fa) = (f64::from(NEAR), f64::from(FAR));
    let (a, b) = if standard {
        (n * fa / (n - fa), fa / (n - fa))
    } else {
        (n * fa / (fa - n), n / (fa - n))
    };
    let h = 1.0 / 0.5f32.tan();
    let proj = Mat4::from_cols(
        glam::Vec4::new(h * H as f32 / W as f32, 0.0, 0.0, 0.0),
        glam::Vec4::new(0.0, h, 0.0, 0.0),
        glam::Vec4::new(0.0, 0.0, b as f32, -1.0),
        glam::Vec4::new(0.0, 0.0, a as f32, 0.0),
    );
    let p = proj.to_cols_array_2d();
    Camera {
        eye,
        view,
        proj,
        a: p[3][2],
        b: p[2][2],
        standard,
    }
}

/// Lights around the view: in front, behind the camera, crossing the near plane, containing
/// the camera, just outside the screen edges; a quarter of them spots.
fn lights(cam: &Camera, n: usize, seed: u64) -> Vec<CullLight> {
    let mut rng = Rng(seed);
    let inv = cam.view.inverse();
    (0..n)
        .map(|i| {
            let kind = i % 5;
            let view_pos = match kind {
                // In front, anywhere in the view.
                0 | 1 => {
                    let w = rng.range(0.5, 60.0);
                    Vec3::new(rng.range(-0.9, 0.9) * w, rng.range(-0.6, 0.6) * w, -w)
                }
                // Behind the camera.
                2 => Vec3::new(
                    rng.range(-3.0, 3.0),
                    rng.range(-3.0, 3.0),
                    rng.range(0.0, 4.0),
                ),
                // At (or just beyond) the screen edges.
                3 => {
                    let w = rng.range(1.0, 30.0);
                    let side = if rng.f() < 0.5 { -1.0 } else { 1.0 };
                    Vec3::new(
                        side * rng.range(0.75, 1.1) * w,
                        rng.range(-0.7, 0.7) * w,
                        -w,
                    )
                }
                // Near the eye: crossing the near plane or holding the camera.
                _ => Vec3::new(
                    rng.range(-0.5, 0.5),
                    rng.range(-0.5, 0.5),
                    rng.range(-0.6, 0.4),
                ),
            };
            let p = inv.transform_point3(view_pos).to_array();
            let range = if kind == 4 {
                rng.range(0.2, 1.5)
            } else {
                rng.range(0.4, 6.0)
            };
            let payload = [rng.f(), rng.f(), rng.f(), 1.0];
            if i % 4 == 3 {
                let d = rng.unit().to_array();
                CullLight::spot(p, range, d, rng.range(-0.4, 0.95), payload)
            } else {
                CullLight::point(p, range, payload)
            }
        })
        .collect()
}

/// An engine's own light: 64 bytes, the culler's fields shuffled among the engine's own.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct EngineLight {
    color: [f32; 3],
    intensity: f32,
    cos_outer: f32,
    direction: [f32; 3],
    kind: u32,
    range: f32,
    /// Never read by the culler: NaN here must not matter.
    shadow: [f32; 2],
    position: [f32; 3],
    pad: f32,
}

/// [`EngineLight`] as the culler reads it.
const ENGINE_LAYOUT: LightLayout = LightLayout {
    stride: 64,
    position: 48,
    range: 36,
    direction: Some(20),
    cos_outer: Some(16),
};

fn engine_lights(lights: &[CullLight]) -> Vec<EngineLight> {
    lights
        .iter()
        .map(|l| EngineLight {
            color: [l.payload[0], l.payload[1], l.payload[2]],
            intensity: 100.0,
            cos_outer: l.cos_outer,
            direction: l.direction,
            kind: u32::from(l.cos_outer >= -1.0),
            range: l.range,
            shadow: [f32::NAN, f32::INFINITY],
            position: l.position,
            pad: f32::NAN,
        })
        .collect()
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Check {
    /// Camera-relative (world minus eye) from view space: the view's inverse rotation.
    inv_rotation: [[f32; 4]; 4],
    eye: [f32; 3],
    light_count: u32,
    a: f32,
    b: f32,
    p00: f32,
    p11: f32,
    viewport: [f32; 2],
    near: f32,
    far: f32,
    standard: u32,
    /// 0: check the depth buffer's samples; 1: a transparent surface's fragment in front of
    /// each sample, looked up with `light_grid_cell_transparent`.
    mode: u32,
    /// The frame's projection's `proj[2][0]`, `proj[2][1]` (off-centre: x_ndc = p00 x / w - p20).
    p20: f32,
    p21: f32,
}

const DEPTH_WGSL: &str = r#"
struct Check { inv_rotation: mat4x4<f32>, eye: vec3<f32>, light_count: u32, a: f32, b: f32,
    p00: f32, p11: f32, viewport: vec2<f32>, near: f32, far: f32, standard: u32, mode: u32, p20: f32, p21: f32 }
@group(0) @binding(0) var<uniform> c: Check;

@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.5, 1.0);
}

fn hash(p: vec2<f32>) -> f32 {
    return fract(sin(dot(p, vec2<f32>(12.9898, 78.233))) * 43758.547);
}

// Every sample its own view distance: smooth slopes, steps every 9 px, noise per sample, and
// a disc of sky.
@fragment fn fs(@builtin(position) pos: vec4<f32>, @builtin(sample_index) s: u32) -> @builtin(frag_depth) f32 {
    let uv = pos.xy / c.viewport;
    if (length(uv - vec2<f32>(0.7, 0.3)) < 0.12) {
        discard;
    }
    let t = clamp(0.15 + 0.5 * uv.y + 0.25 * hash(floor(pos.xy / 9.0)) + 0.08 * hash(pos.xy + f32(s)), 0.0, 1.0);
    let w = c.near * 1.5 * pow(c.far / (c.near * 1.5), t * 0.8);
    return c.a / w - c.b;
}
"#;

const CHECK_WGSL: &str = r#"
struct Check { inv_rotation: mat4x4<f32>, eye: vec3<f32>, light_count: u32, a: f32, b: f32,
    p00: f32, p11: f32, viewport: vec2<f32>, near: f32, far: f32, standard: u32, mode: u32, p20: f32, p21: f32 }
struct MyLight { position: vec3<f32>, range: f32, payload: vec4<f32>, direction: vec3<f32>, cos_outer: f32 }
@group(0) @binding(0) var<uniform> c: Check;
@group(0) @binding(1) var<storage, read> my_lights: array<MyLight>;
@group(0) @binding(2) var depth_tex: DEPTH_TYPE;
// [0] misses, [1] lights reaching samples, [2] entries of the samples' lists, [3] samples,
// [4..6] the first miss: pixel x, y, light.
@group(0) @binding(3) var<storage, read_write> result: array<atomic<u32>, 8>;

// Reaches with a margin (rounding in this shader's own reconstruction is not a miss).
fn reaches(l: MyLight, p: vec3<f32>) -> bool {
    let d = p - l.position;
    let dist = length(d);
    if (dist >= l.range * 0.999) {
        return false;
    }
    if (l.cos_outer < -1.5) {
        return true;
    }
    return dot(d, l.direction) > (l.cos_outer + 1e-3) * dist;
}

fn noise(p: vec2<f32>) -> f32 {
    return fract(sin(dot(p, vec2<f32>(12.9898, 78.233))) * 43758.547);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= u32(c.viewport.x) || gid.y >= u32(c.viewport.y)) {
        return;
    }
    for (var s = 0u; s < SAMPLES; s++) {
        let d = textureLoad(depth_tex, gid.xy, LOAD_SAMPLE);
        let sky = select(d <= 0.0, d >= 1.0, c.standard != 0u);
        if (sky) {
            continue;
        }
        let opaque_w = c.a / (d + c.b);
        let xy = vec2<f32>(gid.xy) + 0.5;
        // Mode 1: a transparent surface between the near plane and the sample.
        let t = 0.02 + 0.96 * noise(xy + f32(s) * 0.37);
        let w = select(opaque_w, c.near + (opaque_w - c.near) * t, c.mode == 1u);
        // NDC shifted by an off-centre projection: ndc + (p20, p21) = (p00 x, p11 y) / w.
        let ndc = vec2<f32>(xy.x / c.viewport.x * 2.0 - 1.0 + c.p20, 1.0 - xy.y / c.viewport.y * 2.0 + c.p21);
        let v = vec3<f32>(ndc.x * w / c.p00, ndc.y * w / c.p11, -w);
        // Camera-relative point; the lights are moved by the eye (world minus eye).
        let p = (c.inv_rotation * vec4<f32>(v, 0.0)).xyz;
        let cell = select(light_grid_cell(xy, w), light_grid_cell_transparent(xy, w), c.mode == 1u);
        let n = light_grid_count(cell);
        atomicAdd(&result[2], n);
        atomicAdd(&result[3], 1u);
        // The walk visits as many lights as the count says, and the same ones, in order, as
        // indexing (lists and z-bins alike); a difference counts as a miss.
        var walk = light_grid_walk(cell);
        var walked = 0u;
        while (light_grid_next(&walk)) {
            if (walked >= n || light_grid_light(cell, walked) != walk.light) {
                atomicAdd(&result[0], 1u);
            }
            walked++;
        }
        if (walked != n) {
            atomicAdd(&result[0], 1u);
        }
        for (var l = 0u; l < c.light_count; l++) {
            var light = my_lights[l];
            light.position = light.position - c.eye;
            if (!reaches(light, p)) {
                continue;
            }
            atomicAdd(&result[1], 1u);
            var found = false;
            var w = light_grid_walk(cell);
            while (light_grid_next(&w)) {
                if (w.light == l) {
                    found = true;
                    break;
                }
            }
            if (!found) {
                if (atomicAdd(&result[0], 1u) == 0u) {
                    atomicStore(&result[4], gid.x);
                    atomicStore(&result[5], gid.y);
                    atomicStore(&result[6], l);
                }
            }
        }
    }
}
"#;

/// The caller's resources for one camera: its depth texture (written by its own pass), its
/// lights, and its oracle pipeline.
struct Caller {
    device: wgpu::Device,
    queue: wgpu::Queue,
    samples: u32,
    depth: wgpu::Texture,
    depth_view: wgpu::TextureView,
    depth_pipeline: wgpu::RenderPipeline,
    check: wgpu::Buffer,
    lights: wgpu::Buffer,
    /// The same lights with ranges 10% short: a culler fed these must fail the oracle.
    shrunk_lights: wgpu::Buffer,
    /// Both as [`EngineLight`]s (`ENGINE_LAYOUT`).
    engine_lights: wgpu::Buffer,
    shrunk_engine_lights: wgpu::Buffer,
    /// Both, on the CPU (`CullInputs::cpu_lights`, for `cpu` and `bvh`).
    cpu_lights: Vec<CullLight>,
    shrunk_cpu_lights: Vec<CullLight>,
    light_count: u32,
    cam: Camera,
}

impl Caller {
    fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        samples: u32,
        cam: Camera,
        lights: &[CullLight],
    ) -> Self {
        let depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("caller depth"),
            size: wgpu::Extent3d {
                width: W,
                height: H,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: samples,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Depth32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let depth_view = depth.create_view(&Default::default());
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("caller depth"),
            source: wgpu::ShaderSource::Wgsl(DEPTH_WGSL.into()),
        });
        let depth_pipeline = fullscreen_depth_pipeline(device, &module, None, samples, true);
        let rot = Mat4::from_mat3(glam::Mat3::from_mat4(cam.view));
        let p = cam.proj.to_cols_array_2d();
        let check = Check {
            inv_rotation: rot.transpose().to_cols_array_2d(),
            eye: cam.eye.to_array(),
            light_count: lights.len() as u32,
            a: cam.a,
            b: cam.b,
            p00: p[0][0],
            p11: p[1][1],
            viewport: [W as f32, H as f32],
            near: NEAR,
            far: FAR,
            standard: u32::from(cam.standard),
            mode: 0,
            p20: 0.0,
            p21: 0.0,
        };
        let check = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("check"),
            contents: bytemuck::bytes_of(&check),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let light_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("caller lights"),
            contents: bytemuck::cast_slice(lights),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let shrunk: Vec<CullLight> = lights
            .iter()
            .map(|l| CullLight {
                range: l.range * 0.9,
                ..*l
            })
            .collect();
        let shrunk_lights = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("caller lights, ranges 10% short"),
            contents: bytemuck::cast_slice(&shrunk),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let engine_buffer = |label, lights: &[CullLight]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::cast_slice(&engine_lights(lights)),
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        Caller {
            engine_lights: engine_buffer("engine lights", lights),
            shrunk_engine_lights: engine_buffer("engine lights, ranges 10% short", &shrunk),
            device: device.clone(),
            queue: queue.clone(),
            samples,
            depth,
            depth_view,
            depth_pipeline,
            check,
            lights: light_buffer,
            shrunk_lights,
            cpu_lights: lights.to_vec(),
            shrunk_cpu_lights: shrunk,
            light_count: lights.len() as u32,
            cam,
        }
    }

    /// The caller's depth pre-pass (every sample its own depth) into `encoder`.
    fn depth_prepass(&self, encoder: &mut wgpu::CommandEncoder) {
        let device = &self.device;
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &self.depth_pipeline.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: self.check.as_entire_binding(),
            }],
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("caller depth pre-pass"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(if self.cam.standard { 1.0 } else { 0.0 }),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.depth_pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
    }

    fn inputs(&self) -> CullInputs<'_> {
        CullInputs {
            depth: Some(&self.depth_view),
            transparent: false,
            cpu_lights: None,
            lights: &self.lights,
            light_count: self.light_count,
            view: self.cam.view.to_cols_array_2d(),
            proj: self.cam.proj.to_cols_array_2d(),
            near: NEAR,
            far: FAR,
            viewport: [W, H],
        }
    }

    /// Depth pre-pass, culling, and the oracle over every sample; returns the oracle's
    /// counts `[misses, reaching, listed, samples, x, y, light]` and the culler's report.
    fn frame(&self, culler: &mut LightCuller) -> ([u32; 7], lightgrid::CullReport) {
        self.frame_as(culler, Mode::default())
    }

    /// [`Self::frame_as`], once more if the frame's lists did not fit (they grew from its
    /// report).
    fn settled_frame(
        &self,
        culler: &mut LightCuller,
        mode: Mode,
    ) -> ([u32; 7], lightgrid::CullReport) {
        let first = self.frame_as(culler, mode);
        match first.1.overflowed {
            true => self.frame_as(culler, mode),
            false => first,
        }
    }

    /// [`Self::frame`], the culler given the depth or not and asked for transparent lists or
    /// not, and the oracle checking the samples or transparent fragments in front of them.
    fn frame_as(&self, culler: &mut LightCuller, mode: Mode) -> ([u32; 7], lightgrid::CullReport) {
        self.frame_with(culler, mode, None)
    }

    /// [`Self::frame_as`], the oracle binding the grid the way a caller that keeps the group
    /// does: `held`'s, taken again only when the generation moved during `encode` (`follow`),
    /// or never (a caller ignoring the rule). `None`: `bind_group()` after `encode`.
    fn frame_with(
        &self,
        culler: &mut LightCuller,
        mode: Mode,
        held: Option<(&mut Held, bool)>,
    ) -> ([u32; 7], lightgrid::CullReport) {
        let device = &self.device;
        self.queue.write_buffer(
            &self.check,
            std::mem::offset_of!(Check, mode) as u64,
            bytemuck::bytes_of(&u32::from(mode.check_transparent)),
        );
        // The frame's projection: the camera's, shifted off centre as `mode` says.
        let mut proj = self.cam.proj.to_cols_array_2d();
        proj[2][0] += mode.shift[0];
        proj[2][1] += mode.shift[1];
        self.queue.write_buffer(
            &self.check,
            std::mem::offset_of!(Check, p20) as u64,
            bytemuck::cast_slice(&[proj[2][0], proj[2][1]]),
        );
        let mut encoder = device.create_command_encoder(&Default::default());
        self.depth_prepass(&mut encoder);
        let inputs = CullInputs {
            depth: mode.depth.then_some(&self.depth_view),
            transparent: mode.transparent_lists,
            lights: match (mode.engine_layout, mode.shrunk) {
                (false, false) => &self.lights,
                (false, true) => &self.shrunk_lights,
                (true, false) => &self.engine_lights,
                (true, true) => &self.shrunk_engine_lights,
            },
            cpu_lights: mode.cpu_lights.then_some(if mode.shrunk {
                &self.shrunk_cpu_lights
            } else {
                &self.cpu_lights
            }),
            proj,
            ..self.inputs()
        };
        let frame = culler.encode(&mut encoder, &inputs).expect("culling");
        let grid_group = match held {
            Some((held, follow)) => {
                if follow && culler.bind_group_generation() != held.generation {
                    held.group = culler.bind_group().clone();
                    held.generation = culler.bind_group_generation();
                    held.moves += 1;
                }
                held.group.clone()
            }
            None => culler.bind_group().clone(),
        };
        let result = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("oracle result"),
            size: 32,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("oracle readback"),
            size: 32,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        {
            let (ty, sample) = if self.samples > 1 {
                ("texture_depth_multisampled_2d", "i32(s)")
            } else {
                ("texture_depth_2d", "0")
            };
            let check = format!(
                "const SAMPLES: u32 = {}u;\n{}",
                self.samples,
                CHECK_WGSL
                    .replace("DEPTH_TYPE", ty)
                    .replace("LOAD_SAMPLE", sample)
            );
            let src = match mode.naga_oil {
                false => format!("{}\n{check}", LightCuller::wgsl(1)),
                true => compose_with_naga_oil(&check),
            };
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("oracle"),
                source: wgpu::ShaderSource::Wgsl(src.into()),
            });
            let own = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("oracle"),
                entries: &[
                    buffer_entry(0, wgpu::BufferBindingType::Uniform),
                    buffer_entry(1, wgpu::BufferBindingType::Storage { read_only: true }),
                    wgpu::BindGroupLayoutEntry {
                        binding: 2,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Depth,
                            view_dimension: wgpu::TextureViewDimension::D2,
                            multisampled: self.samples > 1,
                        },
                        count: None,
                    },
                    buffer_entry(3, wgpu::BufferBindingType::Storage { read_only: false }),
                ],
            });
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("oracle"),
                bind_group_layouts: &[Some(&own), Some(culler.bind_group_layout())],
                immediate_size: 0,
            });
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("oracle"),
                layout: Some(&layout),
                module: &module,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: None,
            });
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("oracle"),
                layout: &own,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: self.check.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: self.lights.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(&self.depth.create_view(
                            &wgpu::TextureViewDescriptor {
                                aspect: wgpu::TextureAspect::DepthOnly,
                                ..Default::default()
                            },
                        )),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: result.as_entire_binding(),
                    },
                ],
            });
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.set_bind_group(1, &grid_group, &[]);
            pass.dispatch_workgroups(W.div_ceil(8), H.div_ceil(8), 1);
        }
        encoder.copy_buffer_to_buffer(&result, 0, &readback, 0, 32);
        self.queue.submit([encoder.finish()]);
        readback.map_async(wgpu::MapMode::Read, .., |r| r.expect("map"));
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("poll");
        let values: Vec<u32> =
            bytemuck::cast_slice(&readback.get_mapped_range(..).expect("mapped")).to_vec();
        let reports = culler.wait().expect("reports");
        let report = *reports
            .iter()
            .find(|r| r.frame == frame)
            .expect("the frame's report");
        (values[..7].try_into().unwrap(), report)
    }
}

/// A caller's copy of the culler's group, kept across frames.
struct Held {
    group: wgpu::BindGroup,
    generation: u64,
    /// Times it was taken again.
    moves: u32,
}

impl Held {
    fn take(culler: &LightCuller) -> Held {
        Held {
            group: culler.bind_group().clone(),
            generation: culler.bind_group_generation(),
            moves: 0,
        }
    }
}

/// How a test frame is culled and checked.
#[derive(Clone, Copy, Debug)]
struct Mode {
    /// The culler gets the depth buffer (`CullInputs::depth`).
    depth: bool,
    /// `CullInputs::transparent`.
    transparent_lists: bool,
    /// The oracle checks a transparent fragment in front of each sample instead of the sample.
    check_transparent: bool,
    /// The culler is given the lights with ranges 10% short (the oracle keeps the true ones).
    shrunk: bool,
    /// Added to the camera's `proj[2][0]`, `proj[2][1]` this frame: an off-centre projection
    /// (TAA jitter, a VR eye). x_ndc = p00 x / w - proj[2][0].
    shift: [f32; 2],
    /// The culler reads the lights as [`EngineLight`]s (its layout set to `ENGINE_LAYOUT`).
    engine_layout: bool,
    /// The oracle imports the accessors from `LightCuller::naga_oil_module` with naga_oil.
    naga_oil: bool,
    /// The lights are handed on the CPU as well (`CullInputs::cpu_lights`).
    cpu_lights: bool,
}

impl Default for Mode {
    fn default() -> Self {
        Mode {
            depth: true,
            transparent_lists: false,
            check_transparent: false,
            shrunk: false,
            shift: [0.0; 2],
            engine_layout: false,
            naga_oil: false,
            cpu_lights: true,
        }
    }
}

/// The oracle composed as a naga_oil user composes: the grid registered as the module
/// `lightgrid::grid`, imported by name, the result written back as WGSL.
fn compose_with_naga_oil(check: &str) -> String {
    use naga_oil::compose::{ComposableModuleDescriptor, Composer, NagaModuleDescriptor};
    let mut composer = Composer::default();
    let added = composer.add_composable_module(ComposableModuleDescriptor {
        source: &LightCuller::naga_oil_module(1),
        file_path: "lightgrid/grid.wgsl",
        ..Default::default()
    });
    if let Err(e) = added {
        panic!("the grid module: {}", e.emit_to_string(&composer));
    }
    let source = format!(
        "#import lightgrid::grid::{{light_grid_cell, light_grid_cell_transparent, light_grid_count, light_grid_light, light_grid_walk, light_grid_next}}\n{check}"
    );
    let module = match composer.make_naga_module(NagaModuleDescriptor {
        source: &source,
        file_path: "oracle.wgsl",
        ..Default::default()
    }) {
        Ok(module) => module,
        Err(e) => panic!("the oracle: {}", e.emit_to_string(&composer)),
    };
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .expect("the composed oracle validates");
    naga::back::wgsl::write_string(&module, &info, naga::back::wgsl::WriterFlags::empty())
        .expect("written as WGSL")
}

fn buffer_entry(binding: u32, ty: wgpu::BufferBindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// Cull one frame with `config` and check it against the oracle; a frame whose lists did not
/// fit is culled again (the lists grew from its report). Returns the lights listed per sample.
fn check(caller: &Caller, config: CullConfig, what: &str) -> f64 {
    check_as(caller, config, what, Mode::default())
}

/// [`check`], the frame culled and checked as `mode` says.
fn check_as(caller: &Caller, config: CullConfig, what: &str, mode: Mode) -> f64 {
    let mut culler = LightCuller::new(&caller.device, &caller.queue, config).expect("culler");
    let (r, report) = caller.settled_frame(&mut culler, mode);
    assert_lists_every_light(caller, r, &report, what)
}

/// The oracle's counts `r` and the report of one frame: complete, a scene that tests
/// something, no reaching light missing, and lists that cull. Returns the lights listed per
/// sample.
fn assert_lists_every_light(
    caller: &Caller,
    r: [u32; 7],
    report: &lightgrid::CullReport,
    what: &str,
) -> f64 {
    assert!(report.is_complete(), "{what}: {report:?}");
    assert!(
        r[3] > W * H / 2,
        "{what}: only {} samples have geometry",
        r[3]
    );
    assert!(
        r[1] > 5_000,
        "{what}: only {} light-sample pairs: the scene tests nothing",
        r[1]
    );
    assert_eq!(
        r[0], 0,
        "{what}: {} lights reaching samples are missing from their cells (first: pixel ({}, {}), light {})",
        r[0], r[4], r[5], r[6]
    );
    // Culling culls: the lists hold far fewer than every light per sample.
    let per_sample = f64::from(r[2]) / f64::from(r[3]);
    let reaching = f64::from(r[1]) / f64::from(r[3]);
    println!("{what}: {per_sample:.1} listed, {reaching:.1} reaching per sample");
    assert!(
        per_sample < f64::from(caller.light_count) * 0.6,
        "{what}: {per_sample:.1} lights listed per sample of {}",
        caller.light_count
    );
    per_sample
}

/// A frame culled as `mode` says but with the lights' ranges 10% short must miss lights: the
/// oracle catches a culler that undersizes them.
fn assert_shrunk_misses(caller: &Caller, culler: &mut LightCuller, mode: Mode, what: &str) {
    let (r, _) = caller.settled_frame(
        culler,
        Mode {
            shrunk: true,
            ..mode
        },
    );
    assert!(
        r[0] > 100,
        "{what}: ranges 10% short must miss lights: {} misses",
        r[0]
    );
}

/// The strategies a caller's culler offers: every row of the registry (`cpu` and `bvh` are
/// given the lights on the CPU as well, `CullInputs::cpu_lights`).
fn strategies() -> Vec<Assign> {
    lightgrid::testing::STRATEGIES
        .iter()
        .map(|s| s.assign)
        .collect()
}
/// (tile size, slices): tiles, and clusters.
const GRIDS: [(u32, u32); 2] = [(16, 1), (32, 16)];

#[test]
fn every_strategy_grid_and_depth_bounds_mode_lists_every_reaching_light() {
    let (device, queue) = device();
    let cam = camera(Vec3::new(3.0, 2.0, 10.0), false);
    let lights = lights(&cam, 300, 7);
    let caller = Caller::new(&device, &queue, 1, cam, &lights);
    for strategy in strategies() {
        for grid in GRIDS {
            for depth_bounds in [
                DepthBounds::Both,
                DepthBounds::Min,
                DepthBounds::Max,
                DepthBounds::None,
            ] {
                let config = CullConfig {
                    tile_size: grid.0,
                    slices: grid.1,
                    strategy,
                    depth_bounds,
                    ..CullConfig::default()
                };
                check(
                    &caller,
                    config,
                    &format!("{strategy:?} {grid:?} {depth_bounds:?}"),
                );
            }
        }
    }
}

/// 2.5D culling and tight cells through the public API (`CullConfig::depth_mask`,
/// `CullConfig::cell_box`): every strategy and grid, with and without MSAA depth, lists every
/// reaching light, and never more per sample than the same grid without them. (This caller's
/// depth has noise per sample, which fills every bin of a tile, so the masks drop next to
/// nothing here; `tests/pipelines.rs` checks that masks and boxes drop lights on the
/// catalog's robots in front of the street.)
#[test]
fn depth_masks_and_cell_boxes_list_every_reaching_light() {
    let (device, queue) = device();
    let eye = Vec3::new(3.0, 2.0, 10.0);
    let lights = lights(&camera(eye, false), 300, 17);
    for samples in [1, 4] {
        let caller = Caller::new(&device, &queue, samples, camera(eye, false), &lights);
        for strategy in strategies() {
            for grid in GRIDS {
                let config = |depth_mask, cell_box| CullConfig {
                    tile_size: grid.0,
                    slices: grid.1,
                    strategy,
                    samples,
                    depth_mask,
                    cell_box,
                    ..CullConfig::default()
                };
                let what = format!("{strategy:?} {grid:?} MSAA {samples}");
                if strategy == Assign::ZBin {
                    // No per-cell lists to cut: refused, with the setting named.
                    for (mask, cell_box) in
                        [(DepthMask::On, CellBox::Off), (DepthMask::Off, CellBox::On)]
                    {
                        let e = LightCuller::new(&device, &queue, config(mask, cell_box))
                            .err()
                            .unwrap_or_else(|| panic!("{what}: masks or boxes accepted"));
                        assert_eq!(e.input, CullInput::Config, "{e}");
                    }
                    check(&caller, config(DepthMask::Off, CellBox::Off), &what);
                    continue;
                }
                let off = check(
                    &caller,
                    config(DepthMask::Off, CellBox::Off),
                    &format!("{what} plain"),
                );
                for (mask, cell_box) in
                    [(DepthMask::On, CellBox::Off), (DepthMask::Off, CellBox::On)]
                {
                    let on = check(
                        &caller,
                        config(mask, cell_box),
                        &format!("{what} mask {} box {}", mask.name(), cell_box.name()),
                    );
                    assert!(
                        on <= off,
                        "{what}: {on:.2} listed with mask {mask:?} box {cell_box:?}, {off:.2} without"
                    );
                }
            }
        }
    }
}

#[test]
fn msaa_depth_standard_depth_and_a_camera_far_from_the_origin() {
    let (device, queue) = device();
    // Reversed-Z, every sample its own depth.
    let cam = camera(Vec3::new(3.0, 2.0, 10.0), false);
    let lights_near = lights(&cam, 300, 11);
    let msaa = Caller::new(&device, &queue, 4, cam, &lights_near);
    for strategy in strategies() {
        for grid in GRIDS {
            let config = CullConfig {
                tile_size: grid.0,
                slices: grid.1,
                strategy,
                samples: 4,
                ..CullConfig::default()
            };
            check(&msaa, config, &format!("MSAA 4 {strategy:?} {grid:?}"));
        }
    }
    // Standard depth (0 at near, cleared to 1), 20 km from the origin.
    let cam = camera(Vec3::new(20_000.0, 35.0, -12_000.0), true);
    let far_lights = lights(&cam, 300, 13);
    let far = Caller::new(&device, &queue, 1, cam, &far_lights);
    for grid in GRIDS {
        let config = CullConfig {
            tile_size: grid.0,
            slices: grid.1,
            strategy: Assign::Gather,
            ..CullConfig::default()
        };
        check(
            &far,
            config,
            &format!("standard depth far from the origin {grid:?}"),
        );
    }
}

#[test]
fn lists_grow_from_the_reports_and_refused_lights_are_reported() {
    let (device, queue) = device();
    let cam = camera(Vec3::new(3.0, 2.0, 10.0), false);
    let mut lights = lights(&cam, 300, 17);
    for strategy in strategies() {
        let config = CullConfig {
            strategy,
            index_capacity: 1,
            ..CullConfig::default()
        };
        let caller = Caller::new(&device, &queue, 1, camera(cam.eye, false), &lights);
        let mut culler = LightCuller::new(&device, &queue, config).expect("culler");
        let (r, first) = caller.frame(&mut culler);
        if strategy == Assign::Cpu {
            // The CPU uploads its whole grid, whatever the capacity: nothing to grow.
            assert!(first.is_complete(), "{strategy:?}: {first:?}");
            assert!(first.index_entries > 1000, "{first:?}");
            assert_eq!(r[0], 0, "{strategy:?}: misses");
            continue;
        }
        if strategy == Assign::ZBin {
            // Z-bins are sized from the light count each frame: nothing to grow.
            assert!(first.is_complete(), "{strategy:?}: {first:?}");
            // The sorted lights, then 10 mask words for each 16-pixel tile.
            assert_eq!(
                first.index_entries,
                300 + W.div_ceil(16) * H.div_ceil(16) * 10,
                "{first:?}"
            );
            assert_eq!(r[0], 0, "{strategy:?}: misses");
            continue;
        }
        assert!(
            first.overflowed,
            "{strategy:?}: one index entry cannot hold the grid: {first:?}"
        );
        assert!(!first.is_complete());
        let (r, second) = caller.frame(&mut culler);
        assert!(
            second.is_complete(),
            "{strategy:?}: the lists did not grow: {second:?}"
        );
        assert_eq!(r[0], 0, "{strategy:?}: misses after growing");
    }
    // A NaN position and a zero range: refused on the GPU, counted, and in no list (handed on
    // the CPU as well, `auto` would assign there and refuse the frame: the test above).
    lights[5].position[1] = f32::NAN;
    lights[9].range = 0.0;
    let caller = Caller::new(&device, &queue, 1, camera(cam.eye, false), &lights);
    let mut culler = LightCuller::new(&device, &queue, CullConfig::default()).expect("culler");
    let gpu_only = Mode {
        cpu_lights: false,
        ..Mode::default()
    };
    let (_, report) = caller.frame_as(&mut culler, gpu_only);
    assert_eq!(report.invalid_lights, 2, "{report:?}");
    assert!(!report.is_complete());
}

/// The caller's own light struct (`LightCuller::set_light_layout`): a 64-byte stride with the
/// fields shuffled among the engine's own (NaN in fields the culler must not read), read in
/// place. Every strategy, tiles and clusters, with the depth and without: every reaching light
/// listed, and the same lists as the `CullLight` buffer gives; ranges 10% short miss lights.
#[test]
fn the_callers_own_light_layout_is_read_in_place() {
    let (device, queue) = device();
    let cam = camera(Vec3::new(3.0, 2.0, 10.0), false);
    let lights = lights(&cam, 300, 41);
    let caller = Caller::new(&device, &queue, 1, cam, &lights);
    for strategy in strategies() {
        for grid in GRIDS {
            let config = CullConfig {
                tile_size: grid.0,
                slices: grid.1,
                strategy,
                ..CullConfig::default()
            };
            for depth in [true, false] {
                let what = format!("{strategy:?} {grid:?} depth {depth}");
                let plain = check_as(
                    &caller,
                    config,
                    &what,
                    Mode {
                        depth,
                        ..Mode::default()
                    },
                );
                let mut culler = LightCuller::new(&device, &queue, config).expect("culler");
                assert_eq!(culler.light_layout(), LightLayout::CULL_LIGHT);
                culler.set_light_layout(ENGINE_LAYOUT).expect("layout");
                let mode = Mode {
                    depth,
                    engine_layout: true,
                    ..Mode::default()
                };
                let (r, report) = caller.settled_frame(&mut culler, mode);
                let listed = assert_lists_every_light(&caller, r, &report, &what);
                assert_eq!(listed, plain, "{what}: the engine's layout lists otherwise");
            }
        }
        let mut culler = LightCuller::new(
            &device,
            &queue,
            CullConfig {
                strategy,
                ..CullConfig::default()
            },
        )
        .expect("culler");
        culler.set_light_layout(ENGINE_LAYOUT).expect("layout");
        let engine = Mode {
            engine_layout: true,
            ..Mode::default()
        };
        assert_shrunk_misses(&caller, &mut culler, engine, &format!("{strategy:?}"));
    }
}

/// The accessors as a naga_oil module (`LightCuller::naga_oil_module`): the oracle imports
/// `lightgrid::grid`'s functions by name through naga_oil's composer, and checks tiles and
/// clusters, z-bins and lists, samples and transparent fragments, as the text form does.
#[test]
fn the_naga_oil_module_serves_a_composed_shader() {
    let (device, queue) = device();
    let cam = camera(Vec3::new(3.0, 2.0, 10.0), false);
    let lights = lights(&cam, 300, 43);
    let caller = Caller::new(&device, &queue, 1, cam, &lights);
    for strategy in [Assign::Gather, Assign::ZBin] {
        for grid in GRIDS {
            let config = CullConfig {
                tile_size: grid.0,
                slices: grid.1,
                strategy,
                ..CullConfig::default()
            };
            for (transparent, depth) in [(false, true), (true, true), (false, false)] {
                let mode = Mode {
                    depth,
                    transparent_lists: transparent && depth,
                    check_transparent: transparent,
                    naga_oil: true,
                    ..Mode::default()
                };
                let what = format!("naga_oil {strategy:?} {grid:?} transparent {transparent}");
                let text = check_as(
                    &caller,
                    config,
                    &what,
                    Mode {
                        naga_oil: false,
                        ..mode
                    },
                );
                let module = check_as(&caller, config, &what, mode);
                assert_eq!(module, text, "{what}: the module lists otherwise");
            }
        }
    }
    // The shrunk lights still miss through the module (the oracle is the same oracle).
    let mut culler = LightCuller::new(&device, &queue, CullConfig::default()).expect("culler");
    let module = Mode {
        naga_oil: true,
        ..Mode::default()
    };
    assert_shrunk_misses(&caller, &mut culler, module, "naga_oil");
}

/// A bind group that stays (`LightCuller::bind_group`'s rule): the group a caller takes before
/// the first frame serves every frame until `bind_group_generation` moves, which happens only
/// in `encode`. Growing from one index entry, the caller following the rule takes it again
/// once and its frames then list every light; a caller ignoring the rule reads the stale group
/// and misses lights (the oracle catches it). With `reserve` and an index capacity set up
/// front, the group taken once serves every frame: with depth, transparent lists and froxels.
#[test]
fn the_bind_group_stays_until_its_generation_moves() {
    let (device, queue) = device();
    let cam = camera(Vec3::new(3.0, 2.0, 10.0), false);
    let lights = lights(&cam, 300, 37);
    let caller = Caller::new(&device, &queue, 1, cam, &lights);
    for strategy in strategies() {
        let config = CullConfig {
            strategy,
            index_capacity: 1,
            ..CullConfig::default()
        };
        // Following the rule.
        let mut culler = LightCuller::new(&device, &queue, config).expect("culler");
        let mut held = Held::take(&culler);
        let mut reports = Vec::new();
        for frame in 0..4 {
            let (r, report) =
                caller.frame_with(&mut culler, Mode::default(), Some((&mut held, true)));
            // `frame_with` waited for the reports: the lists grew there, the group did not.
            assert_eq!(
                culler.bind_group_generation(),
                held.generation,
                "{strategy:?} frame {frame}: the group moved outside encode"
            );
            if frame >= 2 {
                let what = format!("{strategy:?} frame {frame}");
                assert_lists_every_light(&caller, r, &report, &what);
            }
            reports.push((report, held.moves));
        }
        let grew = reports[0].0.overflowed;
        assert!(
            !grew || held.moves >= 1,
            "{strategy:?}: the lists grew without a new group: {reports:?}"
        );
        assert_eq!(
            reports[2].1, reports[3].1,
            "{strategy:?}: the group moved once the lists fit: {reports:?}"
        );
        // Ignoring the rule: the group from before the first frame, after the lists grew.
        if grew {
            let mut culler = LightCuller::new(&device, &queue, config).expect("culler");
            let mut stale = Held::take(&culler);
            caller.frame_with(&mut culler, Mode::default(), Some((&mut stale, false)));
            let (r, report) =
                caller.frame_with(&mut culler, Mode::default(), Some((&mut stale, false)));
            assert!(report.is_complete(), "{strategy:?}: {report:?}");
            assert_ne!(culler.bind_group_generation(), stale.generation);
            assert!(
                r[0] > 100,
                "{strategy:?}: a stale group must miss lights: {} misses",
                r[0]
            );
        }
        // Room set up front: the group taken once serves every frame.
        let mut culler = LightCuller::new(
            &device,
            &queue,
            CullConfig {
                index_capacity: 1 << 18,
                ..config
            },
        )
        .expect("culler");
        culler.reserve([W, H]).expect("reserve");
        let mut once = Held::take(&culler);
        let modes = [
            Mode::default(),
            Mode {
                transparent_lists: true,
                check_transparent: true,
                ..Mode::default()
            },
            Mode {
                depth: false,
                ..Mode::default()
            },
            Mode::default(),
        ];
        for (k, mode) in modes.into_iter().enumerate() {
            let (r, report) = caller.frame_with(&mut culler, mode, Some((&mut once, false)));
            assert_eq!(
                culler.bind_group_generation(),
                once.generation,
                "{strategy:?} reserved, frame {k}: the group moved"
            );
            let what = format!("{strategy:?} reserved, frame {k}");
            assert_lists_every_light(&caller, r, &report, &what);
        }
    }
}

/// `auto` resolves as lightgrid's renderer resolves it: on a CPU adapter (lavapipe here) a
/// frame that hands its lights on the CPU is assigned there (`cpu` uploads its whole grid, so
/// even one index entry of capacity fits its first frame), one that does not stays on the GPU
/// (`gather` overflows one entry); on a GPU both stay there.
#[test]
fn auto_assigns_on_a_software_adapters_cpu_when_given_the_lights() {
    let (device, queue) = device();
    let software = device.adapter_info().device_type == wgpu::DeviceType::Cpu;
    let cam = camera(Vec3::new(3.0, 2.0, 10.0), false);
    let lights = lights(&cam, 300, 47);
    let caller = Caller::new(&device, &queue, 1, cam, &lights);
    let config = CullConfig {
        strategy: Assign::Auto,
        index_capacity: 1,
        ..CullConfig::default()
    };
    for cpu_lights in [true, false] {
        let mut culler = LightCuller::new(&device, &queue, config).expect("culler");
        let mode = Mode {
            cpu_lights,
            ..Mode::default()
        };
        let (r, first) = caller.frame_as(&mut culler, mode);
        let on_cpu = software && cpu_lights;
        assert_eq!(
            first.overflowed, !on_cpu,
            "software adapter {software}, cpu_lights {cpu_lights}: {first:?}"
        );
        if on_cpu {
            assert_lists_every_light(&caller, r, &first, "auto on the CPU");
        }
        let (r, second) = caller.frame_as(&mut culler, mode);
        assert_lists_every_light(
            &caller,
            r,
            &second,
            &format!("auto, cpu_lights {cpu_lights}"),
        );
    }
    // Handed lights that are not finite, `auto` on the CPU refuses them (as `cpu` does).
    if software {
        let mut culler = LightCuller::new(&device, &queue, config).expect("culler");
        let mut bad = lights.clone();
        bad[3].range = f32::NAN;
        let e = refused(
            &mut culler,
            &device,
            &CullInputs {
                cpu_lights: Some(&bad),
                ..caller.inputs()
            },
        );
        assert_eq!(e.input, CullInput::Lights, "{e}");
    }
}

/// Froxels without a depth pre-pass (`CullInputs::depth: None`): every cell spans its slice of
/// near..far, so a sample, or a transparent surface anywhere in front of it, finds every light
/// reaching it in the cell its view distance names. On tiles the lists are never shorter than
/// with the depth (the cells only grow), and they still cull.
#[test]
fn froxels_without_depth_list_every_light_reaching_any_surface() {
    let (device, queue) = device();
    let cam = camera(Vec3::new(3.0, 2.0, 10.0), false);
    let lights = lights(&cam, 300, 23);
    let caller = Caller::new(&device, &queue, 1, cam, &lights);
    for strategy in strategies() {
        // Lights per sample without depth: on tiles, then on clusters.
        let mut without_depth = Vec::new();
        for grid in GRIDS {
            let config = CullConfig {
                tile_size: grid.0,
                slices: grid.1,
                strategy,
                ..CullConfig::default()
            };
            let what = format!("{strategy:?} {grid:?}");
            let with_depth =
                (grid.1 == 1).then(|| check(&caller, config, &format!("{what} with depth")));
            for check_transparent in [false, true] {
                let mode = Mode {
                    depth: false,
                    transparent_lists: false,
                    check_transparent,
                    ..Mode::default()
                };
                let what =
                    format!("{what} without depth, transparent fragments {check_transparent}");
                let without = check_as(&caller, config, &what, mode);
                if let Some(with_depth) = with_depth.filter(|_| !check_transparent) {
                    assert!(without >= with_depth, "{what}: {without} < {with_depth}");
                }
                if !check_transparent {
                    without_depth.push(without);
                }
            }
        }
        // Froxels are bounded by their slices: the clusters cull far more than tiles over
        // near..far (z-binning's bins are per slice range of the whole screen: less so).
        // The oracle catches a culler that undersizes the lights, without depth too.
        let mut culler = LightCuller::new(
            &device,
            &queue,
            CullConfig {
                strategy,
                ..CullConfig::default()
            },
        )
        .expect("culler");
        let froxels = Mode {
            depth: false,
            ..Mode::default()
        };
        assert_shrunk_misses(&caller, &mut culler, froxels, &format!("{strategy:?}"));
        if strategy != Assign::ZBin {
            assert!(
                without_depth[1] < 0.5 * without_depth[0],
                "{strategy:?}: clusters without depth list {:.1} per sample, tiles {:.1}",
                without_depth[1],
                without_depth[0]
            );
        }
    }
}

/// Off-centre projections (`CullInputs::proj` with `proj[2][0]`, `proj[2][1]`): TAA jitter of
/// up to ±0.5 px that changes every frame (one culler, as an engine runs it), a VR eye whose
/// principal point sits 20% of the width off centre, and an off-axis display shifted in both
/// axes. Every strategy, tiles and clusters, with the depth and without (froxels): every light
/// reaching a sample is in its cell. Each case with ranges 10% short must miss lights.
#[test]
fn jittered_and_off_centre_projections_list_every_reaching_light() {
    let (device, queue) = device();
    let cam = camera(Vec3::new(3.0, 2.0, 10.0), false);
    let lights = lights(&cam, 300, 31);
    let caller = Caller::new(&device, &queue, 1, cam, &lights);
    // A sub-pixel jitter in NDC (2 / W per pixel), from a Halton-like sequence.
    let jitter = |k: usize| {
        let h = |base: usize| {
            let (mut f, mut r, mut i) = (1.0f32, 0.0f32, k + 1);
            while i > 0 {
                f /= base as f32;
                r += f * (i % base) as f32;
                i /= base;
            }
            r - 0.5
        };
        [h(2) * 2.0 / W as f32, h(3) * 2.0 / H as f32]
    };
    // (name, shift per frame): the principal point at x = W/2 + 0.2 W is ndc 0.4, so
    // proj[2][0] = -0.4; an off-axis window far from the axis in both directions.
    let vr_eye = |_: usize| [-0.4, 0.0];
    let off_axis = |_: usize| [0.6, -0.5];
    // (name, shift of frame k, the frames: with the depth or without).
    type Case<'a> = (&'a str, &'a dyn Fn(usize) -> [f32; 2], &'a [bool]);
    let cases: [Case; 3] = [
        ("TAA jitter", &jitter, &[true, true, false, true]),
        ("VR eye", &vr_eye, &[true, false]),
        ("off-axis", &off_axis, &[true, false]),
    ];
    for (name, shift, frames) in cases {
        for strategy in strategies() {
            for grid in GRIDS {
                let config = CullConfig {
                    tile_size: grid.0,
                    slices: grid.1,
                    strategy,
                    ..CullConfig::default()
                };
                let mut culler = LightCuller::new(&device, &queue, config).expect("culler");
                for (k, &depth) in frames.iter().enumerate() {
                    let mode = Mode {
                        depth,
                        shift: shift(k),
                        ..Mode::default()
                    };
                    let what = format!(
                        "{name} {:?} {strategy:?} {grid:?} depth {depth}",
                        mode.shift
                    );
                    let (r, report) = caller.settled_frame(&mut culler, mode);
                    assert_lists_every_light(&caller, r, &report, &what);
                }
            }
        }
        let mut culler = LightCuller::new(&device, &queue, CullConfig::default()).expect("culler");
        let shifted = Mode {
            shift: shift(5),
            ..Mode::default()
        };
        assert_shrunk_misses(&caller, &mut culler, shifted, name);
    }
}

/// Transparent surfaces in front of the depth (`CullInputs::transparent`): with separate lists
/// (a second layer of cells, read with `light_grid_cell_transparent`) or shared ones (the
/// opaque cells widened to the near plane), every light reaching a fragment between the near
/// plane and the sample is listed, and the samples still find theirs. Without transparent
/// lists the same fragments miss lights: the oracle catches it. Asking for transparent lists
/// without a depth buffer is a typed error.
#[test]
fn transparent_lists_cover_surfaces_in_front_of_the_depth() {
    let (device, queue) = device();
    let cam = camera(Vec3::new(3.0, 2.0, 10.0), false);
    let lights = lights(&cam, 300, 29);
    let caller = Caller::new(&device, &queue, 1, cam, &lights);
    for strategy in strategies() {
        for grid in GRIDS {
            for lists in [GridLists::Separate, GridLists::Shared] {
                let config = CullConfig {
                    tile_size: grid.0,
                    slices: grid.1,
                    strategy,
                    lists,
                    ..CullConfig::default()
                };
                for check_transparent in [true, false] {
                    let mode = Mode {
                        depth: true,
                        transparent_lists: true,
                        check_transparent,
                        ..Mode::default()
                    };
                    let what = format!(
                        "{strategy:?} {grid:?} {lists:?}, transparent fragments {check_transparent}"
                    );
                    check_as(&caller, config, &what, mode);
                }
            }
        }
    }
    let mut culler = LightCuller::new(&device, &queue, CullConfig::default()).expect("culler");
    let without_lists = Mode {
        depth: true,
        transparent_lists: false,
        check_transparent: true,
        ..Mode::default()
    };
    let (r, report) = caller.settled_frame(&mut culler, without_lists);
    assert!(report.is_complete(), "{report:?}");
    assert!(
        r[0] > 100,
        "without transparent lists, fragments in front of the samples must miss lights: {} misses",
        r[0]
    );
    let e = refused(
        &mut culler,
        &device,
        &CullInputs {
            depth: None,
            transparent: true,
            ..caller.inputs()
        },
    );
    assert_eq!(e.input, CullInput::Depth, "{e}");
}

/// What a renderer adds through `encode_with` ([`CullExtras`]), as lightgrid's own renderer
/// does: its pass timer holds the culling passes; its frame's CPU-side costs gain `cpu`'s
/// part-way readback; the report names the strategy that ran and its CPU time; and with MSAA
/// the fragments it draws in the culler's pass widen their cells' bounds.
#[test]
fn extras_time_the_passes_count_the_readback_and_bound_msaa_fragments() {
    let (device, queue, timestamps) = device_with(true);
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        assert!(timestamps, "lavapipe offers TIMESTAMP_QUERY");
    }
    let cam = camera(Vec3::new(3.0, 2.0, 10.0), false);
    let lights = lights(&cam, 300, 53);
    let caller = Caller::new(&device, &queue, 1, cam, &lights);
    for strategy in [Assign::Cpu, Assign::Gather, Assign::Auto] {
        let config = CullConfig {
            strategy,
            index_capacity: 1 << 17,
            ..CullConfig::default()
        };
        let mut culler = LightCuller::new(&device, &queue, config).expect("culler");
        let mut timer = PassTimer::for_device(&device, &queue, timestamps, 64);
        let mut io = FrameIo::default();
        let mut encoder = device.create_command_encoder(&Default::default());
        caller.depth_prepass(&mut encoder);
        let inputs = CullInputs {
            cpu_lights: Some(&caller.cpu_lights),
            ..caller.inputs()
        };
        let extras = CullExtras {
            timer: Some(&mut timer),
            io: Some(&mut io),
            fragments: None,
        };
        let frame = culler
            .encode_with(&mut encoder, &inputs, extras)
            .expect("culling");
        queue.submit([encoder.finish()]);
        let reports = culler.wait().expect("reports");
        let report = reports.iter().find(|r| r.frame == frame).expect("report");
        assert!(report.is_complete(), "{strategy:?}: {report:?}");
        let ran = report.assign;
        assert_ne!(ran, Assign::Auto, "auto is reported resolved");
        if strategy != Assign::Auto {
            assert_eq!(ran, strategy);
        }
        if ran == Assign::Cpu {
            // The cell bounds read back part-way: one submission, its bytes, its wait.
            assert_eq!(io.submits, 1, "{strategy:?}: {io:?}");
            assert!(io.readback_bytes > 0, "{strategy:?}: {io:?}");
            assert!(report.cpu_ms > 0.0, "{strategy:?}: {report:?}");
        } else {
            assert_eq!(
                io,
                FrameIo::default(),
                "{strategy:?}: a GPU strategy adds nothing"
            );
            assert_eq!(report.cpu_ms, 0.0);
        }
        let passes = timer.read_passes(&device, &queue).expect("timings");
        let labels: Vec<&str> = passes.iter().map(|p| p.label.as_str()).collect();
        match timestamps {
            true => {
                for wanted in [
                    lightgrid::culling::labels::CULL_LIGHTS,
                    "assign: cell bounds",
                ] {
                    assert!(labels.contains(&wanted), "{strategy:?}: {labels:?}");
                }
                assert!(passes.iter().all(|p| p.ms >= 0.0 && p.ms.is_finite()));
            }
            false => assert!(passes.is_empty()),
        }
    }
    // MSAA: every pixel's fragment at a view distance nearer than any sample, drawn in the
    // culler's pass; every tile's bounds then reach it, and without the draws some do not.
    const W_FRAG: f32 = 2.0 * NEAR;
    let msaa = Caller::new(
        &device,
        &queue,
        4,
        camera(Vec3::new(3.0, 2.0, 10.0), false),
        &lights,
    );
    let config = CullConfig {
        strategy: Assign::Gather,
        samples: 4,
        slices: 1,
        index_capacity: 1 << 17,
        ..CullConfig::default()
    };
    let mut culler = LightCuller::new(&device, &queue, config).expect("culler");
    assert!(LightCuller::new(&device, &queue, CullConfig::default())
        .expect("culler")
        .fragment_bounds_layout()
        .is_none());
    let layout = culler.fragment_bounds_layout().expect("MSAA").clone();
    let source = format!(
        "{}\n@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {{
             let p = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
             return vec4<f32>(p * 2.0 - 1.0, 0.5, 1.0);
         }}
         @fragment fn fs(@builtin(position) pos: vec4<f32>) {{
             light_grid_bound_fragment(pos.xy, {W_FRAG:?}, false);
         }}",
        LightCuller::fragment_bounds_wgsl(0)
    );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("caller fragments"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("caller fragments"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = fullscreen_depth_pipeline(&device, &module, Some(&pipeline_layout), 4, false);
    let draw = |pass: &mut wgpu::RenderPass<'_>, group: &wgpu::BindGroup| {
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.draw(0..3, 0..1);
    };
    for with_fragments in [false, true] {
        let mut encoder = device.create_command_encoder(&Default::default());
        msaa.depth_prepass(&mut encoder);
        let extras = CullExtras {
            fragments: with_fragments.then_some(&draw as _),
            ..CullExtras::default()
        };
        culler
            .encode_with(&mut encoder, &msaa.inputs(), extras)
            .expect("culling");
        queue.submit([encoder.finish()]);
        let reports = culler.wait().expect("reports");
        assert!(reports.iter().all(|r| r.is_complete()), "{reports:?}");
        let bounds = culler.read_cell_bounds().expect("bounds");
        let reach = bounds
            .iter()
            .filter(|b| b[0] <= W_FRAG * 1.001 && b[0] <= b[1])
            .count();
        match with_fragments {
            true => assert_eq!(reach, bounds.len(), "every tile holds its fragments"),
            false => assert!(reach < bounds.len(), "the samples alone lie farther"),
        }
    }
}

fn refused(culler: &mut LightCuller, device: &wgpu::Device, inputs: &CullInputs) -> CullError {
    let mut encoder = device.create_command_encoder(&Default::default());
    culler
        .encode(&mut encoder, inputs)
        .expect_err("bad input must be refused")
}

#[test]
fn bad_use_is_a_typed_error_naming_the_input() {
    let (device, queue) = device();
    let cam = camera(Vec3::new(3.0, 2.0, 10.0), false);
    let lights = lights(&cam, 40, 19);
    let caller = Caller::new(&device, &queue, 1, cam, &lights);
    let mut culler = LightCuller::new(
        &device,
        &queue,
        CullConfig {
            max_lights: 40,
            ..CullConfig::default()
        },
    )
    .expect("culler");
    let good = caller.inputs();
    let expect = |culler: &mut LightCuller, inputs: &CullInputs, input: CullInput, words: &str| {
        let e = refused(culler, &device, inputs);
        assert_eq!(e.input, input, "{e}");
        assert!(e.to_string().contains(words), "{e} (expected '{words}')");
    };
    // Depth: a colour texture, an MSAA texture for a 1-sample culler, no TEXTURE_BINDING.
    let texture = |format, samples, usage| {
        device
            .create_texture(&wgpu::TextureDescriptor {
                label: None,
                size: wgpu::Extent3d {
                    width: W,
                    height: H,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
            .create_view(&Default::default())
    };
    use wgpu::TextureUsages as U;
    let colour = texture(wgpu::TextureFormat::Rgba8Unorm, 1, U::TEXTURE_BINDING);
    expect(
        &mut culler,
        &CullInputs {
            depth: Some(&colour),
            ..caller.inputs()
        },
        CullInput::Depth,
        "not a depth format",
    );
    let msaa = texture(
        wgpu::TextureFormat::Depth32Float,
        4,
        U::TEXTURE_BINDING | U::RENDER_ATTACHMENT,
    );
    expect(
        &mut culler,
        &CullInputs {
            depth: Some(&msaa),
            ..caller.inputs()
        },
        CullInput::Depth,
        "4 samples",
    );
    let unbound = texture(wgpu::TextureFormat::Depth32Float, 1, U::RENDER_ATTACHMENT);
    expect(
        &mut culler,
        &CullInputs {
            depth: Some(&unbound),
            ..caller.inputs()
        },
        CullInput::Depth,
        "TEXTURE_BINDING",
    );
    // Lights: a buffer smaller than the count says, more lights than configured, no STORAGE.
    let small = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 48 * 10,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    expect(
        &mut culler,
        &CullInputs {
            lights: &small,
            ..caller.inputs()
        },
        CullInput::Lights,
        "1920 bytes",
    );
    expect(
        &mut culler,
        &CullInputs {
            light_count: 41,
            ..caller.inputs()
        },
        CullInput::LightCount,
        "max_lights 40",
    );
    // Even no lights need a buffer of one light (a storage binding holds one element).
    let tiny = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 16,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    expect(
        &mut culler,
        &CullInputs {
            lights: &tiny,
            light_count: 0,
            ..caller.inputs()
        },
        CullInput::Lights,
        "48 bytes",
    );
    let uniform = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 48 * 40,
        usage: wgpu::BufferUsages::UNIFORM,
        mapped_at_creation: false,
    });
    expect(
        &mut culler,
        &CullInputs {
            lights: &uniform,
            ..caller.inputs()
        },
        CullInput::Lights,
        "STORAGE",
    );
    // The caller's light layout: refused by the field at fault, and the layout unchanged.
    let layouts = [
        (
            LightLayout {
                stride: 50,
                ..ENGINE_LAYOUT
            },
            "multiple of 4",
        ),
        (
            LightLayout {
                stride: 0,
                ..ENGINE_LAYOUT
            },
            "between 4 and 4096",
        ),
        (
            LightLayout {
                stride: 8192,
                ..ENGINE_LAYOUT
            },
            "between 4 and 4096",
        ),
        (
            LightLayout {
                position: 2,
                ..ENGINE_LAYOUT
            },
            "position at byte 2",
        ),
        (
            LightLayout {
                range: 64,
                ..ENGINE_LAYOUT
            },
            "range (bytes 64..68) does not fit",
        ),
        (
            LightLayout {
                position: 56,
                ..ENGINE_LAYOUT
            },
            "position (bytes 56..68)",
        ),
        (
            LightLayout {
                cos_outer: None,
                ..ENGINE_LAYOUT
            },
            "come together",
        ),
        (
            LightLayout {
                range: 52,
                ..ENGINE_LAYOUT
            },
            "position and range overlap",
        ),
        (
            LightLayout {
                cos_outer: Some(24),
                ..ENGINE_LAYOUT
            },
            "direction and cos_outer overlap",
        ),
    ];
    for (layout, words) in layouts {
        let e = culler
            .set_light_layout(layout)
            .expect_err(&format!("{layout:?} accepted"));
        assert_eq!(e.input, CullInput::Lights, "{e}");
        assert!(e.to_string().contains(words), "{e} (expected '{words}')");
        assert_eq!(culler.light_layout(), LightLayout::CULL_LIGHT);
    }
    // Room reserved for no pixels, beyond any texture, or for more cells than a device binds
    // (4-px tiles, 256 slices, two layers over the largest texture).
    let huge = [1 << 30, 1 << 30];
    let largest = device.limits().max_texture_dimension_2d;
    let mut fine = LightCuller::new(
        &device,
        &queue,
        CullConfig {
            tile_size: 4,
            slices: 256,
            ..CullConfig::default()
        },
    )
    .expect("culler");
    for (fine_grid, viewport, words) in [
        (false, [0, H], "no pixels"),
        (false, huge, "largest 2D texture"),
        (true, [largest, largest], "cells, more than"),
    ] {
        let target = if fine_grid { &mut fine } else { &mut culler };
        let e = target.reserve(viewport).expect_err("reserved");
        assert_eq!(e.input, CullInput::Viewport, "{e}");
        assert!(e.to_string().contains(words), "{e} (expected '{words}')");
    }
    // A frame without depth cannot be larger than a texture either.
    expect(
        &mut culler,
        &CullInputs {
            depth: None,
            viewport: huge,
            ..caller.inputs()
        },
        CullInput::Viewport,
        "largest 2D texture",
    );
    // A buffer of 40 CullLights is too short for 40 lights of 64 bytes.
    culler.set_light_layout(ENGINE_LAYOUT).expect("layout");
    expect(
        &mut culler,
        &caller.inputs(),
        CullInput::Lights,
        "40 lights of 64 bytes need 2560 bytes; the buffer has 1920",
    );
    culler
        .set_light_layout(LightLayout::default())
        .expect("layout");
    // Viewport: empty, larger than the depth texture.
    expect(
        &mut culler,
        &CullInputs {
            viewport: [0, H],
            ..caller.inputs()
        },
        CullInput::Viewport,
        "no pixels",
    );
    expect(
        &mut culler,
        &CullInputs {
            viewport: [W + 1, H],
            ..caller.inputs()
        },
        CullInput::Viewport,
        "larger than the depth texture",
    );
    // Matrices: NaN, a scaled view, an orthographic or off-centre projection.
    let mut nan_view = good.view;
    nan_view[3][0] = f32::NAN;
    expect(
        &mut culler,
        &CullInputs {
            view: nan_view,
            ..caller.inputs()
        },
        CullInput::View,
        "not finite",
    );
    let mut nan_proj = good.proj;
    nan_proj[0][0] = f32::NAN;
    expect(
        &mut culler,
        &CullInputs {
            proj: nan_proj,
            ..caller.inputs()
        },
        CullInput::Projection,
        "not finite",
    );
    let scaled = (Mat4::from_scale(Vec3::splat(2.0)) * caller.cam.view).to_cols_array_2d();
    expect(
        &mut culler,
        &CullInputs {
            view: scaled,
            ..caller.inputs()
        },
        CullInput::View,
        "rotation and a translation",
    );
    let ortho = Mat4::from_cols(
        glam::Vec4::X,
        glam::Vec4::Y,
        glam::Vec4::new(0.0, 0.0, -0.01, 0.0),
        glam::Vec4::new(0.0, 0.0, 0.0, 1.0),
    )
    .to_cols_array_2d();
    expect(
        &mut culler,
        &CullInputs {
            proj: ortho,
            ..caller.inputs()
        },
        CullInput::Projection,
        "perspective",
    );
    // Off-centre is accepted (`jittered_and_off_centre_projections_...`); a skew, a constant
    // shift and a depth that varies across the image are not a camera's.
    for (col, row, why) in [
        (1, 0, "skewed"),
        (3, 1, "shifts"),
        (0, 2, "varies with x or y"),
    ] {
        let mut odd = good.proj;
        odd[col][row] = 0.01;
        expect(
            &mut culler,
            &CullInputs {
                proj: odd,
                ..caller.inputs()
            },
            CullInput::Projection,
            why,
        );
    }
    // Planes: near ≥ far, NaN, and planes the projection does not have.
    expect(
        &mut culler,
        &CullInputs {
            near: FAR,
            far: NEAR,
            ..caller.inputs()
        },
        CullInput::Planes,
        "0 < near < far",
    );
    expect(
        &mut culler,
        &CullInputs {
            near: f32::NAN,
            ..caller.inputs()
        },
        CullInput::Planes,
        "0 < near < far",
    );
    expect(
        &mut culler,
        &CullInputs {
            near: 0.5,
            ..caller.inputs()
        },
        CullInput::Planes,
        "not the projection's near plane",
    );
    expect(
        &mut culler,
        &CullInputs {
            far: 50.0,
            ..caller.inputs()
        },
        CullInput::Planes,
        "not the projection's far plane",
    );
    // Configurations: tile sizes, slices, sample counts and capacities out of range.
    for config in [
        CullConfig {
            tile_size: 0,
            ..CullConfig::default()
        },
        CullConfig {
            tile_size: 1 << 20,
            ..CullConfig::default()
        },
        CullConfig {
            slices: 0,
            ..CullConfig::default()
        },
        CullConfig {
            slices: 100_000,
            ..CullConfig::default()
        },
        CullConfig {
            samples: 3,
            ..CullConfig::default()
        },
        CullConfig {
            max_lights: 0,
            ..CullConfig::default()
        },
        CullConfig {
            max_lights: u32::MAX,
            ..CullConfig::default()
        },
        CullConfig {
            index_capacity: 0,
            ..CullConfig::default()
        },
        CullConfig {
            depth_mask: DepthMask::On,
            depth_bounds: DepthBounds::Min,
            ..CullConfig::default()
        },
        CullConfig {
            cell_box: CellBox::On,
            depth_bounds: DepthBounds::None,
            ..CullConfig::default()
        },
    ] {
        let e = LightCuller::new(&device, &queue, config)
            .err()
            .unwrap_or_else(|| panic!("{config:?} accepted"));
        assert_eq!(e.input, CullInput::Config, "{e}");
    }
    // The strategies that assign on the CPU need the lights there too: one per light, each
    // finite with a positive range.
    for row in lightgrid::testing::STRATEGIES
        .iter()
        .filter(|s| s.cpu_lights)
    {
        let config = CullConfig {
            strategy: row.assign,
            max_lights: 40,
            ..CullConfig::default()
        };
        let mut culler = LightCuller::new(&device, &queue, config).expect("a cpu strategy");
        let e = refused(&mut culler, &device, &caller.inputs());
        assert_eq!(e.input, CullInput::Lights, "{e}");
        assert!(e.message.contains("cpu_lights"), "{e}");
        let e = refused(
            &mut culler,
            &device,
            &CullInputs {
                cpu_lights: Some(&caller.cpu_lights[..39]),
                ..caller.inputs()
            },
        );
        assert_eq!(e.input, CullInput::Lights, "{e}");
        assert!(e.message.contains("39"), "{e}");
        let mut nan = caller.cpu_lights.clone();
        nan[3].position[0] = f32::NAN;
        let e = refused(
            &mut culler,
            &device,
            &CullInputs {
                cpu_lights: Some(&nan),
                ..caller.inputs()
            },
        );
        assert_eq!(e.input, CullInput::Lights, "{e}");
        assert!(e.message.contains("cpu_lights[3]"), "{e}");
    }
    // After all that, the good inputs still cull, with lights and without, every strategy.
    for strategy in strategies() {
        let mut culler = LightCuller::new(
            &device,
            &queue,
            CullConfig {
                strategy,
                max_lights: 40,
                ..CullConfig::default()
            },
        )
        .expect("culler");
        // With its 40 lights, through the caller's own depth pre-pass and oracle.
        let (r, report) = caller.frame(&mut culler);
        assert!(
            report.is_complete() && report.index_entries > 0,
            "{strategy:?}: {report:?}"
        );
        assert_eq!(r[0], 0, "{strategy:?}: misses");
        // No lights: an empty grid, reported complete.
        let mut encoder = device.create_command_encoder(&Default::default());
        let inputs = CullInputs {
            light_count: 0,
            cpu_lights: Some(&[]),
            ..caller.inputs()
        };
        let frame = culler.encode(&mut encoder, &inputs).expect("no lights");
        queue.submit([encoder.finish()]);
        let reports = culler.wait().expect("reports");
        let report = reports
            .iter()
            .find(|r| r.frame == frame)
            .expect("its report");
        assert!(
            report.is_complete(),
            "{strategy:?} without lights: {report:?}"
        );
        assert_eq!(
            report.index_entries, 0,
            "{strategy:?} without lights: {report:?}"
        );
    }
}

/// The culler asks for WebGPU's default limits and every strategy runs within them (every
/// test here culls on such a device); the budget is tight: with one storage buffer fewer
/// per stage the strategies binding 8 (the BVH walks, scatter's emit kernel) are refused with
/// an error naming the limit, and those binding fewer still run. A binding added past 8
/// fails the first half.
#[test]
fn every_strategy_fits_webgpu_default_limits_and_the_ones_at_eight_name_the_limit() {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&Default::default()))
        .expect("an adapter (CI installs mesa-vulkan-drivers)");
    assert_eq!(
        LightCuller::required_limits(&adapter),
        wgpu::Limits::default(),
        "the culler asks for no more than WebGPU's defaults"
    );
    for storage in [None, Some(7)] {
        let cam = camera(Vec3::new(3.0, 2.0, 10.0), false);
        let lights = lights(&cam, 200, 61);
        let (device, queue, _) = device_limited(false, storage);
        let caller = Caller::new(&device, &queue, 1, cam, &lights);
        for strategy in strategies().into_iter().filter(|&a| a != Assign::Auto) {
            let what = format!("{strategy:?} with {storage:?} storage buffers per stage");
            let config = CullConfig {
                strategy,
                index_capacity: 1 << 17,
                ..CullConfig::default()
            };
            let culled = LightCuller::new(&device, &queue, config).and_then(|mut culler| {
                let mut encoder = device.create_command_encoder(&Default::default());
                caller.depth_prepass(&mut encoder);
                let inputs = CullInputs {
                    cpu_lights: Some(&caller.cpu_lights),
                    ..caller.inputs()
                };
                culler.encode(&mut encoder, &inputs)?;
                queue.submit([encoder.finish()]);
                culler.wait()
            });
            let at_eight = matches!(strategy, Assign::Bvh | Assign::BvhGpu | Assign::Scatter);
            match (storage, culled) {
                (Some(_), Err(e)) if at_eight => assert!(
                    e.to_string()
                        .contains("max_storage_buffers_per_shader_stage"),
                    "{what}: the refusal names the limit: {e}"
                ),
                (Some(_), Ok(_)) if at_eight => panic!("{what}: binds 8, yet ran on 7"),
                (_, Ok(reports)) => {
                    assert!(
                        reports.iter().all(|r| r.is_complete()),
                        "{what}: {reports:?}"
                    )
                }
                (_, Err(e)) => panic!("{what}: {e}"),
            }
        }
    }
}
