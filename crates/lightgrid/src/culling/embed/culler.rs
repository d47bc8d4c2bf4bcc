//! [`LightCuller`]: lightgrid's light grid for any wgpu renderer (tiled-shading §6.2: the grid
//! is three arrays any shading pass can read; forward-plus §3: culling is a compute stage
//! between the caller's depth pre-pass and the caller's shading).
//!
//! The caller keeps its device, queue, encoder, depth buffer, lights and shaders. Per frame
//! [`LightCuller::encode`] records into the caller's encoder, after its depth pre-pass:
//! 1. `cull_lights.wgsl`: the caller's lights ([`CullLight`], world space) into a
//!    camera-relative copy and their bounding spheres;
//! 2. the same stages lightgrid's own renderer runs ([`GridBuilder`]): for clusters the
//!    depth range their slices are spread over, the cell bounds, the strategy;
//! 3. a copy of the culler's counters into a staging slot mapped when the caller submits.
//!
//! The caller's shading pass binds [`LightCuller::bind_group`] and includes
//! [`LightCuller::wgsl`], which answers "which cell is this sample in", "how many lights",
//! "the i-th light's index"; the light loop and the BRDF are the caller's. No submission, no
//! wait: overflow, truncated shader loops and refused lights come back a frame or two later
//! from [`LightCuller::poll`], and the lists grow from them.

use crate::consts::POINT_LIGHT_COS;
use crate::culling::builder::GridBuilder;
use crate::culling::frame::{bind_cull_group, cull_layout, CullFrame};
use crate::culling::grid::GridDims;
use crate::culling::strategies::registry::find_strategy;
use crate::frame::{CullConfig, FrameEncoder, SpotCull};
use crate::gpu::{
    buffer_entry, groups_1d, grow_storage, storage_buffer, FrameCounters, FrameTag, PassTimer,
    STORAGE_READ, STORAGE_RW, UNIFORM,
};
use crate::gpu_types::{FrameUniforms, GpuLight};
use crate::scene::{Light, Spot, ViewSetup};
use crate::shader::{compose, compute_pipeline, src, ComposedShader, Def, ShaderKey};
use glam::{DMat3, DVec3, Mat4, Vec3};

/// One light as [`LightCuller`] reads it from the caller's buffer: 48 bytes, `#[repr(C)]`,
/// the layout of a WGSL `struct { position: vec3<f32>, range: f32, payload: vec4<f32>,
/// direction: vec3<f32>, cos_outer: f32 }` in a `storage` array.
///
/// - `position` (world space) and `range` (> 0): the light reaches nothing farther.
/// - `payload`: the caller's (colour, intensity, ...); the culler never reads it.
/// - `direction` (unit) and `cos_outer` (−1..=1): a spot light's axis and the cosine of its
///   outer half-angle; a point light has `cos_outer` = [`CullLight::POINT`] (−2) and any
///   direction.
///
/// A light that is not finite or has no positive range is culled from every cell and counted
/// in [`CullReport::invalid_lights`].
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CullLight {
    /// World position.
    pub position: [f32; 3],
    /// Greater than zero: the light reaches nothing farther.
    pub range: f32,
    /// The caller's: never read by the culler.
    pub payload: [f32; 4],
    /// A spot's unit axis (ignored for a point light).
    pub direction: [f32; 3],
    /// A spot's outer half-angle cosine (−1..=1), or [`CullLight::POINT`].
    pub cos_outer: f32,
}

const _: () = assert!(std::mem::size_of::<CullLight>() == std::mem::size_of::<GpuLight>());

impl CullLight {
    /// `cos_outer` of a point light.
    pub const POINT: f32 = POINT_LIGHT_COS;

    /// A point light at `position` reaching `range`, with the caller's `payload`.
    pub fn point(position: [f32; 3], range: f32, payload: [f32; 4]) -> Self {
        CullLight {
            position,
            range,
            payload,
            direction: [0.0, 0.0, 0.0],
            cos_outer: Self::POINT,
        }
    }

    /// The light as the CPU strategies read it (a spot's inner cone just inside its outer).
    fn into_light(self) -> Light {
        let spot = (self.cos_outer >= -1.0).then(|| Spot {
            direction: Vec3::from(self.direction),
            cos_inner: (self.cos_outer + crate::scene::SPOT_MIN_FALLOFF).min(1.0),
            cos_outer: self.cos_outer,
        });
        Light {
            position: Vec3::from(self.position),
            color: Vec3::ZERO,
            intensity: 0.0,
            range: self.range,
            spot,
        }
    }

    /// A spot light: unit `direction`, outer half-angle cosine `cos_outer`.
    pub fn spot(
        position: [f32; 3],
        range: f32,
        direction: [f32; 3],
        cos_outer: f32,
        payload: [f32; 4],
    ) -> Self {
        CullLight {
            position,
            range,
            payload,
            direction,
            cos_outer,
        }
    }
}

/// Where the culler finds each light's fields in the caller's own light buffer
/// ([`LightCuller::set_light_layout`]): the culler reads the buffer in place, whatever the
/// caller's struct is. Byte offsets within a light, each a multiple of 4; f32 values.
///
/// - `position`: three f32s, world space; `range`: one f32 (> 0, the light reaches nothing
///   farther);
/// - `direction` (three f32s, a unit axis) and `cos_outer` (one f32, the cosine of the outer
///   half-angle, −1..=1; exactly −2, [`CullLight::POINT`], for a point light): both, for a
///   buffer with spot lights, or neither (every light a point light).
///
/// Everything else in a light (colour, intensity, type, shadows) is the caller's and never
/// read. The default is [`CullLight`]'s layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightLayout {
    /// Bytes from one light to the next (a multiple of 4, 4..=4096).
    pub stride: u32,
    /// Byte offset of the position (three f32s).
    pub position: u32,
    /// Byte offset of the range (one f32).
    pub range: u32,
    /// Byte offset of a spot's unit axis (three f32s), with `cos_outer`; `None`: no spots.
    pub direction: Option<u32>,
    /// Byte offset of a spot's outer half-angle cosine (one f32), with `direction`.
    pub cos_outer: Option<u32>,
}

impl LightLayout {
    /// [`CullLight`]'s layout: 48 bytes, position at 0, range 12, direction 32, cosine 44.
    pub const CULL_LIGHT: LightLayout = LightLayout {
        stride: std::mem::size_of::<CullLight>() as u32,
        position: std::mem::offset_of!(CullLight, position) as u32,
        range: std::mem::offset_of!(CullLight, range) as u32,
        direction: Some(std::mem::offset_of!(CullLight, direction) as u32),
        cos_outer: Some(std::mem::offset_of!(CullLight, cos_outer) as u32),
    };

    /// The layout as the light-preparing kernel reads it (in 4-byte words), after `check`.
    fn words(&self) -> [u32; 8] {
        let spot = self.direction.zip(self.cos_outer);
        [
            self.stride / 4,
            self.position / 4,
            self.range / 4,
            spot.map_or(0, |(d, _)| d / 4),
            spot.map_or(0, |(_, c)| c / 4),
            u32::from(spot.is_some()),
            0,
            0,
        ]
    }

