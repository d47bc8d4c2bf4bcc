//! The renderer: owns the targets and scene buffers and renders frames of a scene with a
//! registry pipeline. The scene's static part (meshes, materials, textures, the geometry
//! that never moves) is given once ([`Renderer::set_scene`], an `Arc` the caller may share);
//! each frame is then a small description, a [`FrameState`] (camera, lights, object
//! transforms), rendered in three steps:
//! 1. **upload** (`upload`): lights and uniforms every frame, the moving objects every frame
//!    after the static geometry (uploaded by `set_scene`); the frame is validated here, once;
//! 2. **encode** (`encode_frame`): the pipeline's passes, the tonemap and the copy of the
//!    frame counters, recorded into one [`FrameEncoder`] and submitted once, without waiting
//!    (only the `cpu` strategy with depth bounds reads the cell bounds back part-way);
//! 3. **analyze** (`analysis.rs`, only when asked: [`Renderer::render_state`]): image, depth
//!    and counts read back, the ideal count, the grid downloaded, [`FrameStats`] filled.
//!
//! [`Renderer::render`] is the convenience form of step 3 for one frame of a `&Scene` (it sets
//! the scene when its contents differ from the one held). [`Renderer::render_frame`] is the
//! real-time path (steps 1-2): frames stay in flight, their
//! counters and timestamps come back asynchronously ([`Renderer::poll_finished`]), list sizes
//! follow them a frame later, and a frame they show to be wrong is reported in its
//! [`FinishedFrame`].

use crate::analysis::{self, AnalysisReadbacks};
use crate::consts::{MAX_FRAME_EDGE, MAX_LIGHTS};
use crate::culling::{CullReport, GridDims, ViewSetup};
use crate::error::{Error, Result};
use crate::frame::{
    FinishedFrame, FrameEncoder, FrameInputs, FrameIo, RenderSettings, SubmittedFrame,
};
use crate::gpu::{scoped, FrameCounters, FrameReadback, FrameTag, GpuContext, PassTimer};
use crate::gpu_types::{FrameUniforms, GpuLight};
use crate::passes::base_textures::BaseTextures;
use crate::passes::shadow_atlas::ShadowAtlas;
use crate::passes::{scene_layout_with, SceneBounds, Targets, Tonemap};
use crate::pipelines::{self, PipelineContext, Technique, TransparentLights, TransparentPass};
use crate::scene::{Draw, FrameState, Geometry, Light, Lighting, Scene, Shading, SpotCull};
use std::collections::{HashMap, VecDeque};
use std::sync::{Arc, OnceLock};
use web_time::Instant;

use crate::analysis::FrameOutput;

/// Most passes one frame may record (timestamp slots).
const MAX_PASSES: u32 = 128;

/// Frames the real-time path keeps in flight before it waits for the oldest (a game's
/// swap chain does the same).
pub const MAX_FRAMES_IN_FLIGHT: usize = 3;

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

    /// Make room for `bytes`, reallocating (contents lost) when too small. Returns true when
    /// the buffer was replaced.
    fn reserve(&mut self, device: &wgpu::Device, bytes: u64) -> bool {
        let grown = bytes > self.buffer.size();
        if grown {
            *self = GrowBuffer::new(device, self.label, self.usage, bytes.next_power_of_two());
        }
        grown
    }

    /// Upload `bytes` at `offset` (the buffer must hold them: [`GrowBuffer::reserve`]).
    fn write(&self, queue: &wgpu::Queue, offset: u64, bytes: &[u8]) {
        if !bytes.is_empty() {
            queue.write_buffer(&self.buffer, offset, bytes);
        }
    }
}

/// What the GPU holds of the current scene: the static geometry (uploaded once) and where the
/// moving geometry follows it.
struct SceneUpload {
    scene: Arc<Scene>,
    /// `Scene::content_fingerprint`, computed when [`Renderer::render`] first compares a scene
    /// with this one (never on the frame path).
    fingerprint: OnceLock<u64>,
    static_vertices: u32,
    static_indices: u32,
    /// The static geometry's runs of one material shader each.
    static_draws: Vec<Draw>,
    /// With `--shadows rays`: the static triangles' hierarchy and shadow space.
    shadows: Option<crate::shadows::StaticShadows>,
}

/// A tree a shadow ray's stack cannot walk is refused (the build's balanced trees reach that
/// depth only past 2^31 triangles).
fn check_shadow_tree(bvh: &crate::shadows::bvh::TriangleBvh) -> Result<()> {
    let depth = bvh.depth();
    if depth >= crate::consts::SHADOW_STACK_DEPTH {
        return Err(Error::invalid(
            "shadows",
            format!(
                "the shadow rays' hierarchy over {} triangles is {depth} levels deep; the shaders walk at most {}",
                bvh.triangles.len(),
                crate::consts::SHADOW_STACK_DEPTH - 1
            ),
        ));
    }
    Ok(())
}

/// What one frame uploaded.
struct Uploaded<'s> {
    state: &'s FrameState,
    setup: ViewSetup,
    /// The camera's projection (`setup.view` is its rotation).
    proj: glam::Mat4,
    index_count: u32,
    /// Runs of one material shader: the opaque geometry's, the transparent objects'.
    opaque: Vec<Draw>,
    transparent: Vec<Draw>,
    /// What this frame wrote after the static geometry (its transparent triangles are
    /// rasterized for the ideal count), and the vertex it starts at.
    frame_geometry: Geometry,
    static_vertices: u32,
    /// Bytes written to the GPU for this frame.
    upload_bytes: u64,
    /// Lights lit without shadows with `--shadows` on (`--shadow-lights`).
    unshadowed: u32,
    /// With `--shadows maps`: the frame's faces and where they lie.
    shadow_maps: Option<crate::shadows::maps::MapFrame>,
}

/// The frame's shadow maps when its pipeline re-uses one light's maps (`ReusedShadowMaps`).
fn reused_maps<'a>(
    atlas: &'a ShadowAtlas,
    up: &'a Uploaded,
) -> Option<crate::passes::shadow_atlas::ReusedMaps<'a>> {
    up.shadow_maps
        .as_ref()
        .filter(|m| m.reused)
        .map(|frame| crate::passes::shadow_atlas::ReusedMaps { atlas, frame })
}

/// Whose culler a report came from: a technique's (its pipeline id) or the transparent
/// pass's own grid (`None`).
type CullerOwner = Option<&'static str>;