    /// Refuse a layout whose fields are unaligned, outside the stride or overlapping.
    fn check(&self) -> Result<(), CullError> {
        let bad = |m: String| refuse(CullInput::Lights, format!("light layout: {m}"));
        if self.stride % 4 != 0 || !(4..=4096).contains(&self.stride) {
            return bad(format!(
                "stride {} must be a multiple of 4 between 4 and 4096",
                self.stride
            ));
        }
        let mut fields = vec![("position", self.position, 12), ("range", self.range, 4)];
        match (self.direction, self.cos_outer) {
            (Some(d), Some(c)) => {
                fields.push(("direction", d, 12));
                fields.push(("cos_outer", c, 4));
            }
            (None, None) => {}
            _ => return bad("direction and cos_outer come together (spots) or not at all".into()),
        }
        for &(name, at, len) in &fields {
            if at % 4 != 0 {
                return bad(format!("{name} at byte {at} is not a multiple of 4"));
            }
            if u64::from(at) + len > u64::from(self.stride) {
                return bad(format!(
                    "{name} (bytes {at}..{}) does not fit the stride {}",
                    u64::from(at) + len,
                    self.stride
                ));
            }
        }
        for (i, &(a, at_a, len_a)) in fields.iter().enumerate() {
            for &(b, at_b, len_b) in &fields[i + 1..] {
                let (a0, b0) = (u64::from(at_a), u64::from(at_b));
                if a0 < b0 + len_b && b0 < a0 + len_a {
                    return bad(format!("{a} and {b} overlap"));
                }
            }
        }
        Ok(())
    }
}

impl Default for LightLayout {
    fn default() -> Self {
        Self::CULL_LIGHT
    }
}

/// One frame's inputs to [`LightCuller::encode`].
#[derive(Clone, Copy)]
pub struct CullInputs<'a> {
    /// The caller's depth buffer after its depth pre-pass, recorded earlier in the same
    /// encoder (a view of a 2D depth texture with `TEXTURE_BINDING` usage and
    /// [`CullConfig::samples`] samples; its depth aspect is read): each cell is bounded by the
    /// samples in it. `None` for a renderer without a depth pre-pass: every cell spans its
    /// whole slice of `near..far` (froxels: the slices follow the exponential spacing of
    /// `light_grid_slice` over `near..far`, [`CullConfig::slices`] of them; one slice is
    /// tiles spanning the whole range), so any surface at any depth, opaque or transparent,
    /// finds its lights with `light_grid_cell`.
    pub depth: Option<&'a wgpu::TextureView>,
    /// With `depth`: the frame has transparent surfaces in front of it, so lists are also
    /// built for them as [`CullConfig::lists`] says (`Separate`: a second layer of cells over
    /// `near` to the tile's farthest sample, read with `light_grid_cell_transparent`;
    /// `Shared`: the opaque cells widened to `near`). Without depth every cell already covers
    /// them. `false`: lists cover the depth buffer's samples only.
    pub transparent: bool,
    /// The caller's lights from byte 0, with `STORAGE` usage: [`CullLight`]s, or the
    /// caller's own struct as [`LightCuller::set_light_layout`] describes it.
    pub lights: &'a wgpu::Buffer,
    /// The same lights on the CPU as [`CullLight`]s (whatever the buffer's layout), for the
    /// strategies that assign there (tiled-shading §6.1:
    /// `cpu`, and `bvh`, which builds its hierarchy there); the others ignore it. `cpu` reads
    /// the cells' depth bounds back part-way through the frame: what the encoder holds so far
    /// (the depth pre-pass) is submitted, and the caller's encoder is replaced by a new one,
    /// into which the rest of the frame records.
    pub cpu_lights: Option<&'a [CullLight]>,
    /// Lights in the buffer this frame (at most [`CullConfig::max_lights`]).
    pub light_count: u32,
    /// World to view space (right-handed, the camera looking down −z): a rotation and a
    /// translation, column-major (`glam::Mat4::to_cols_array_2d`).
    pub view: [[f32; 4]; 4],
    /// View to clip space: a perspective projection with depth 0..1, standard (0 at `near`,
    /// cleared to 1) or reversed (1 at `near`, cleared to 0; infinite allowed). It may be
    /// off-centre (`proj[2][0]`, `proj[2][1]` not 0: TAA jitter changing every frame, a VR
    /// eye, an off-axis display): the cells follow its actual frustum. An orthographic
    /// projection is refused (its cells would be boxes, not frusta).
    pub proj: [[f32; 4]; 4],
    /// The projection's near plane (a view distance).
    pub near: f32,
    /// The projection's far plane; for an infinite projection, where the slices end.
    pub far: f32,
    /// Pixels of the depth buffer the grid covers, from its top-left corner.
    pub viewport: [u32; 2],
}

/// Which input a [`CullError`] is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CullInput {
    /// [`CullConfig`].
    Config,
    /// [`CullInputs::depth`]: format, dimension, sample count, usage; or asked to cover
    /// transparent surfaces without it.
    Depth,
    /// [`CullInputs::lights`]: size, usage; [`LightLayout`]: alignment, fit, overlap;
    /// [`CullInputs::cpu_lights`].
    Lights,
    /// [`CullInputs::light_count`] beyond [`CullConfig::max_lights`].
    LightCount,
    /// [`CullInputs::viewport`] (or [`LightCuller::reserve`]'s): empty, larger than the depth
    /// texture or than any texture the device makes, or more cells than it binds.
    Viewport,
    /// [`CullInputs::view`]: not finite, or not a rotation and a translation.
    View,
    /// [`CullInputs::proj`]: not finite, not a perspective projection (orthographic, skewed).
    Projection,
    /// [`CullInputs::near`] / [`CullInputs::far`]: not 0 < near < far, or not the
    /// projection's.
    Planes,
    /// The device could not do what the frame needs (a list too large to bind).
    Device,
}

/// A refused configuration or frame: the input, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct CullError {
    /// The input at fault.
    pub input: CullInput,
    /// Why, with the values involved.
    pub message: String,
}

impl std::fmt::Display for CullError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?}: {}", self.input, self.message)
    }
}

impl std::error::Error for CullError {}

fn refuse<T>(input: CullInput, message: impl Into<String>) -> Result<T, CullError> {
    Err(CullError {
        input,
        message: message.into(),
    })
}

impl From<crate::error::Error> for CullError {
    /// A grid the description cannot build (too many cells for the device) is the
    /// configuration's fault, named by its setting; the rest is the device's.
    fn from(e: crate::error::Error) -> Self {
        match e {
            crate::error::Error::Invalid { what, reason } => CullError {
                input: CullInput::Config,
                message: format!("{what}: {reason}"),
            },
            e => CullError {
                input: CullInput::Device,
                message: e.to_string(),
            },
        }
    }
}