/// The frames a renderer frame had its cullers encode.
struct CulledFrame {
    serial: u64,
    technique: Option<u64>,
    transparent: Option<u64>,
}

/// Renders frames at one size on one device.
///
/// It owns clones of the context's device and queue (cheap handles) and the adapter facts it
/// reads, so it borrows nothing: a [`GpuContext`] may be dropped or moved while it lives.
pub struct Renderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    /// R32Float blends (`GpuContext::count_blend`): forward pipelines count lighting.
    count_blend: bool,
    /// The adapter runs the compute grid and the compute passes reading depth
    /// ([`Renderer::runs_compute`]); not wgpu's GL backend.
    compute_grid: bool,
    /// `GpuContext::adapter_label`, for the statistics.
    adapter_label: String,
    targets: Targets,
    /// Group 0's layouts: the light bounds seen by the vertex stage only, and also by compute
    /// (`SceneBounds`).
    scene_layout: [wgpu::BindGroupLayout; 2],
    uniforms: wgpu::Buffer,
    lights: GrowBuffer,
    light_bounds: GrowBuffer,
    materials: GrowBuffer,
    vertices: GrowBuffer,
    indices: GrowBuffer,
    /// The shadow rays' buffer (`shading/shadows.wgsl`, group 0 binding 7): a header, the
    /// static triangles' hierarchy (written once per scene: `shadow_static_written`), the
    /// moving ones' and the casters (every frame). Two vec4s, never read, without shadows.
    shadow_data: GrowBuffer,
    shadow_static_written: bool,
    /// The shadow maps' texture (`--shadows maps`; 1x1 and unread otherwise), sized per frame
    /// to what its faces need within the budget's side (`shadows::maps::atlas_side`).
    shadow_atlas: ShadowAtlas,
    /// Group 0 for each of `scene_layout`.
    scene_bind_group: [wgpu::BindGroup; 2],
    /// The frame's lights as uploaded (camera-relative), which the grids' cullers also read
    /// on the CPU (`cpu`, `bvh`).
    gpu_lights: Vec<GpuLight>,
    /// The culler frames of each frame in flight, to match their reports with it.
    culled: VecDeque<CulledFrame>,
    /// Reports collected from the cullers and not yet matched with their frame.
    cull_reports: Vec<(CullerOwner, CullReport)>,
    /// The scene's base-colour textures (uploaded with its static geometry).
    textures: BaseTextures,
    scene: Option<SceneUpload>,
    /// Bytes `set_scene` wrote, counted in the next frame's `upload_bytes`.
    static_upload_bytes: u64,
    tonemap: Tonemap,
    timer: PassTimer,
    counters: FrameCounters,
    techniques: HashMap<&'static str, Box<dyn Technique>>,
    /// The transparent objects' pass after every technique (created with the first one).
    transparent: Option<TransparentPass>,
    /// What the techniques' and the transparent pass's modules are made for: the scene's
    /// lighting with `settings.brdf` (a new scene that changes it drops them, to be made again).
    shading: Shading,
    settings: RenderSettings,
    dims: GridDims,
    readbacks: AnalysisReadbacks,
    serial: u64,
    in_flight: VecDeque<wgpu::SubmissionIndex>,
    finished: Vec<FinishedFrame>,
}

/// The longest frame edge: lightgrid's limit or the adapter's, whichever is smaller.
pub fn max_frame_edge(ctx: &GpuContext) -> u32 {
    ctx.max_texture_edge().min(MAX_FRAME_EDGE)
}