/// What the GPU said about one encoded frame (from [`LightCuller::poll`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CullReport {
    /// The number [`LightCuller::encode`] returned for the frame.
    pub frame: u64,
    /// Index entries the frame's lists needed.
    pub index_entries: u32,
    /// Some list did not fit: the frame's grid lacks lights. The lists have grown since.
    pub overflowed: bool,
    /// Kernel loops the shader compiler cut short: the frame's grid is wrong.
    pub truncated_loops: u32,
    /// Lights refused (not finite, range not positive): in no cell.
    pub invalid_lights: u32,
    /// The strategy that built the frame's grid (`auto` resolved).
    pub assign: crate::frame::Assign,
    /// CPU time of the assignment itself in milliseconds: the `cpu` strategy's, or `bvh`'s
    /// hierarchy build; 0 for the GPU strategies.
    pub cpu_ms: f64,
}

/// What a renderer may add to a frame's culling besides its [`CullInputs`]
/// ([`LightCuller::encode_with`]); lightgrid's own renderer passes all three.
#[derive(Default)]
pub struct CullExtras<'a> {
    /// Time every culling pass with this timer's timestamp queries (two slots per pass; the
    /// labels start with `assign:`), in the caller's frame: the frame's
    /// submissions and spans are the caller's.
    pub timer: Option<&'a mut crate::gpu::PassTimer>,
    /// Add what the culling cost the CPU side to the caller's frame: the `cpu` strategy's
    /// part-way submission, the bytes it waited to read back, and the wait.
    pub io: Option<&'a mut crate::frame::FrameIo>,
    /// Forward shading with MSAA ([`CullConfig::samples`] above 1, a depth given): a fragment
    /// covering part of a pixel is shaded at the pixel centre, whose depth may lie outside
    /// every sample of its cell. The culler begins a render pass over the depth (loaded, not
    /// written) and calls this with it and the group of [`LightCuller::fragment_bounds_wgsl`]
    /// (layout [`LightCuller::fragment_bounds_layout`]); the caller draws the fragments it
    /// will shade from the grid, with its shading passes' depth tests, each calling
    /// `light_grid_bound_fragment`. The cells' bounds then hold every such fragment.
    #[allow(clippy::type_complexity)]
    pub fragments: Option<&'a dyn Fn(&mut wgpu::RenderPass<'_>, &wgpu::BindGroup)>,
}

impl CullReport {
    /// Every light reached every cell it should: no overflow, no truncated loop, no refused
    /// light.
    pub fn is_complete(&self) -> bool {
        !self.overflowed && self.truncated_loops == 0 && self.invalid_lights == 0
    }
}

/// The caller-facing WGSL's own part: the grid's bindings (at group `LIGHT_GRID_GROUP`) and
/// the accessors. The cell addressing and z-bin walk are lightgrid's own parts, whose names
/// already carry the `light_grid` prefix, so nothing collides with the caller's names.
const EMBED_WGSL: &str = include_str!("embed.wgsl");

/// The import path of [`LightCuller::naga_oil_module`].
const NAGA_OIL_IMPORT_PATH: &str = "lightgrid::grid";

/// The caller's WGSL at bind group `group` ([`LightCuller::wgsl`]): a shader key like every
/// other, composed without the constants prelude (it declares only `light_grid` names).
#[derive(Clone, Copy, Debug)]
pub(crate) struct CallerGridKey {
    pub group: u32,
}

impl ShaderKey for CallerGridKey {
    const STAGE: &'static str = "light grid (caller)";
    const PRELUDE: bool = false;

    /// Every group a default wgpu device has.
    fn all() -> Vec<Self> {
        (0..wgpu::Limits::default().max_bind_groups)
            .map(|group| CallerGridKey { group })
            .collect()
    }

    fn defs(self) -> Vec<Def> {
        vec![
            Def::U32("LIGHT_GRID_GROUP", self.group),
            Def::U32(
                "LIGHT_GRID_LISTS_SEPARATE",
                crate::consts::GRID_LISTS_SEPARATE,
            ),
        ]
    }

    fn parts(self) -> Vec<&'static str> {
        vec![src::GRID_PARAMS, EMBED_WGSL, src::GRID_CELL, src::ZBIN_WALK]
    }
}

/// The part of [`LightCuller::fragment_bounds_wgsl`] after the grid's parameters.
const FRAGMENTS_WGSL: &str = include_str!("fragments.wgsl");

/// The MSAA fragment-bounds WGSL at bind group `group` ([`LightCuller::fragment_bounds_wgsl`]):
/// like [`CallerGridKey`], only `light_grid` names.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CallerFragmentsKey {
    pub group: u32,
}

impl ShaderKey for CallerFragmentsKey {
    const STAGE: &'static str = "light grid fragment bounds (caller)";
    const PRELUDE: bool = false;

    fn all() -> Vec<Self> {
        (0..wgpu::Limits::default().max_bind_groups)
            .map(|group| CallerFragmentsKey { group })
            .collect()
    }

    fn defs(self) -> Vec<Def> {
        let mut defs = CallerGridKey { group: self.group }.defs();
        defs.push(Def::Wgsl(
            "LIGHT_GRID_DEPTH_SLACK",
            "f32".into(),
            format!("{:?}", crate::consts::ASSIGN_DEPTH_SLACK),
        ));
        defs
    }

    fn parts(self) -> Vec<&'static str> {
        vec![src::GRID_PARAMS, FRAGMENTS_WGSL, src::GRID_CELL]
    }
}

/// Culls a caller's lights into lightgrid's light grid, in the caller's encoder.
///
/// ```no_run
/// # fn frame(device: &wgpu::Device, queue: &wgpu::Queue, depth: &wgpu::TextureView,
/// #          lights: &wgpu::Buffer, view: glam::Mat4, proj: glam::Mat4)
/// #          -> Result<(), lightgrid::CullError> {
/// use lightgrid::{CullConfig, CullInputs, LightCuller};
/// let mut culler = LightCuller::new(device, queue, CullConfig {
///     tile_size: 16,
///     slices: 24,
///     ..CullConfig::default()
/// })?;
/// // The caller's shader: `LightCuller::wgsl(1)` declares the grid at group 1.
/// let grid_wgsl = LightCuller::wgsl(1);
/// let mut encoder = device.create_command_encoder(&Default::default());
/// // ... the caller's depth pre-pass into `depth` ...
/// culler.encode(&mut encoder, &CullInputs {
///     depth: Some(depth),
///     transparent: false,
///     cpu_lights: None,
///     lights,
///     light_count: 300,
///     view: view.to_cols_array_2d(),
///     proj: proj.to_cols_array_2d(),
///     near: 0.1,
///     far: 100.0,
///     viewport: [1280, 720],
/// })?;
/// // ... the caller's shading pass with `culler.bind_group()` at group 1 ...
/// queue.submit([encoder.finish()]);
/// for report in culler.poll()? {
///     assert!(report.is_complete(), "frame {} lacks lights", report.frame);
/// }
/// # Ok(()) }
/// ```
pub struct LightCuller {
    /// The stages every grid is built by (lightgrid's renderer's and a caller's).
    core: GridBuilder,
    /// What the grid is.
    config: CullConfig,
    /// What turns the caller's inputs into the culling kernels' group 0, and its frames.
    caller: Caller,
}

/// Bytes of a `CullRecord` (`shading/types.wgsl`): sphere, position and range, direction
/// and outer cone.
const RECORD_BYTES: u64 = 48;