/// Check a frame size against lightgrid's and the adapter's limits.
pub fn validate_size(ctx: &GpuContext, width: u32, height: u32) -> Result<()> {
    let limit = max_frame_edge(ctx);
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

/// Refuse a size or settings the adapter cannot render: the frame's edges, the settings'
/// own ranges, MSAA for every target, and what needs subgroup operations.
fn check_settings(
    ctx: &GpuContext,
    width: u32,
    height: u32,
    settings: &RenderSettings,
) -> Result<()> {
    validate_size(ctx, width, height)?;
    settings.validate()?;
    crate::frame::check_msaa(ctx, settings.grid.samples, settings.gbuffer)?;
    // The settings that need subgroup operations, and what to use without them.
    for (wants, what, instead) in [
        (
            settings.grid.depth_reduction == crate::frame::DepthReduction::Subgroup,
            "depth reduction",
            "atomics",
        ),
        (
            settings.light_loop == crate::frame::LightLoop::Subgroup,
            "light loop",
            "lane",
        ),
    ] {
        if wants && !ctx.subgroups {
            return Err(Error::invalid(
                what,
                format!(
                    "subgroup: {} has no subgroup operations; use {instead}",
                    ctx.adapter_label()
                ),
            ));
        }
    }
    Ok(())
}

impl Renderer {
    /// A renderer for `width`×`height`-pixel frames: the shared render targets, buffers and
    /// layouts (pipelines are created on first use). Refuses sizes and settings the adapter
    /// cannot render.
    pub fn new(
        ctx: &GpuContext,
        width: u32,
        height: u32,
        settings: RenderSettings,
    ) -> Result<Self> {
        check_settings(ctx, width, height, &settings)?;
        let dims = GridDims::new(width, height, settings.grid.tile_size)?;
        let device = &ctx.device;
        let created = scoped(device, "creating render targets", || {
            let targets = Targets::new(ctx, width, height, settings.grid.samples);
            let scene_layout =
                [SceneBounds::Vertex, SceneBounds::Compute].map(|b| scene_layout_with(device, b));
            let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("frame uniforms"),
                size: std::mem::size_of::<FrameUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            use wgpu::BufferUsages as U;
            let lights = GrowBuffer::new(device, "lights", U::STORAGE, 1 << 16);
            let light_bounds = GrowBuffer::new(device, "light bounds", U::STORAGE, 1 << 14);
            let materials = GrowBuffer::new(device, "materials", U::STORAGE, 1 << 12);
            let vertices = GrowBuffer::new(device, "vertices", U::VERTEX, 1 << 20);
            let indices = GrowBuffer::new(device, "indices", U::INDEX, 1 << 20);
            let shadow_data = GrowBuffer::new(device, "shadows", U::STORAGE, 32);
            let maps = settings.shadows == crate::scene::Shadows::Maps;
            let mut shadow_atlas = ShadowAtlas::new(device, maps);
            shadow_atlas.bind(device, &uniforms, &shadow_data.buffer);
            // With MSAA the per-pixel lighting counts follow the counters.
            let pixels = if settings.grid.samples > 1 {
                u64::from(width) * u64::from(height)
            } else {
                0
            };
            let counters = FrameCounters::new(device, MAX_PASSES, pixels);
            let textures = BaseTextures::new(device, &ctx.queue, &[]);
            let scene_bind_group = Self::bind_scene(
                device,
                &scene_layout,
                &uniforms,
                [&lights, &light_bounds, &materials, &shadow_data],
                counters.buffer(),
                (&textures, &shadow_atlas),
            );
            Renderer {
                device: device.clone(),
                queue: ctx.queue.clone(),
                count_blend: ctx.count_blend,
                compute_grid: Renderer::runs_compute(ctx),
                adapter_label: ctx.adapter_label(),
                targets,
                tonemap: Tonemap::new(device, settings.grid.samples),
                timer: PassTimer::new(ctx, MAX_PASSES),
                counters,
                scene_layout,
                uniforms,
                lights,
                light_bounds,
                materials,
                vertices,
                indices,
                shadow_data,
                shadow_static_written: false,
                shadow_atlas,
                scene_bind_group,
                gpu_lights: Vec::new(),
                culled: VecDeque::new(),
                cull_reports: Vec::new(),
                textures,
                scene: None,
                static_upload_bytes: 0,
                techniques: HashMap::new(),
                shading: Shading::default(),
                transparent: None,
                settings,
                dims,
                readbacks: AnalysisReadbacks::new(ctx, (width, height), settings.grid.samples),
                serial: 0,
                in_flight: VecDeque::new(),
                finished: Vec::new(),
            }
        });
        created.map_err(|e| match e {
            Error::Gpu { stage, message } if message.contains("out of memory") => Error::Gpu {
                stage,
                message: format!(
                    "out of memory: the shared render targets of {width}x{height} alone need {} MiB",
                    (Targets::bytes_per_pixel(settings.grid.samples) * u64::from(width) * u64::from(height)) >> 20
                ),
            },
            e => e,
        })
    }

    /// Group 0 of the scene, for each of its layouts.
    fn bind_scene(
        device: &wgpu::Device,
        layouts: &[wgpu::BindGroupLayout; 2],
        uniforms: &wgpu::Buffer,
        [lights, light_bounds, materials, shadow_data]: [&GrowBuffer; 4],
        counters: &wgpu::Buffer,
        (textures, atlas): (&BaseTextures, &ShadowAtlas),
    ) -> [wgpu::BindGroup; 2] {
        layouts.each_ref().map(|layout| {
            crate::gpu::bind_resources(
                device,
                "scene (group 0)",
                layout,
                &[
                    uniforms.as_entire_binding(),
                    lights.buffer.as_entire_binding(),
                    materials.buffer.as_entire_binding(),
                    counters.as_entire_binding(),
                    light_bounds.buffer.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&textures.view),
                    wgpu::BindingResource::Sampler(&textures.sampler),
                    shadow_data.buffer.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&atlas.view),
                    wgpu::BindingResource::Sampler(&atlas.sampler),
                    wgpu::BindingResource::Sampler(&textures.nearest),
                    wgpu::BindingResource::TextureView(&textures.view),
                ],
            )
        })
    }

    /// The frame size, `(width, height)` in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.targets.width, self.targets.height)
    }

    /// The settings the renderer was created with (fixed for its lifetime).
    pub fn settings(&self) -> RenderSettings {
        self.settings
    }

    /// The display target (tone-mapped sRGB, `passes::LDR_FORMAT`) the last submitted frame
    /// writes: what a window shows. Sampling it after [`Renderer::render_frame`] on the same
    /// queue reads that frame.
    pub fn display_view(&self) -> &wgpu::TextureView {
        &self.targets.ldr
    }

    /// Does `ctx`'s adapter run compute shaders reading depth and storage buffers written by
    /// fragment shaders (every pipeline)? Not wgpu's GL backend: it cannot `textureLoad` a
    /// depth texture as depth (naga's GLSL has no such load), llvmpipe GL's multisampled
    /// reads in compute return 0, and WebGL2 has neither compute nor storage buffers. There
    /// `forward` and the texture grid's tiled forward run (`--grid-storage auto` picks it).
    pub fn runs_compute(ctx: &GpuContext) -> bool {
        use wgpu::DownlevelFlags as D;
        ctx.downlevel()
            .contains(D::COMPUTE_SHADERS | D::FRAGMENT_WRITABLE_STORAGE)
            && ctx.info.backend != wgpu::Backend::Gl
    }

    /// Refuse what an adapter without the compute grid cannot render right (`runs_compute`).
    fn check_downlevel(&self, info: &pipelines::PipelineInfo) -> Result<()> {
        if self.compute_grid {
            return Ok(());
        }
        let textures =
            self.settings.grid_storage.resolve(false) == crate::frame::GridStorage::Textures;
        let reason = if self.settings.grid.samples > 1 {
            Some(
                "MSAA (its analysis and edge passes read multisampled depth in compute)"
                    .to_string(),
            )
        } else if info.id == pipelines::ids::FORWARD || (info.texture_grid && textures) {
            None
        } else if info.texture_grid {
            Some(format!(
                "{} with --grid-storage buffers (its grid is built by compute passes)",
                info.id
            ))
        } else {
            Some(format!(
                "{} (it reads depth or builds its grid in compute passes)",
                info.id
            ))
        };
        match reason {
            None => Ok(()),
            Some(what) => Err(Error::invalid(
                "adapter",
                format!(
                    "{} cannot run {what}: wgpu's GL backend cannot load depth textures in shaders and llvmpipe GL's multisampled compute reads return 0, so it runs `forward` and tiled_forward / tiled_forward_prez with --grid-storage textures at 1 sample; use a Vulkan, Metal or DX12 adapter for the rest",
                    self.adapter_label
                ),
            )),
        }
    }

    fn prepare_technique(&mut self, info: &'static pipelines::PipelineInfo) -> Result<()> {
        self.check_downlevel(info)?;
        if let (true, pipelines::Msaa::Refused(reason)) =
            (self.settings.grid.samples > 1, info.msaa)
        {
            return Err(Error::invalid(
                "msaa",
                format!(
                    "{} does not render with MSAA ({}x asked): {reason}",
                    info.id, self.settings.grid.samples
                ),
            ));
        }
        if !self.techniques.contains_key(info.id) {
            let device = &self.device;
            let ctx = PipelineContext {
                device,
                queue: &self.queue,
                scene_layout: &self.scene_layout[0],
                scene_culling_layout: &self.scene_layout[1],
                dims: self.dims,
                settings: self.settings,
                shading: self.shading,
                count_blend: self.count_blend,
                compute_grid: self.compute_grid,
            };
            let stage = format!("creating pipeline {}", info.id);
            let t = scoped(device, &stage, || (info.create)(&ctx))?.map_err(|e| match e {
                // A refusal from inside (its light grid's culler) names the pipeline too.
                Error::Gpu {
                    stage: inner,
                    message,
                } => Error::Gpu {
                    stage: format!("{stage} ({inner})"),
                    message,
                },
                e => e,
            })?;
            let own_grid = matches!(t.transparent_lights(), TransparentLights::Own);
            self.techniques.insert(info.id, t);
            if self.transparent.is_none() {
                let pass = scoped(device, "creating the transparent pass", || {
                    TransparentPass::new(&ctx)
                })??;
                self.transparent = Some(pass);
            }
            if own_grid {
                let pass = self.transparent.as_mut().expect("created above");
                scoped(device, "creating the transparent pass's grid", || {
                    pass.ensure_own_grid(&ctx)
                })??;
            }
        }
        Ok(())
    }

    /// The scene whose static part the GPU holds ([`Renderer::set_scene`]), if any.
    pub fn scene(&self) -> Option<&Arc<Scene>> {
        self.scene.as_ref().map(|u| &u.scene)
    }

    /// Take `scene` as the one whose frames follow: its materials, textures and static
    /// opaque geometry are uploaded now, once; each frame then uploads only its
    /// [`FrameState`] (lights, uniforms, moving and transparent objects). The renderer keeps
    /// the `Arc`, so a viewer and its analysis worker can share one scene without copies.
    /// A scene whose indices do not hold (`Scene::validate_structure`) is refused, and the
    /// renderer then holds none.
    pub fn set_scene(&mut self, scene: Arc<Scene>) -> Result<()> {
        self.scene = None;
        scene.validate_structure()?;
        scoped(&self.device.clone(), "uploading the scene", || {
            self.upload_static(scene)
        })?
    }

    /// [`Renderer::set_scene`] with a copy of `scene`, unless the scene held has the same
    /// contents. The comparison hashes the scene's meshes, objects, materials and textures
    /// (`Scene::content_fingerprint`): a call per frame costs that hash every frame, so a
    /// caller rendering many frames calls this (or `set_scene`) once and then renders
    /// [`FrameState`]s.
    pub fn use_scene(&mut self, scene: &Scene) -> Result<()> {
        let held = self
            .scene
            .as_ref()
            .map(|u| *u.fingerprint.get_or_init(|| u.scene.content_fingerprint()));
        if held != Some(scene.content_fingerprint()) {
            self.set_scene(Arc::new(scene.clone()))?;
        }
        Ok(())
    }

    /// The static geometry, materials and textures of `scene`, in buffers with room for what
    /// every frame writes after them (`Scene::frame_geometry_len`).
    fn upload_static(&mut self, scene: Arc<Scene>) -> Result<()> {
        // Cheap handle clones: `rebind_scene` borrows `self` mutably while they are in use.
        let (device, queue) = (&self.device.clone(), &self.queue.clone());
        let geometry = scene.static_geometry();
        let materials = scene.materials_gpu();
        let vb: &[u8] = bytemuck::cast_slice(&geometry.vertices);
        let ib: &[u8] = bytemuck::cast_slice(&geometry.indices);
        let mb: &[u8] = bytemuck::cast_slice(&materials);
        let (moving_vertices, moving_indices) = scene.frame_geometry_len();
        let vertex_bytes = std::mem::size_of::<crate::gpu_types::GpuVertex>();
        self.vertices
            .reserve(device, (vb.len() + moving_vertices * vertex_bytes) as u64);
        self.indices
            .reserve(device, (ib.len() + moving_indices * 4) as u64);
        // A new scene gets its own textures (a white texel without any), and the bind group
        // the new view.
        self.textures = BaseTextures::new(device, queue, &scene.textures);
        self.materials.reserve(device, mb.len() as u64);
        self.rebind_scene();
        self.vertices.write(queue, 0, vb);
        self.indices.write(queue, 0, ib);
        self.materials.write(queue, 0, mb);
        self.static_upload_bytes = self.textures.bytes + (vb.len() + ib.len() + mb.len()) as u64;
        let shading = Shading::of(&scene, self.settings.brdf, self.settings.shadows);
        let shadows = (self.settings.shadows == crate::scene::Shadows::Rays)
            .then(|| crate::shadows::StaticShadows::new(&geometry));
        if let Some(s) = &shadows {
            check_shadow_tree(&s.bvh)?;
        }
        self.shadow_static_written = false;
        if shading != self.shading {
            self.techniques.clear();
            self.transparent = None;
            self.shading = shading;
        }
        self.scene = Some(SceneUpload {
            scene,
            fingerprint: OnceLock::new(),
            static_vertices: geometry.vertices.len() as u32,
            static_indices: geometry.indices.len() as u32,
            static_draws: geometry.draws,
            shadows,
        });
        Ok(())
    }

    /// Step 1: validate `state` against the scene held and upload what the frame needs.
    /// `reuse_maps`: the pipeline re-uses one light's shadow maps
    /// (`Technique::reuses_shadow_maps`).
    fn upload<'s>(&mut self, state: &'s FrameState, reuse_maps: bool) -> Result<Uploaded<'s>> {
        let upload = self.scene.as_ref().ok_or_else(|| {
            Error::invalid(
                "scene",
                "no scene to render: give one with Renderer::set_scene first",
            )
        })?;
        Self::validate_state(&upload.scene, state)?;
        // What `set_scene` wrote is this frame's too (once).
        let mut upload_bytes = std::mem::take(&mut self.static_upload_bytes);
        let (bytes, frame_geometry) = self.upload_geometry(state)?;
        upload_bytes += bytes + self.upload_frame_data(state);
        let (shadow_bytes, unshadowed, shadow_maps) =
            if self.settings.shadows == crate::scene::Shadows::Maps {
                let transparent = frame_geometry.opaque_indices < frame_geometry.indices.len();
                self.upload_shadow_maps(state, reuse_maps, transparent)?
            } else {
                let (bytes, unshadowed) = self.upload_shadows(state, &frame_geometry)?;
                (bytes, unshadowed, None)
            };
        upload_bytes += shadow_bytes;
        let upload = self.scene.as_ref().expect("checked above");
        let (static_vertices, static_indices) = (upload.static_vertices, upload.static_indices);
        let (moving_opaque, moving_transparent) = frame_geometry.split_draws();
        let mut opaque = upload.static_draws.clone();
        opaque.extend(moving_opaque.iter().map(|d| d.offset(static_indices)));
        let transparent = moving_transparent
            .iter()
            .map(|d| d.offset(static_indices))
            .collect();
        let (width, height) = self.size();
        let mut setup = ViewSetup::new(&state.camera, width, height);
        setup.spot_cull = self.settings.grid.spot_cull;
        Ok(Uploaded {
            setup,
            proj: state.camera.proj(width as f32 / height as f32),
            index_count: static_indices + frame_geometry.indices.len() as u32,
            opaque,
            transparent,
            frame_geometry,
            static_vertices,
            state,
            upload_bytes,
            unshadowed,
            shadow_maps,
        })
    }

    /// With `--shadows maps`: the frame's casters, their faces and every face's matrix, and a
    /// texture of the size they need (the re-used tiles, the atlas, or both when a re-using
    /// pipeline's frame has transparent objects). Returns the bytes written, the lights lit
    /// unshadowed and the frame's maps.
    fn upload_shadow_maps(
        &mut self,
        state: &FrameState,
        reuse: bool,
        transparent: bool,
    ) -> Result<(u64, u32, Option<crate::shadows::maps::MapFrame>)> {
        let (width, height) = self.size();
        let casters = crate::shadows::casters(
            &state.lights,
            &state.camera,
            width as f32 / height as f32,
            self.settings.shadow_lights,
        );
        let eye = state.camera.eye;
        let relative: Vec<Light> = state.lights.iter().map(|l| l.relative_to(eye)).collect();
        let side = crate::shadows::maps::atlas_side(
            self.settings.shadow_atlas,
            self.device.limits().max_texture_dimension_2d,
        );
        let maps = crate::shadows::maps::MapFrame::new(
            &relative,
            &casters,
            side,
            self.settings.shadow_map_size,
            reuse,
        )
        .map_err(|reason| Error::invalid("shadow-atlas", reason))?;
        let size = maps.texture_size(transparent);
        let data = maps.gpu_data(size);
        let bytes: &[u8] = bytemuck::cast_slice(&data);
        let device = &self.device.clone();
        let grew = self.shadow_data.reserve(device, bytes.len() as u64);
        if self.shadow_atlas.fit(device, size) || grew {
            self.rebind_scene();
        }
        self.shadow_data.write(&self.queue, 0, bytes);
        let unshadowed = casters.iter().filter(|&&c| !c).count() as u32;
        Ok((bytes.len() as u64, unshadowed, Some(maps)))
    }

    /// With `--shadows rays`: the moving objects' hierarchy and the frame's shadow casters
    /// (and the static hierarchy when the buffer is new). Returns the bytes written and the
    /// lights lit unshadowed.
    fn upload_shadows(&mut self, state: &FrameState, moving: &Geometry) -> Result<(u64, u32)> {
        let upload = self.scene.as_ref().expect("checked by upload");
        let Some(statics) = &upload.shadows else {
            return Ok((0, 0));
        };
        let (width, height) = self.size();
        let frame = crate::shadows::ShadowFrame::new(
            statics,
            moving,
            upload.static_vertices,
            &state.camera,
            width as f32 / height as f32,
            &state.lights,
            self.settings.shadow_lights,
        );
        check_shadow_tree(&frame.moving)?;
        let header = frame.header(statics);
        let rest = frame.frame_data(statics);
        let start = u64::from(statics.frame_start()) * 16;
        let total = start + rest.len() as u64 * 16;
        let (device, queue) = (&self.device.clone(), &self.queue.clone());
        let mut bytes = 0;
        if self.shadow_data.reserve(device, total) {
            self.shadow_static_written = false;
            self.rebind_scene();
        }
        let upload = self.scene.as_ref().expect("checked by upload");
        let statics = upload.shadows.as_ref().expect("checked above");
        if !self.shadow_static_written {
            let data = statics.gpu_data();
            self.shadow_data.write(
                queue,
                u64::from(crate::shadows::HEADER_VEC4S) * 16,
                bytemuck::cast_slice(&data),
            );
            bytes += data.len() as u64 * 16;
            self.shadow_static_written = true;
        }
        self.shadow_data
            .write(queue, 0, bytemuck::cast_slice(&header));
        self.shadow_data
            .write(queue, start, bytemuck::cast_slice(&rest));
        bytes += (header.len() + rest.len()) as u64 * 16;
        Ok((bytes, frame.unshadowed() as u32))
    }

    /// A frame of `scene` as the caller describes it: the camera, the lights (count, NaN,
    /// ranges) and one finite transform per object.
    fn validate_state(scene: &Scene, state: &FrameState) -> Result<()> {
        state.camera.validate()?;
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
        if state.transforms.len() != scene.objects.len() {
            return Err(Error::invalid(
                "frame",
                format!(
                    "{} object transforms for the {} objects of {}",
                    state.transforms.len(),
                    scene.objects.len(),
                    scene.name
                ),
            ));
        }
        if let Some(i) = state.transforms.iter().position(|m| !m.is_finite()) {
            return Err(Error::invalid(
                "frame",
                format!("object {i}'s transform is not finite"),
            ));
        }
        Ok(())
    }

    /// The moving objects, written after the static geometry. Returns the bytes written and
    /// what was written.
    fn upload_geometry(&mut self, state: &FrameState) -> Result<(u64, Geometry)> {
        let queue = &self.queue.clone();
        let upload = self.scene.as_ref().expect("checked by upload");
        let (static_vertices, static_indices) = (upload.static_vertices, upload.static_indices);
        let moving = upload.scene.frame_geometry(state, static_vertices);
        let vb: &[u8] = bytemuck::cast_slice(&moving.vertices);
        let ib: &[u8] = bytemuck::cast_slice(&moving.indices);
        let (v_off, i_off) = (
            u64::from(static_vertices) * std::mem::size_of::<crate::gpu_types::GpuVertex>() as u64,
            u64::from(static_indices) * 4,
        );
        let mut upload_bytes = 0;
        if self.vertices.buffer.size() < v_off + vb.len() as u64
            || self.indices.buffer.size() < i_off + ib.len() as u64
        {
            // `upload_static` made room for every frame; should a frame still not fit,
            // growing loses the static part: upload it again.
            let scene = upload.scene.clone();
            self.upload_static(scene)?;
            upload_bytes += std::mem::take(&mut self.static_upload_bytes);
        }
        self.vertices.write(queue, v_off, vb);
        self.indices.write(queue, i_off, ib);
        upload_bytes += (vb.len() + ib.len()) as u64;
        Ok((upload_bytes, moving))
    }

    /// The frame's lights and uniforms. Returns the bytes written.
    fn upload_frame_data(&mut self, state: &FrameState) -> u64 {
        // Cheap handle clones: `rebind_scene` borrows `self` mutably while they are in use.
        let (device, queue) = (&self.device.clone(), &self.queue.clone());
        // Lights and geometry are drawn and shaded camera-relative (`ViewSetup::relative`).
        let eye = state.camera.eye;
        let lighting = self
            .scene
            .as_ref()
            .map_or_else(Lighting::default, |s| s.scene.lighting);
        // The BRDF the modules were made for (`upload_static` keeps it the scene's).
        let scale = lighting.light_scale(self.shading.brdf);
        let relative: Vec<_> = state.lights.iter().map(|l| l.relative_to(eye)).collect();
        let mut gpu_lights = std::mem::take(&mut self.gpu_lights);
        gpu_lights.clear();
        gpu_lights.extend(relative.iter().map(|l| l.to_gpu_scaled(scale)));
        let bounds: Vec<[f32; 4]> = relative.iter().map(Light::bounds_gpu).collect();
        let lb: &[u8] = bytemuck::cast_slice(&gpu_lights);
        let bb: &[u8] = bytemuck::cast_slice(&bounds);
        let grew_lights = self.lights.reserve(device, lb.len() as u64);
        if self.light_bounds.reserve(device, bb.len() as u64) || grew_lights {
            self.rebind_scene();
        }
        self.lights.write(queue, 0, lb);
        self.light_bounds.write(queue, 0, bb);
        let bytes = (lb.len() + bb.len() + std::mem::size_of::<FrameUniforms>()) as u64;
        // Kept for the grids' cullers.
        self.gpu_lights = gpu_lights;
        let (width, height) = self.size();
        let view = state.camera.rotation();
        let proj = state.camera.proj(width as f32 / height as f32);
        let view_proj = proj * view;
        let uniforms = FrameUniforms {
            view: view.to_cols_array_2d(),
            proj: proj.to_cols_array_2d(),
            view_proj: view_proj.to_cols_array_2d(),
            inv_view: view.transpose().to_cols_array_2d(),
            eye: eye.to_array(),
            light_count: state.lights.len() as u32,
            viewport: [width as f32, height as f32],
            near: state.camera.near,
            far: state.camera.far,
            spot_cull: u32::from(self.settings.grid.spot_cull == SpotCull::Cone),
            standard_depth: 0,
            _pad1: 0,
            _pad2: 0,
        };
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&uniforms));
        bytes
    }

    /// The shadow maps' texture as the last frame left it (`--shadows maps`; analysis: waits
    /// for the GPU): the atlas of every face, or a light-volume pipeline's last re-used cube
    /// (the atlas too when its frame had transparent objects). None without shadow maps.
    pub fn shadow_maps_image(&self) -> Result<Option<image::RgbaImage>> {
        if self.settings.shadows != crate::scene::Shadows::Maps || self.shadow_atlas.size == (1, 1)
        {
            return Ok(None);
        }
        self.shadow_atlas.image(&self.device, &self.queue).map(Some)
    }

    /// Does `info`'s technique (prepared) re-use one light's shadow maps?
    fn reuses_shadow_maps(&self, info: &pipelines::PipelineInfo) -> bool {
        self.techniques
            .get(info.id)
            .is_some_and(|t| t.reuses_shadow_maps())
    }

    /// Group 0 again, after a buffer it binds was replaced.
    fn rebind_scene(&mut self) {
        self.scene_bind_group = Self::bind_scene(
            &self.device,
            &self.scene_layout,
            &self.uniforms,
            [
                &self.lights,
                &self.light_bounds,
                &self.materials,
                &self.shadow_data,
            ],
            self.counters.buffer(),
            (&self.textures, &self.shadow_atlas),
        );
        self.shadow_atlas
            .bind(&self.device, &self.uniforms, &self.shadow_data.buffer);
    }

    /// Step 2: record the frame (pipeline, tonemap, `analysis` readback copies when given,
    /// the frame counters) and submit it once. Returns what the frame cost and its submission.
    fn encode_frame(
        &mut self,
        info: &'static pipelines::PipelineInfo,
        up: &Uploaded,
        analysis: bool,
    ) -> Result<(u64, FrameIo, wgpu::SubmissionIndex)> {
        let (device, queue) = (&self.device, &self.queue);
        let technique = self.techniques.get_mut(info.id).expect("prepared");
        self.timer.reset();
        let reused = reused_maps(&self.shadow_atlas, up);
        let inputs = FrameInputs {
            device,
            queue,
            scene_bind_group: &self.scene_bind_group[0],
            scene_culling_bind_group: &self.scene_bind_group[1],
            vertices: &self.vertices.buffer,
            indices: &self.indices.buffer,
            opaque: &up.opaque,
            transparent: &up.transparent,
            targets: &self.targets,
            setup: up.setup,
            lights: &up.state.lights,
            light_buffer: &self.lights.buffer,
            gpu_lights: &self.gpu_lights,
            proj: up.proj,
            count_blend: self.count_blend,
            reused_shadow_maps: reused
                .as_ref()
                .map(|r| r as &dyn crate::frame::ReusedShadowMaps),
        };
        let mut enc = FrameEncoder::new(device, queue, &mut self.timer);
        self.counters.clear(enc.parts().0);
        // Shadow maps all in flight before shading; a re-using pipeline renders each light's
        // itself, and the atlas after it for the transparent pass's forward shading.
        let atlas_at = |before: bool| {
            up.shadow_maps
                .as_ref()
                .filter(|m| m.reused != before && (before || inputs.has_transparency()))
        };
        if let Some(m) = atlas_at(true) {
            let (encoder, timer) = enc.parts();
            self.shadow_atlas
                .encode_all(encoder, timer, &inputs, &m.atlas);
        }
        technique.encode(&inputs, &mut enc)?;
        let technique_frame = technique.culler().map(|c| c.last_frame());
        if let Some(m) = atlas_at(false) {
            let (encoder, timer) = enc.parts();
            self.shadow_atlas
                .encode_all(encoder, timer, &inputs, &m.atlas);
        }
        if analysis && inputs.has_transparency() {
            self.readbacks.encode_opaque_counts(
                enc.parts().0,
                &self.targets,
                self.counters.buffer(),
            );
        }
        let transparent = (self
            .transparent
            .as_mut()
            .expect("created with the technique"))
        .encode(&inputs, &mut enc, technique.transparent_lights())?;
        let (encoder, timer) = enc.parts();
        if !technique.resolved_to_display() {
            self.tonemap
                .encode(device, encoder, timer, &self.targets.hdr, &self.targets.ldr);
        }
        if analysis {
            self.readbacks
                .encode(device, encoder, &self.targets, self.counters.buffer());
        }
        self.serial += 1;
        let tag = FrameTag {
            serial: self.serial,
            pipeline: info.id,
            pass_labels: timer.labels().to_vec(),
        };
        let timer: &PassTimer = timer;
        // `timer` and `encoder` borrow `enc`; the copy needs both.
        self.counters.encode_copy(device, encoder, timer, tag);
        match enc.submit(&format!("rendering with {}", info.id)) {
            Ok((io, index)) => {
                self.counters.after_submit();
                self.culled.push_back(CulledFrame {
                    serial: self.serial,
                    technique: technique_frame,
                    transparent,
                });
                Ok((self.serial, io, index))
            }
            Err(e) => {
                self.counters.abandon();
                Err(e)
            }
        }
    }

    /// A finished frame's report: its counters and timestamps, and its cullers' reports
    /// (their lists grow from them). Also returns the technique's grid's report.
    fn observe(&mut self, r: &FrameReadback) -> Result<(FinishedFrame, Option<CullReport>)> {
        let culled = loop {
            match self.culled.pop_front() {
                Some(c) if c.serial == r.tag.serial => break Some(c),
                // An older frame whose counters never came back (abandoned).
                Some(c) if c.serial < r.tag.serial => continue,
                Some(c) => {
                    self.culled.push_front(c);
                    break None;
                }
                None => break None,
            }
        };
        let (technique, transparent) =
            culled.map_or((None, None), |c| (c.technique, c.transparent));
        let technique = match technique {
            Some(frame) => Some(self.cull_report(Some(r.tag.pipeline), frame)?),
            None => None,
        };
        let transparent = match transparent {
            Some(frame) => Some(self.cull_report(None, frame)?),
            None => None,
        };
        let culls = [technique, transparent];
        let culls = culls.iter().flatten();
        let write_overflow = r.values.write_overflow();
        if write_overflow > 0 {
            return Err(Error::Gpu {
                stage: r.tag.pipeline.into(),
                message: format!(
                    "{write_overflow} light indices did not fit the counted lists (count and write passes disagree)"
                ),
            });
        }
        let t = self.timer.timings(&r.tag.pass_labels, &r.ticks);
        let finished = FinishedFrame {
            serial: r.tag.serial,
            pipeline: r.tag.pipeline,
            gpu_ms: t.gpu_ms,
            assign_gpu_ms: t.assign_ms,
            passes: t.passes,
            truncated_loops: r.values.truncated_loops()
                + culls.clone().map(|c| c.truncated_loops).sum::<u32>(),
            overflowed: r.values.overflowed() || culls.clone().any(|c| c.overflowed),
            msaa_shading: (r.values.geometry_samples() > 0).then(|| crate::frame::MsaaShading {
                edge_pixels: r.values.edge_pixels().into(),
                shaded_samples: r.values.shaded_samples().into(),
                geometry_samples: r.values.geometry_samples().into(),
            }),
            fragments_off_bounds: r.values.fragments_off_bounds().into(),
            shadow_rays: r.values.shadow_rays().into(),
        };
        Ok((finished, technique))
    }

    /// Culler `owner`'s report of its frame `frame` (encoded in a renderer frame the GPU has
    /// finished, so its counters are mapped or about to be).
    fn cull_report(&mut self, owner: CullerOwner, frame: u64) -> Result<CullReport> {
        for wait in [false, true] {
            if let Some(i) = self
                .cull_reports
                .iter()
                .position(|(o, r)| *o == owner && r.frame == frame)
            {
                let (_, report) = self.cull_reports.swap_remove(i);
                self.cull_reports
                    .retain(|(o, r)| *o != owner || r.frame > frame);
                return Ok(report);
            }
            let culler = match owner {
                Some(id) => self.techniques.get_mut(id).and_then(|t| t.culler()),
                None => self.transparent.as_mut().and_then(|t| t.culler_mut()),
            };
            let Some(culler) = culler else {
                break;
            };
            let reports = match wait {
                false => culler.poll(),
                true => culler.wait(),
            }
            .map_err(|e| Error::Gpu {
                stage: "light culling".into(),
                message: e.to_string(),
            })?;
            self.cull_reports
                .extend(reports.into_iter().map(|r| (owner, r)));
        }
        Err(Error::Gpu {
            stage: "light culling".into(),
            message: format!("the report of culler frame {frame} did not come back"),
        })
    }

    /// Collect the frames the GPU has finished, without waiting.
    fn collect(&mut self, wait: bool) -> Result<()> {
        let device = &self.device;
        let done = if wait {
            self.counters.wait(device)?
        } else {
            self.counters.poll(device)?
        };
        for r in &done {
            let (f, _) = self.observe(r)?;
            self.finished.push(f);
        }
        Ok(())
    }

    /// Real time: render `state`, a frame of the scene held ([`Renderer::set_scene`]), with
    /// `pipeline_id` and return once it is submitted, without waiting for it (nor for
    /// anything of this frame). Frames finished meanwhile are collected for
    /// [`Renderer::poll_finished`]; with more than [`MAX_FRAMES_IN_FLIGHT`] in flight this
    /// waits for the oldest first.
    pub fn render_frame(
        &mut self,
        state: &FrameState,
        pipeline_id: &str,
    ) -> Result<SubmittedFrame> {
        let info = pipelines::find(pipeline_id)?;
        self.prepare_technique(info)?;
        let mut throttle_ms = 0.0;
        if self.in_flight.len() >= MAX_FRAMES_IN_FLIGHT {
            let oldest = self.in_flight.pop_front().expect("non-empty");
            let start = Instant::now();
            self.device
                .poll(wgpu::PollType::Wait {
                    submission_index: Some(oldest),
                    timeout: None,
                })
                .map_err(|e| Error::Gpu {
                    stage: "waiting for an older frame".into(),
                    message: e.to_string(),
                })?;
            throttle_ms = start.elapsed().as_secs_f64() * 1e3;
        }
        self.collect(false)?;
        let up = self.upload(state, self.reuses_shadow_maps(info))?;
        let (serial, io, index) = self.encode_frame(info, &up, false)?;
        self.in_flight.push_back(index);
        while self.in_flight.len() > MAX_FRAMES_IN_FLIGHT {
            self.in_flight.pop_front();
        }
        Ok(SubmittedFrame {
            serial,
            io,
            throttle_ms,
            upload_bytes: up.upload_bytes,
        })
    }

    /// Real-time frames submitted whose GPU work may not be done yet (at most
    /// [`MAX_FRAMES_IN_FLIGHT`]).
    pub(crate) fn frames_in_flight(&self) -> usize {
        self.in_flight.len()
    }

    /// The real-time frames finished since the last call, oldest first (no waiting).
    pub fn poll_finished(&mut self) -> Result<Vec<FinishedFrame>> {
        self.collect(false)?;
        Ok(std::mem::take(&mut self.finished))
    }

    /// Wait for every frame in flight and return the reports not collected yet.
    pub fn finish(&mut self) -> Result<Vec<FinishedFrame>> {
        self.collect(true)?;
        self.in_flight.clear();
        Ok(std::mem::take(&mut self.finished))
    }

    /// Analysis of one frame of `scene`: [`Renderer::use_scene`] (which hashes the scene to
    /// see whether it is the one held), then [`Renderer::render_state`] of
    /// `scene.frame(frame)`.
    pub fn render(&mut self, scene: &Scene, frame: u32, pipeline_id: &str) -> Result<FrameOutput> {
        scene.check_frame(frame)?;
        self.use_scene(scene)?;
        self.render_state(&scene.frame(frame), pipeline_id)
    }

    /// Analysis: render `state`, a frame of the scene held ([`Renderer::set_scene`]), with
    /// `pipeline_id`, wait for it, read back image, depth and counts, download the grid and
    /// compute the ideal count ([`FrameOutput`]). A frame whose lists did not fit is rerun
    /// after growing them (`assign_reruns`); a frame with truncated shader loops is an error
    /// ([`Error::TruncatedLoops`]).
    pub fn render_state(&mut self, state: &FrameState, pipeline_id: &str) -> Result<FrameOutput> {
        let info = pipelines::find(pipeline_id)?;
        self.prepare_technique(info)?;
        // Earlier real-time frames first, so this frame's counters are its own.
        self.finish()?;
        let mut reruns = 0u32;
        // A rerun records the same uploaded frame again with the grown lists.
        let up = self.upload(state, self.reuses_shadow_maps(info))?;
        loop {
            let start = Instant::now();
            let (serial, io, _) = self.encode_frame(info, &up, true)?;
            let done = self.counters.wait(&self.device)?;
            let wall_ms = start.elapsed().as_secs_f64() * 1e3;
            let readback = done
                .into_iter()
                .find(|r| r.tag.serial == serial)
                .ok_or_else(|| Error::Gpu {
                    stage: "frame counters".into(),
                    message: "the frame's counters did not come back".into(),
                })?;
            let (finished, cull) = self.observe(&readback)?;
            if finished.truncated_loops > 0 {
                return Err(Error::TruncatedLoops {
                    pipeline: info.id.to_string(),
                    count: finished.truncated_loops,
                });
            }
            if finished.fragments_off_bounds > 0 {
                return Err(Error::Gpu {
                    stage: info.id.into(),
                    message: format!(
                        "{} MSAA fragments lay outside their light-grid cell's bounds (their lists may miss lights); the frame is refused",
                        finished.fragments_off_bounds
                    ),
                });
            }
            if finished.overflowed {
                reruns += 1;
                if reruns > 2 {
                    return Err(Error::Overflow {
                        pipeline: info.id.to_string(),
                        reason: "the light lists still did not fit after growing them twice".into(),
                    });
                }
                continue;
            }
            let grid = match (
                self.techniques.get_mut(info.id).and_then(|t| t.culler()),
                cull,
            ) {
                (Some(culler), Some(report)) => Some(analysis::BuiltGrid::read(culler, &report)?),
                _ => self.techniques[info.id]
                    .texture_grid()
                    .map(|t| analysis::BuiltGrid {
                        grid: t.grid.clone(),
                        cell_bounds: t.bounds.clone(),
                        cell_culls: Vec::new(),
                        assign: crate::frame::Assign::Cpu,
                        cpu_ms: t.cpu_ms,
                    }),
            };
            return analysis::analyze(analysis::AnalysisInput {
                device: &self.device,
                count_blend: self.count_blend,
                adapter: &self.adapter_label,
                size: self.size(),
                dims: self.dims,
                settings: self.settings,
                readbacks: &self.readbacks,
                scene_name: &self.scene.as_ref().expect("uploaded").scene.name,
                info,
                up_state: up.state,
                transparent: up.frame_geometry.transparent_triangles(up.static_vertices),
                setup: up.setup,
                triangles: up.index_count / 3,
                finished,
                grid,
                io,
                reruns,
                wall_ms,
                unshadowed: up.unshadowed,
                shadow_maps: up
                    .shadow_maps
                    .as_ref()
                    .map(|m| crate::stats::ShadowMapStats {
                        bytes: u64::from(self.shadow_atlas.size.0)
                            * u64::from(self.shadow_atlas.size.1)
                            * 4,
                        face: m.layout.tile,
                        faces: m.matrices.len() as u32,
                        reused: m.reused,
                    }),
                resolved_in_kernel: self
                    .techniques
                    .get(info.id)
                    .is_some_and(|t| t.resolved_to_display()),
            });
        }
    }
}