/// What a [`LightCuller`] keeps besides the grid's stages.
struct Caller {
    device: wgpu::Device,
    queue: wgpu::Queue,
    layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
    /// Per light of the caller's, its camera-relative `CullRecord` (`light_records.wgsl`).
    records: wgpu::Buffer,
    counters: FrameCounters,
    group: wgpu::BindGroup,
    prep: wgpu::ComputePipeline,
    prep_layout: wgpu::BindGroupLayout,
    /// [`software_adapter`]: `auto` assigns on the CPU when a frame brings `cpu_lights`.
    software_adapter: bool,
    /// The caller's light layout, and its words for the light-preparing kernel.
    light_layout: LightLayout,
    light_layout_buffer: wgpu::Buffer,
    frames: u64,
    /// The newest finished frame's number and counters ([`LightCuller::read_grid`]).
    last_report: Option<(u64, crate::gpu::CounterValues)>,
    /// Frames encoded and not reported yet: what their reports carry besides the counters.
    encoded: Vec<EncodedFrame>,
}

/// What a frame's report carries that its counters do not.
struct EncodedFrame {
    frame: u64,
    assign: crate::frame::Assign,
    cpu_ms: f64,
    /// Index entries of a grid the CPU built (the GPU counted none).
    cpu_entries: u32,
}

/// Refuse a configuration the culler cannot build on `device`, naming why.
fn check_config(device: &wgpu::Device, config: &CullConfig) -> Result<(), CullError> {
    let config_error = |e: crate::error::Error| CullError {
        input: CullInput::Config,
        message: e.to_string(),
    };
    config.validate().map_err(config_error)?;
    let max_bytes = u64::from(config.max_lights) * std::mem::size_of::<GpuLight>() as u64;
    let limits = device.limits();
    if max_bytes
        > limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size)
    {
        return refuse(
            CullInput::Config,
            format!(
                "max_lights {} needs {max_bytes} bytes of lights, more than this device binds",
                config.max_lights
            ),
        );
    }
    // A device binding fewer storage buffers per stage than WebGPU's default 8 (what the BVH
    // walks and scatter's emit kernel bind) runs the strategies that fit it; one that does not
    // fit is refused when it is created, with the device's (or the browser's) message naming
    // the limit and the count.
    Ok(())
}

impl Caller {
    /// The buffers and the light-preparing kernel of a caller's culler (group 0 of the
    /// culling kernels over its own copies of the caller's lights).
    fn new(device: &wgpu::Device, queue: &wgpu::Queue, layout: wgpu::BindGroupLayout) -> Caller {
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("culler uniforms"),
            size: std::mem::size_of::<FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let records = storage_buffer(device, "culler light records", RECORD_BYTES * 64);
        let counters = FrameCounters::new(device, 0, 0);
        let group = bind_cull_group(device, &layout, [&uniforms, counters.buffer(), &records]);
        let prep_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("cull lights"),
            entries: &[
                buffer_entry(0, UNIFORM),
                buffer_entry(1, STORAGE_READ),
                buffer_entry(2, STORAGE_RW),
                buffer_entry(3, STORAGE_RW),
                buffer_entry(4, UNIFORM),
            ],
        });
        let light_layout = LightLayout::CULL_LIGHT;
        let light_layout_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("culler light layout"),
            size: 32,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(
            &light_layout_buffer,
            0,
            bytemuck::cast_slice(&light_layout.words()),
        );
        let prep = compute_pipeline(
            device,
            "cull lights",
            &prep_shader(),
            "main",
            &[Some(&prep_layout)],
        );
        Caller {
            device: device.clone(),
            queue: queue.clone(),
            layout,
            uniforms,
            records,
            counters,
            group,
            prep,
            prep_layout,
            light_layout,
            light_layout_buffer,
            software_adapter: software_adapter(device),
            frames: 0,
            last_report: None,
            encoded: Vec::new(),
        }
    }

    /// Make room for `n` lights (a new group 0 when the buffers grow), write the frame's
    /// uniforms, and record the kernel that copies the caller's lights camera-relative with
    /// their bounding spheres.
    fn prepare_lights(
        &mut self,
        enc: &mut FrameEncoder,
        inputs: &CullInputs,
        uniforms: &FrameUniforms,
    ) {
        let n = inputs.light_count;
        if grow_storage(
            &self.device,
            &mut self.records,
            "culler light records",
            u64::from(n.max(1)) * RECORD_BYTES,
        ) {
            self.group = bind_cull_group(
                &self.device,
                &self.layout,
                [&self.uniforms, self.counters.buffer(), &self.records],
            );
        }
        self.queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(uniforms));
        let prep_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("cull lights"),
            layout: &self.prep_layout,
            entries: &[
                entry(0, &self.uniforms),
                entry(1, inputs.lights),
                entry(2, &self.records),
                entry(3, self.counters.buffer()),
                entry(4, &self.light_layout_buffer),
            ],
        });
        let (encoder, timer) = enc.parts();
        self.counters.clear(encoder);
        let mut pass = timer.begin_compute(encoder, crate::consts::pass_labels::CULL_LIGHTS);
        pass.set_pipeline(&self.prep);
        pass.set_bind_group(0, &prep_group, &[]);
        let (x, y) = groups_1d(n.div_ceil(crate::consts::ASSIGN_THREADS));
        pass.dispatch_workgroups(x, y, 1);
    }
}

pub(crate) fn prep_shader() -> ComposedShader {
    compose(
        "cull lights",
        &[src::TYPES, include_str!("cull_lights.wgsl")],
    )
}

/// The caller-facing module at every group a default wgpu device has, for the validation
/// test.
pub(crate) fn embed_shaders() -> Vec<ComposedShader> {
    let mut all = CallerGridKey::all_shaders();
    all.extend(CallerFragmentsKey::all_shaders());
    all
}

impl LightCuller {
    /// A culler on the caller's device and queue (clones of the handles). Refuses a
    /// configuration outside lightgrid's limits.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        config: CullConfig,
    ) -> Result<Self, CullError> {
        check_config(device, &config)?;
        let layout = cull_layout(device);
        let tiles =
            GridDims::new(config.tile_size, config.tile_size, config.tile_size).map_err(|e| {
                CullError {
                    input: CullInput::Config,
                    message: e.to_string(),
                }
            })?;
        let mut core = crate::gpu::scoped(device, "creating the light culler", || {
            // `Auto` picks `cpu` on a CPU adapter for frames that bring their lights on the
            // CPU (`CullFrame::lights_on_cpu`).
            GridBuilder::new(device, &layout, &config, tiles, software_adapter(device))
        })?;
        core.prepare(device)?;
        let caller = crate::gpu::scoped(device, "creating the light culler", || {
            Caller::new(device, queue, layout)
        })?;
        Ok(LightCuller {
            core,
            config,
            caller,
        })
    }

    /// The limits a device needs for the culler, for `wgpu::DeviceDescriptor::required_limits`:
    /// WebGPU's defaults, what every browser offers. Every strategy's kernels bind at most
    /// 8 storage buffers per stage in at most 3 groups, and a
    /// caller's shading pass adds the grid's group (3). The adapter is not consulted; a
    /// caller wanting index lists longer than the default 128 MiB binding raises
    /// `max_storage_buffer_binding_size` itself (the culler reads the device's limits).
    pub fn required_limits(_adapter: &wgpu::Adapter) -> wgpu::Limits {
        wgpu::Limits::default()
    }

    /// The caller's shading pass's WGSL for the grid at bind group `group`: the bindings, and
    ///
    /// - `light_grid_cell(pixel: vec2<f32>, view_distance: f32) -> u32`: the cell of the sample
    ///   at framebuffer position `pixel` (`@builtin(position).xy`) and view distance
    ///   `view_distance` (−z in view space);
    /// - `light_grid_cell_transparent(pixel: vec2<f32>, view_distance: f32) -> u32`: the cell
    ///   of a transparent surface's fragment (the second layer with `GridLists::Separate`
    ///   and [`CullInputs::transparent`]; otherwise the same as `light_grid_cell`);
    /// - `light_grid_walk(cell: u32) -> LightGridWalk` and
    ///   `light_grid_next(walk: ptr<function, LightGridWalk>) -> bool`: the cell's lights one
    ///   at a time (`walk.light`, the index in the caller's light buffer), whatever the
    ///   strategy built (lists, or `Assign::ZBin`'s bins and masks);
    /// - `light_grid_count(cell: u32) -> u32`: how many lights the cell has;
    /// - `light_grid_light(cell: u32, i: u32) -> u32`: the index, in the caller's light
    ///   buffer, of the cell's `i`-th light (a scan of the mask words on z-bins).
    ///
    /// Every name it declares starts with `light_grid` or `LightGrid`.
    pub fn wgsl(group: u32) -> String {
        CallerGridKey { group }.shader().source()
    }

    /// [`Self::wgsl`] as a [naga_oil](https://crates.io/crates/naga_oil) module named
    /// `lightgrid::grid` (the same text under a `#define_import_path` line), for a renderer
    /// that composes its shaders with naga_oil (Bevy's composer):
    ///
    /// ```text
    /// composer.add_composable_module(ComposableModuleDescriptor {
    ///     source: &LightCuller::naga_oil_module(1),
    ///     file_path: "lightgrid/grid.wgsl",
    ///     ..Default::default()
    /// })?;
    /// // in the caller's shader:
    /// #import lightgrid::grid::{light_grid_cell, light_grid_walk, light_grid_next}
    /// ```
    ///
    /// `tests/culler.rs` composes its oracle this way with naga_oil 0.23 and culls through it.
    pub fn naga_oil_module(group: u32) -> String {
        format!(
            "#define_import_path {NAGA_OIL_IMPORT_PATH}\n{}",
            Self::wgsl(group)
        )
    }

    /// MSAA forward shading ([`CullExtras::fragments`]): the WGSL of the group the culler
    /// hands the caller's fragment draws, at bind group `group`, declaring
    /// `light_grid_bound_fragment(pixel: vec2<f32>, view_distance: f32, transparent: bool)`:
    /// the fragment at framebuffer position `pixel` and view distance `view_distance` (within
    /// near..far) will look its cell up there (`transparent`: with
    /// `light_grid_cell_transparent`). Every name it declares starts with `light_grid` or
    /// `LightGrid`; it is not meant to share a module with [`Self::wgsl`] (both declare
    /// `light_grid`).
    pub fn fragment_bounds_wgsl(group: u32) -> String {
        CallerFragmentsKey { group }.shader().source()
    }

    /// The layout of the group [`CullExtras::fragments`] is handed (`None` unless
    /// [`CullConfig::samples`] is above 1), for the caller's fragment-bounds pipelines.
    pub fn fragment_bounds_layout(&self) -> Option<&wgpu::BindGroupLayout> {
        self.core.fragments_layout()
    }

    /// The layout of [`Self::bind_group`], for the caller's pipeline layout (visible to
    /// fragment and compute stages).
    pub fn bind_group_layout(&self) -> &wgpu::BindGroupLayout {
        self.core.layout()
    }

    /// The grid the frames build, for the caller's shading pass.
    ///
    /// **The rule:** the group stays the same object until [`Self::bind_group_generation`]
    /// changes, and that happens only inside [`Self::encode`], when a frame needs more room
    /// than the buffers have: longer lists (a finished frame's report said its lists
    /// overflowed, so `poll`/`wait` raised the capacity) or more cells (a larger viewport, more
    /// layers). `poll`, `wait` and `read_grid` never replace it. A caller that keeps the group
    /// in its own bind groups compares the generation after each `encode` and rebuilds only
    /// when it moved; one that wants it never to move calls [`Self::reserve`] and sets
    /// [`CullConfig::index_capacity`] to what its frames need.
    pub fn bind_group(&self) -> &wgpu::BindGroup {
        self.core.bind_group()
    }

    /// How many times [`Self::bind_group`] has been replaced (0 until a frame needs more room
    /// than the culler was made or reserved with); see the rule there.
    pub fn bind_group_generation(&self) -> u64 {
        self.core.generation()
    }

    /// Make room now for frames of up to `viewport` pixels (every cell of the configured
    /// slices, both layers with separate transparent lists) and
    /// [`CullConfig::index_capacity`] index entries (for z-binning: its sorted lights and
    /// every tile's mask words, `lights + tiles × ⌈lights / 32⌉`), so that such frames never
    /// replace [`Self::bind_group`]. It may replace it once, now: take the group after this.
    pub fn reserve(&mut self, viewport: [u32; 2]) -> Result<(), CullError> {
        let device = self.caller.device.clone();
        check_viewport(&device, viewport)?;
        let [w, h] = viewport;
        let tiles = GridDims::new(w, h, self.config.tile_size).map_err(|e| CullError {
            input: CullInput::Viewport,
            message: e.to_string(),
        })?;
        let cells = (tiles.tile_count() as u64)
            .saturating_mul(u64::from(self.config.slices) * u64::from(self.config.lists.layers()));
        let max_bytes = crate::culling::frame::max_index_entries(&device) * 4;
        if cells.saturating_mul(8) > max_bytes {
            return refuse(
                CullInput::Viewport,
                format!(
                    "{w}x{h} makes {cells} cells, more than the {} this device binds; use a larger tile size or fewer slices",
                    max_bytes / 8
                ),
            );
        }
        self.core.reserve(&device, cells as usize)?;
        Ok(())
    }

    /// The description of the grid the culler builds.
    pub fn config(&self) -> &CullConfig {
        &self.config
    }

    /// Read the caller's lights in its own struct from now on ([`LightLayout`]; the default
    /// is [`CullLight`]'s): [`CullInputs::lights`] is then the caller's buffer as it is, of
    /// `light_count × stride` bytes or more. Refuses, naming the field, a layout whose fields
    /// are unaligned, overlap or do not fit the stride. It is written through the queue, so it
    /// holds for every frame submitted after the call (set it between frames).
    pub fn set_light_layout(&mut self, layout: LightLayout) -> Result<(), CullError> {
        layout.check()?;
        let c = &mut self.caller;
        c.light_layout = layout;
        c.queue.write_buffer(
            &c.light_layout_buffer,
            0,
            bytemuck::cast_slice(&layout.words()),
        );
        Ok(())
    }

    /// The layout the culler reads the caller's lights with.
    pub fn light_layout(&self) -> LightLayout {
        self.caller.light_layout
    }

    /// Record one frame's culling into `encoder` after the caller's depth pre-pass. The
    /// caller submits the encoder (one `encode` per submission). Returns the frame's number,
    /// which its [`CullReport`] carries.
    pub fn encode(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &CullInputs,
    ) -> Result<u64, CullError> {
        self.encode_with(encoder, inputs, CullExtras::default())
    }

    /// [`Self::encode`] with what a renderer may add ([`CullExtras`]): its pass timer, its
    /// frame's CPU-side costs, and with MSAA forward shading the draws of its fragments.
    pub fn encode_with(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &CullInputs,
        extras: CullExtras,
    ) -> Result<u64, CullError> {
        let core = &mut self.core;
        let c = &mut self.caller;
        let camera = c.check(inputs, &self.config)?;
        let (width, height) = (inputs.viewport[0], inputs.viewport[1]);
        let tile_size = self.config.tile_size;
        core.set_tiles(
            GridDims::new(width, height, tile_size).map_err(|e| CullError {
                input: CullInput::Viewport,
                message: e.to_string(),
            })?,
        );
        let n = inputs.light_count;
        let depth_view = inputs.depth.map(|depth| {
            depth.texture().create_view(&wgpu::TextureViewDescriptor {
                label: Some("culler depth"),
                aspect: wgpu::TextureAspect::DepthOnly,
                base_mip_level: 0,
                mip_level_count: Some(1),
                ..Default::default()
            })
        });
        // Only a frame that assigns on the CPU reads them (the others ignore them).
        let on_cpu = c.uses_cpu_lights(inputs, &self.config);
        let cpu_lights: Vec<Light> = match on_cpu {
            true => inputs
                .cpu_lights
                .unwrap_or_default()
                .iter()
                .map(|l| l.into_light())
                .collect(),
            false => Vec::new(),
        };
        c.frames += 1;
        let frame = c.frames;
        let setup = camera.setup(inputs, self.config.spot_cull);
        let uniforms = camera.uniforms(inputs, self.config.spot_cull);
        let (device, queue) = (c.device.clone(), c.queue.clone());
        let mut own_timer = PassTimer::disabled();
        let timer = match extras.timer {
            Some(t) => t,
            None => &mut own_timer,
        };
        let mut enc = FrameEncoder::borrowed(&device, &queue, encoder, timer);
        let result = crate::gpu::scoped(&device, "recording the light culler", || {
            c.prepare_lights(&mut enc, inputs, &uniforms);
            let f = CullFrame {
                device: &c.device,
                queue: &c.queue,
                bind_group: &c.group,
                counters: c.counters.buffer(),
                depth: depth_view.as_ref(),
                setup,
                light_count: n as usize,
                lights: &cpu_lights,
                lights_on_cpu: on_cpu,
                transparency: inputs.transparent,
                depth_attachment: inputs.depth,
                fragments: extras.fragments,
            };
            core.build(&f, &mut enc)
        });
        let io = enc.io();
        if let Some(total) = extras.io {
            total.add(io);
        }
        drop(enc);
        result??;
        let (assign, cpu_ms) = core.last_assign().expect("a frame was built");
        c.encoded.push(EncodedFrame {
            frame,
            assign,
            cpu_ms,
            cpu_entries: core.last_cpu_entries().unwrap_or(0),
        });
        let tag = FrameTag {
            serial: frame,
            pipeline: "LightCuller",
            pass_labels: Vec::new(),
        };
        c.counters
            .encode_copy(&c.device, encoder, &PassTimer::disabled(), tag);
        c.counters.map_on_submit(encoder);
        Ok(frame)
    }

    /// The number of the last frame [`Self::encode`] recorded (0 before the first).
    pub fn last_frame(&self) -> u64 {
        self.caller.frames
    }

    /// The last encoded frame's report, collected ([`Self::wait`], or `poll` until it came).
    fn last_values(&self) -> Result<crate::gpu::CounterValues, CullError> {
        let c = &self.caller;
        match c.last_report {
            Some((frame, values)) if frame == c.frames => Ok(values),
            _ => refuse(
                CullInput::Config,
                format!(
                    "frame {} has not been reported yet: call wait (or poll until it is) before reading it back",
                    c.frames
                ),
            ),
        }
    }

    /// The grid the last encoded frame built, read back (tests and tools; waits for the
    /// GPU): per cell its `(offset, count)` and the light indices, in the caller's light
    /// buffer's numbering (a z-binned grid as the per-cell lists it stands for). Its report
    /// must have been collected first ([`Self::wait`]). The offsets and the order of a cell's
    /// lights follow the order the GPU's workgroups finished in; the lists themselves do not.
    pub fn read_grid(&self) -> Result<crate::culling::grid::LightGrid, CullError> {
        let values = self.last_values()?;
        let c = &self.caller;
        Ok(self.core.download(&c.device, &c.queue, &values)?)
    }

    /// The view-distance bounds `[min, max]` of every cell of the last encoded frame's grid
    /// (min > max: no samples; without depth each cell's slice of near..far), as
    /// [`Self::read_grid`] reads the lists (tests and tools; waits for the GPU).
    pub fn read_cell_bounds(&self) -> Result<Vec<[f32; 2]>, CullError> {
        Ok(self.read_cells()?.cell_bounds)
    }

    /// Each cell's culling record beyond its bounds, as [`Self::read_cell_bounds`] reads
    /// them: its 2.5D depth mask and tight box ([`CullConfig::depth_mask`],
    /// [`CullConfig::cell_box`]; neither when both are off).
    pub fn read_cell_culls(
        &self,
    ) -> Result<Vec<crate::culling::bounds::cell_box::CellCull>, CullError> {
        Ok(self.read_cells()?.cell_culls)
    }

    fn read_cells(&self) -> Result<crate::culling::builder::BuiltCells, CullError> {
        self.last_values()?;
        let c = &self.caller;
        Ok(self.core.download_cells(&c.device, &c.queue)?)
    }

    /// The reports of the frames the GPU has finished since the last call, oldest first,
    /// without waiting (the caller's event loop polls the device, or this does). The lists
    /// grow from them.
    pub fn poll(&mut self) -> Result<Vec<CullReport>, CullError> {
        let c = &mut self.caller;
        let readbacks = c.counters.poll(&c.device)?;
        self.reports(readbacks)
    }

    /// [`Self::poll`] after waiting for every submitted frame (tests, tools).
    pub fn wait(&mut self) -> Result<Vec<CullReport>, CullError> {
        let c = &mut self.caller;
        let readbacks = c.counters.wait(&c.device)?;
        self.reports(readbacks)
    }

    fn reports(
        &mut self,
        readbacks: Vec<crate::gpu::FrameReadback>,
    ) -> Result<Vec<CullReport>, CullError> {
        let mut out = Vec::with_capacity(readbacks.len());
        for r in readbacks {
            self.core.observe(&self.caller.device, &r.values)?;
            let c = &mut self.caller;
            let write_overflow = r.values.write_overflow();
            if write_overflow > 0 {
                return refuse(
                    CullInput::Device,
                    format!(
                        "frame {}: {write_overflow} light indices did not fit the counted lists (count and write passes disagree)",
                        r.tag.serial
                    ),
                );
            }
            c.last_report = Some((r.tag.serial, r.values));
            let encoded = c
                .encoded
                .iter()
                .position(|e| e.frame == r.tag.serial)
                .map(|i| c.encoded.swap_remove(i));
            c.encoded.retain(|e| e.frame > r.tag.serial);
            let (assign, cpu_ms, cpu_entries) = encoded
                .map_or((self.config.strategy, 0.0, 0), |e| {
                    (e.assign, e.cpu_ms, e.cpu_entries)
                });
            out.push(CullReport {
                frame: r.tag.serial,
                index_entries: r
                    .values
                    .index_needed()
                    .max(r.values.pairs_needed())
                    .max(cpu_entries),
                overflowed: r.values.overflowed(),
                truncated_loops: r.values.truncated_loops(),
                invalid_lights: r.values.invalid_lights(),
                assign,
                cpu_ms,
            });
        }
        Ok(out)
    }
}

impl Caller {
    /// Refuse inputs the kernels cannot honour, each error naming its input.
    fn check(&self, i: &CullInputs, config: &CullConfig) -> Result<Camera, CullError> {
        use CullInput as I;
        check_viewport(&self.device, i.viewport)?;
        match i.depth {
            Some(depth) => Self::check_depth(depth.texture(), i, config)?,
            None if i.transparent => {
                return refuse(
                    I::Depth,
                    "transparent lists are built in front of a depth buffer; without one every cell already spans near..far",
                )
            }
            None => {}
        }
        self.check_lights(i, config)?;
        Camera::new(i)
    }

    /// The depth texture: a 2D depth format with the configured samples, readable, as large
    /// as the viewport.
    fn check_depth(
        texture: &wgpu::Texture,
        i: &CullInputs,
        config: &CullConfig,
    ) -> Result<(), CullError> {
        use CullInput as I;
        let format = texture.format();
        if !format.is_depth_stencil_format() || !format.has_depth_aspect() {
            return refuse(I::Depth, format!("{format:?} is not a depth format"));
        }
        if texture.dimension() != wgpu::TextureDimension::D2 || texture.depth_or_array_layers() != 1
        {
            return refuse(I::Depth, "the depth texture must be 2D with one layer");
        }
        if texture.sample_count() != config.samples {
            return refuse(
                I::Depth,
                format!(
                    "the depth texture has {} samples per pixel; the culler was configured for {}",
                    texture.sample_count(),
                    config.samples
                ),
            );
        }
        if !texture
            .usage()
            .contains(wgpu::TextureUsages::TEXTURE_BINDING)
        {
            return refuse(I::Depth, "the depth texture lacks TEXTURE_BINDING usage");
        }
        let [w, h] = i.viewport;
        if w > texture.width() || h > texture.height() {
            return refuse(
                I::Viewport,
                format!(
                    "{w}x{h} is larger than the depth texture ({}x{})",
                    texture.width(),
                    texture.height()
                ),
            );
        }
        Ok(())
    }

    /// The light buffer and count.
    fn check_lights(&self, i: &CullInputs, config: &CullConfig) -> Result<(), CullError> {
        use CullInput as I;
        if i.light_count > config.max_lights {
            return refuse(
                I::LightCount,
                format!(
                    "{} lights, more than the configured max_lights {}",
                    i.light_count, config.max_lights
                ),
            );
        }
        // A storage binding holds at least one element, even for a frame without lights.
        let stride = self.light_layout.stride;
        let needed = u64::from(i.light_count.max(1)) * u64::from(stride);
        if i.lights.size() < needed {
            return refuse(
                I::Lights,
                format!(
                    "{} lights of {stride} bytes need {needed} bytes; the buffer has {}",
                    i.light_count,
                    i.lights.size()
                ),
            );
        }
        if !i.lights.usage().contains(wgpu::BufferUsages::STORAGE) {
            return refuse(I::Lights, "the light buffer lacks STORAGE usage");
        }
        self.check_cpu_lights(i, config)
    }

    /// Does this frame assign on the CPU from [`CullInputs::cpu_lights`]: a strategy that
    /// always does, or `auto` on a CPU adapter given them (as lightgrid's renderer resolves
    /// it: `cpu` is the fastest there, README "Light assignment scaling")?
    fn uses_cpu_lights(&self, i: &CullInputs, config: &CullConfig) -> bool {
        needs_cpu_lights(config)
            || (config.strategy == crate::frame::Assign::Auto
                && self.software_adapter
                && i.cpu_lights.is_some())
    }

    /// The lights on the CPU, for a frame that assigns there: one per light, each finite
    /// with a positive range (the GPU counts such lights and leaves them out; the CPU
    /// strategies refuse them). Other frames ignore them.
    fn check_cpu_lights(&self, i: &CullInputs, config: &CullConfig) -> Result<(), CullError> {
        use CullInput as I;
        if !self.uses_cpu_lights(i, config) {
            return Ok(());
        }
        let Some(lights) = i.cpu_lights else {
            return refuse(
                I::Lights,
                format!(
                    "strategy {} assigns on the CPU: CullInputs::cpu_lights must hold the lights",
                    config.strategy.name()
                ),
            );
        };
        if lights.len() != i.light_count as usize {
            return refuse(
                I::Lights,
                format!(
                    "cpu_lights holds {} lights; light_count is {}",
                    lights.len(),
                    i.light_count
                ),
            );
        }
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
        if let Some(k) = lights.iter().position(|l| {
            !(finite(&l.position)
                && finite(&l.direction)
                && l.cos_outer.is_finite()
                && l.range > 0.0
                && l.range.is_finite())
        }) {
            return refuse(
                I::Lights,
                format!("cpu_lights[{k}] is not finite or has no positive range"),
            );
        }
        Ok(())
    }
}

/// A viewport of at least one pixel and at most the largest 2D texture the device makes.
fn check_viewport(device: &wgpu::Device, [w, h]: [u32; 2]) -> Result<(), CullError> {
    if w == 0 || h == 0 {
        return refuse(CullInput::Viewport, format!("{w}x{h} has no pixels"));
    }
    let max = device.limits().max_texture_dimension_2d;
    if w > max || h > max {
        return refuse(
            CullInput::Viewport,
            format!(
                "{w}x{h} is larger than this device's largest 2D texture ({max} pixels a side)"
            ),
        );
    }
    Ok(())
}

/// `auto`'s CPU rule ([`crate::gpu::auto_assigns_on_cpu`]) for the caller's device.
fn software_adapter(device: &wgpu::Device) -> bool {
    crate::gpu::auto_assigns_on_cpu(&device.adapter_info())
}

/// Does `config`'s strategy assign on the CPU (`CullInputs::cpu_lights`)?
fn needs_cpu_lights(config: &CullConfig) -> bool {
    find_strategy(config.strategy).is_some_and(|s| s.cpu_lights)
}

fn entry(binding: u32, b: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: b.as_entire_binding(),
    }
}

/// The camera a frame's matrices describe, checked.
struct Camera {
    rotation: Mat4,
    eye: glam::Vec3,
    standard_depth: bool,
}

impl Camera {
    fn new(i: &CullInputs) -> Result<Camera, CullError> {
        use CullInput as I;
        let finite = |m: &[[f32; 4]; 4]| m.iter().flatten().all(|x| x.is_finite());
        if !finite(&i.view) {
            return refuse(I::View, "the view matrix is not finite");
        }
        if !finite(&i.proj) {
            return refuse(I::Projection, "the projection is not finite");
        }
        // The view: a rotation and a translation (computed in f64, so a camera far from the
        // origin keeps its eye).
        let v = glam::DMat4::from_cols_array_2d(&i.view.map(|c| c.map(f64::from)));
        let r = DMat3::from_mat4(v);
        let rtr = r.transpose() * r;
        let off = (rtr - DMat3::IDENTITY)
            .to_cols_array()
            .iter()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        if off > 1e-3 || r.determinant() < 0.0 {
            return refuse(
                I::View,
                "the view matrix must be a rotation and a translation (no scale, shear or mirror)",
            );
        }
        if v.row(3) != glam::DVec4::new(0.0, 0.0, 0.0, 1.0) {
            return refuse(I::View, "the view matrix's last row must be (0, 0, 0, 1)");
        }
        let eye: DVec3 = -(r.transpose() * v.w_axis.truncate());
        let standard_depth = projection_depth(i)?;
        Ok(Camera {
            rotation: Mat4::from_mat3(r.as_mat3()),
            eye: eye.as_vec3(),
            standard_depth,
        })
    }

    fn uniforms(&self, i: &CullInputs, spot_cull: SpotCull) -> FrameUniforms {
        let proj = Mat4::from_cols_array_2d(&i.proj);
        FrameUniforms {
            view: self.rotation.to_cols_array_2d(),
            proj: i.proj,
            view_proj: (proj * self.rotation).to_cols_array_2d(),
            inv_view: self.rotation.transpose().to_cols_array_2d(),
            eye: self.eye.to_array(),
            light_count: i.light_count,
            viewport: [i.viewport[0] as f32, i.viewport[1] as f32],
            near: i.near,
            far: i.far,
            spot_cull: u32::from(spot_cull == SpotCull::Cone),
            standard_depth: u32::from(self.standard_depth),
            _pad1: 0,
            _pad2: 0,
        }
    }

    fn setup(&self, i: &CullInputs, spot_cull: SpotCull) -> ViewSetup {
        ViewSetup {
            view: self.rotation,
            eye: self.eye,
            p00: i.proj[0][0],
            p11: i.proj[1][1],
            p20: i.proj[2][0],
            p21: i.proj[2][1],
            near: i.near,
            far: i.far,
            width: i.viewport[0],
            height: i.viewport[1],
            spot_cull,
        }
    }
}

/// Check the projection against the planes: a perspective (maybe off-centre) with w = -z
/// whose near (and finite far) plane are `i.near` and `i.far`; true for standard depth (0 at
/// near), false for reversed.
fn projection_depth(i: &CullInputs) -> Result<bool, CullError> {
    use CullInput as I;
    // The projection: perspective, w = -z.
    let p = &i.proj;
    let zero = |x: f32| x == 0.0;
    let perspective = p[2][3] == -1.0
        && zero(p[3][3])
        && zero(p[0][3])
        && zero(p[1][3])
        && p[0][0] > 0.0
        && p[1][1] > 0.0;
    if !perspective {
        return refuse(
            I::Projection,
            "a perspective projection with w = -z (right-handed, looking down -z) is needed",
        );
    }
    // Off-centre (TAA jitter, a VR eye, an off-axis display: p[2][0], p[2][1]) is any
    // frustum the cells follow; a skew or a shift of the image that does not grow with depth
    // is no pinhole camera.
    if !(zero(p[1][0]) && zero(p[0][1]) && zero(p[3][0]) && zero(p[3][1])) {
        return refuse(
            I::Projection,
            "a skewed projection (proj[1][0], proj[0][1]) or one that shifts x or y by a constant (proj[3][0], proj[3][1]) is not a perspective camera's",
        );
    }
    if !(zero(p[0][2]) && zero(p[1][2])) {
        return refuse(
            I::Projection,
            "the projection's depth varies with x or y (proj[0][2], proj[1][2]): depth must depend on the view distance alone",
        );
    }
    let (near, far) = (i.near, i.far);
    // The renderer's own check of a camera's planes (finite, 0 < near < far, a ratio the
    // depth buffer holds).
    crate::depth::check_planes(near, far).map_err(|e| CullError {
        input: I::Planes,
        message: e.to_string(),
    })?;
    // depth = A / w - B (A = proj[3][2], B = proj[2][2]): reversed when A > 0.
    let (a, b) = (f64::from(p[3][2]), f64::from(p[2][2]));
    if a == 0.0 {
        return refuse(
            I::Projection,
            "the projection's depth does not vary with distance",
        );
    }
    let standard_depth = a < 0.0;
    let w_at = |d: f64| a / (d + b);
    let (near_depth, far_depth) = if standard_depth {
        (0.0, 1.0)
    } else {
        (1.0, 0.0)
    };
    let proj_near = w_at(near_depth);
    let agrees = |x: f64, y: f32| (x - f64::from(y)).abs() <= 1e-3 * f64::from(y);
    if !agrees(proj_near, near) {
        return refuse(
            I::Planes,
            format!("near {near} is not the projection's near plane ({proj_near})"),
        );
    }
    let proj_far = w_at(far_depth);
    if proj_far.is_finite() && proj_far > 0.0 && !agrees(proj_far, far) {
        return refuse(
            I::Planes,
            format!("far {far} is not the projection's far plane ({proj_far})"),
        );
    }
    if standard_depth && !(proj_far.is_finite() && proj_far > 0.0) {
        return refuse(
            I::Projection,
            "a standard-depth projection needs a finite far plane",
        );
    }
    Ok(standard_depth)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_modules_declare_only_prefixed_names() {
        for source in [LightCuller::wgsl(2), LightCuller::fragment_bounds_wgsl(2)] {
            declares_only_prefixed_names(&source);
        }
    }

    fn declares_only_prefixed_names(source: &str) {
        let module = naga::front::wgsl::parse_str(source).expect("parses");
        for (_, g) in module.global_variables.iter() {
            let name = g.name.as_deref().unwrap_or("");
            assert!(name.starts_with("light_grid"), "{name}");
            assert_eq!(g.binding.as_ref().map(|b| b.group), Some(2));
        }
        for (_, f) in module.functions.iter() {
            let name = f.name.as_deref().unwrap_or("");
            assert!(name.starts_with("light_grid"), "{name}");
        }
        for (_, t) in module.types.iter() {
            if let Some(name) = &t.name {
                assert!(name.starts_with("LightGrid"), "{name}");
            }
        }
        for (_, c) in module.constants.iter() {
            let name = c.name.as_deref().unwrap_or("");
            assert!(name.starts_with("LIGHT_GRID"), "{name}");
        }
        assert!(
            module.constants.iter().count() >= 2,
            "the group and the lists' value"
        );
    }
}
