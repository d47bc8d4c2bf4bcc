//! Headless adapter and device selection.
//!
//! Order of preference: discrete GPU, integrated, virtual, then software adapters (Mesa
//! lavapipe). `--adapter` overrides the choice by index, name or backend.
//!
//! Vulkan, Metal and DX12 are searched ([`BACKENDS`]); wgpu's GL backend only when asked for
//! by name (`--adapter gl`): it runs `forward` and the texture grid's tiled forward, and the
//! renderer refuses the rest (`Renderer::runs_compute`: no depth loads in GLSL, llvmpipe GL's
//! multisampled compute reads return 0, R32Float neither blendable nor renderable).

use crate::error::{Error, Result};

/// A device ready to render, with what was learnt about its adapter.
pub struct GpuContext {
    /// The instance the adapter came from (a window's surface is created from it).
    pub instance: wgpu::Instance,
    /// The adapter the device was created on.
    pub adapter: wgpu::Adapter,
    /// The device every resource and pipeline is created on.
    pub device: wgpu::Device,
    /// The device's queue: buffer writes and command submissions.
    pub queue: wgpu::Queue,
    /// The adapter's name, backend, device type and driver (reports, software checks).
    pub info: wgpu::AdapterInfo,
    /// Timestamp queries at pass boundaries are available and enabled.
    pub timestamps: bool,
    /// R32Float can be blended, so forward pipelines can count lighting computations.
    pub count_blend: bool,
    /// Subgroup operations are enabled (`--depth-reduction subgroup`).
    pub subgroups: bool,
}

/// One line of `lightgrid list`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct AdapterSummary {
    /// Position in preference order; `--adapter <index>` selects it.
    pub index: usize,
    /// The adapter's name as its driver reports it.
    pub name: String,
    /// Backend as wgpu names it, lowercase (`vulkan`, `metal`, `dx12`, `gl`, ...).
    pub backend: String,
    /// `wgpu::DeviceType` as Debug prints it (`DiscreteGpu`, `IntegratedGpu`, `Cpu`...).
    pub device_type: String,
    /// Driver name and driver info, space-separated (empty if the adapter reports none).
    pub driver: String,
}

/// The backends searched unless GL is asked for by name (see the module docs).
pub const BACKENDS: wgpu::Backends = wgpu::Backends::VULKAN
    .union(wgpu::Backends::METAL)
    .union(wgpu::Backends::DX12);

const NO_ADAPTER_HELP: &str = "no GPU adapter found. lightgrid needs a Vulkan, Metal or DX12 \
adapter (`--adapter gl` runs only `forward` and the texture grid); on a machine without a GPU install Mesa's software Vulkan driver: \
`sudo apt-get install -y mesa-vulkan-drivers libvulkan1` (Debian/Ubuntu)";

/// A display handle for the instance: a window system's display (the viewer's), or none for
/// headless rendering.
pub type Display = Box<dyn wgpu::wgt::WgpuHasDisplayHandle>;

fn instance(display: Option<Display>) -> wgpu::Instance {
    wgpu::Instance::new(match display {
        Some(d) => wgpu::InstanceDescriptor::new_with_display_handle_from_env(d),
        None => wgpu::InstanceDescriptor::new_without_display_handle_from_env(),
    })
}

/// The backends searched for `wanted`: GL only when asked for by name (`--adapter gl`), as
/// it runs fewer pipelines (`GpuContext::gl_refusal`).
fn backends_for(wanted: Option<&str>) -> wgpu::Backends {
    match wanted.map(|w| w.trim().to_lowercase()).as_deref() {
        Some("gl") | Some("opengl") => wgpu::Backends::GL,
        _ => BACKENDS,
    }
}

fn rank(info: &wgpu::AdapterInfo) -> u32 {
    match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    }
}

fn sorted_adapters(instance: &wgpu::Instance, backends: wgpu::Backends) -> Vec<wgpu::Adapter> {
    let mut adapters = pollster::block_on(instance.enumerate_adapters(backends));
    adapters.sort_by_key(|a| rank(&a.get_info()));
    adapters
}

fn summarize(index: usize, info: &wgpu::AdapterInfo) -> AdapterSummary {
    AdapterSummary {
        index,
        name: info.name.clone(),
        backend: format!("{:?}", info.backend).to_lowercase(),
        device_type: format!("{:?}", info.device_type),
        driver: format!("{} {}", info.driver, info.driver_info)
            .trim()
            .to_string(),
    }
}

/// Every adapter wgpu sees, in preference order (index 0 is the default choice).
pub fn list_adapters() -> Vec<AdapterSummary> {
    sorted_adapters(&instance(None), BACKENDS)
        .iter()
        .enumerate()
        .map(|(i, a)| summarize(i, &a.get_info()))
        .collect()
}

/// The limits a device is asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DeviceLimits {
    /// The adapter's own: the largest storage bindings (very long light lists) and textures.
    Adapter,
    /// WebGPU's defaults, what every page may rely on: every pipeline and strategy runs
    /// within them (8 storage buffers per stage, 4 bind groups; README, "Platforms").
    WebGpu,
    /// WebGPU's defaults with 2D textures at most this many texels on a side (WebGL2
    /// guarantees 2048): the texture grid's capacity follows the edge
    /// (`--grid-storage textures`), and its tests reach it with a small one.
    WebGpuTextureEdge(u32),
}

impl DeviceLimits {
    /// What the environment asks for: `LIGHTGRID_LIMITS=webgpu` shows natively what a page
    /// on WebGPU's defaults gets; otherwise the adapter's.
    pub fn from_env() -> Self {
        match std::env::var("LIGHTGRID_LIMITS").as_deref() {
            Ok("webgpu") => DeviceLimits::WebGpu,
            _ => DeviceLimits::Adapter,
        }
    }

    fn of(self, adapter: &wgpu::Adapter) -> wgpu::Limits {
        match self {
            DeviceLimits::Adapter => adapter.limits(),
            DeviceLimits::WebGpu => wgpu::Limits::default(),
            DeviceLimits::WebGpuTextureEdge(edge) => wgpu::Limits {
                max_texture_dimension_2d: edge,
                ..wgpu::Limits::default()
            },
        }
    }
}

/// Does `wanted` (an index, a backend name, or part of the adapter name) select this adapter?
fn matches(wanted: &str, index: usize, info: &wgpu::AdapterInfo) -> bool {
    let w = wanted.trim().to_lowercase();
    if let Ok(i) = w.parse::<usize>() {
        return i == index;
    }
    let backend = format!("{:?}", info.backend).to_lowercase();
    backend == w
        || (w == "opengl" && backend == "gl")
        || info.name.to_lowercase().contains(&w)
        || info.driver.to_lowercase().contains(&w)
}

impl GpuContext {
    /// Pick an adapter (the best one, or the one `wanted` names) and create a device on it.
    pub fn new(wanted: Option<&str>) -> Result<Self> {
        Self::with_display(None, wanted)
    }

    /// [`GpuContext::new`] asking for `limits` whatever the environment says (the tests run
    /// every pipeline on WebGPU's defaults).
    pub fn with_limits(wanted: Option<&str>, limits: DeviceLimits) -> Result<Self> {
        Self::open_adapter(None, wanted, limits)
    }

    /// [`GpuContext::new`] on an instance that knows a window system's `display`, so that
    /// surfaces of its windows can be created ([`GpuContext::instance`]).
    pub fn with_display(display: Option<Display>, wanted: Option<&str>) -> Result<Self> {
        Self::open_adapter(display, wanted, DeviceLimits::from_env())
    }

    fn open_adapter(
        display: Option<Display>,
        wanted: Option<&str>,
        limits: DeviceLimits,
    ) -> Result<Self> {
        let instance = instance(display);
        let adapters = sorted_adapters(&instance, backends_for(wanted));
        if adapters.is_empty() {
            return Err(Error::NoAdapter(NO_ADAPTER_HELP.to_string()));
        }
        let adapter = match wanted {
            None => adapters.into_iter().next(),
            Some(w) if w.trim().is_empty() => {
                return Err(Error::NoAdapter(
                    "--adapter is empty; give an index from `lightgrid list`, a backend (vulkan) or part of an adapter's name".into(),
                ))
            }
            Some(w) => {
                let names: Vec<String> = adapters
                    .iter()
                    .enumerate()
                    .map(|(i, a)| {
                        let s = summarize(i, &a.get_info());
                        format!("{}: {} ({})", s.index, s.name, s.backend)
                    })
                    .collect();
                let found = adapters
                    .into_iter()
                    .enumerate()
                    .find(|(i, a)| matches(w, *i, &a.get_info()))
                    .map(|(_, a)| a);
                if found.is_none() {
                    return Err(Error::NoAdapter(format!(
                        "no adapter matches '{w}'; available: {}",
                        names.join(", ")
                    )));
                }
                found
            }
        }
        .expect("checked above");
        pollster::block_on(Self::open(instance, adapter, limits))
    }

    /// The page's context (wasm32): the browser's WebGPU adapter and a device on it. Nothing
    /// on the web may block, so this is the one `async` constructor.
    /// `limits`: the adapter's, or WebGPU's defaults (the page's `?limits=webgpu`; a page has
    /// no environment).
    #[cfg(target_arch = "wasm32")]
    pub async fn for_page(limits: DeviceLimits) -> Result<Self> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        desc.backends = wgpu::Backends::BROWSER_WEBGPU;
        let instance = wgpu::Instance::new(desc);
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                ..Default::default()
            })
            .await
            .map_err(|e| {
                Error::NoAdapter(format!(
                    "this browser offers no WebGPU adapter ({e}): use a browser with WebGPU \
                     (Chrome or Edge 113+, Firefox 141+, Safari 26+)"
                ))
            })?;
        Self::open(instance, adapter, limits).await
    }

    async fn open(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        limits: DeviceLimits,
    ) -> Result<Self> {
        let info = adapter.get_info();
        let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let mut features = wgpu::Features::empty();
        if timestamps {
            features |= wgpu::Features::TIMESTAMP_QUERY;
        }
        let count_blend = adapter
            .features()
            .contains(wgpu::Features::FLOAT32_BLENDABLE);
        if count_blend {
            features |= wgpu::Features::FLOAT32_BLENDABLE;
        }
        // Forced early depth tests keep early-Z for forward fragment shaders that may write
        // the frame counters (`shader::create_module` drops the attribute without it).
        features |= adapter.features() & wgpu::Features::SHADER_EARLY_DEPTH_TEST;
        // Sample counts beyond WebGPU's 1 and 4 (and MSAA of 32-bit float G-buffers) are
        // adapter-specific format features (`--msaa`, [`GpuContext::sample_counts`]).
        features |= adapter.features() & wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES;
        // A float depth copy for the light-volume passes (`passes::volume_depth_format`).
        features |= adapter.features() & wgpu::Features::DEPTH32FLOAT_STENCIL8;
        // Subgroup operations for the depth reduction (tiled-shading §8), where there are any.
        let subgroups = adapter.features().contains(wgpu::Features::SUBGROUP);
        features |= adapter.features() & wgpu::Features::SUBGROUP;
        let desc = wgpu::DeviceDescriptor {
            label: Some("lightgrid"),
            required_features: features,
            required_limits: limits.of(&adapter),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        };
        let (device, queue) = adapter
            .request_device(&desc)
            .await
            .map_err(|e| Error::Device {
                adapter: info.name.clone(),
                reason: e.to_string(),
            })?;
        // Errors are caught by error scopes around every stage; anything that escapes is a
        // bug, reported loudly rather than turned into a wrong image.
        device.on_uncaptured_error(std::sync::Arc::new(|e| {
            super::report_late("a GPU command", e.to_string());
        }));
        Ok(Self {
            instance,
            adapter,
            device,
            queue,
            info,
            timestamps,
            count_blend,
            subgroups,
        })
    }

    /// "name (backend)", as printed in stats and tables.
    pub fn adapter_label(&self) -> String {
        // A browser may name no adapter (privacy); it still says whether it is a fallback.
        let name = match (self.info.name.trim(), self.is_software()) {
            ("", true) => "software adapter",
            ("", false) => "unnamed adapter",
            (n, _) => n,
        };
        format!(
            "{name} ({})",
            format!("{:?}", self.info.backend).to_lowercase()
        )
    }

    /// Is this a software rasterizer (lavapipe / llvmpipe)?
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Loop iterations one shader invocation may run before the driver silently ends its loops
    /// (`consts::SOFTWARE_LOOP_BUDGET` on llvmpipe); None where no such limit is known. Only
    /// informative (tests, messages): frames detect truncated loops on the GPU
    /// (`FrameStats::truncated_loops`).
    pub fn loop_budget(&self) -> Option<u64> {
        self.info
            .name
            .contains("llvmpipe")
            .then_some(crate::consts::SOFTWARE_LOOP_BUDGET)
    }

    /// The MSAA sample counts (`consts::MSAA_COUNTS`) every one of `formats` supports as a
    /// multisampled render target, ascending; always has 1.
    pub fn sample_counts(&self, formats: &[wgpu::TextureFormat]) -> Vec<u32> {
        let specific = self
            .device
            .features()
            .contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES);
        crate::consts::MSAA_COUNTS
            .iter()
            .copied()
            .filter(|&n| {
                n == 1
                    || formats.iter().all(|&f| {
                        let features = if specific {
                            self.adapter.get_texture_format_features(f)
                        } else {
                            f.guaranteed_format_features(self.device.features())
                        };
                        features.flags.sample_count_supported(n)
                            && features
                                .allowed_usages
                                .contains(wgpu::TextureUsages::RENDER_ATTACHMENT)
                    })
            })
            .collect()
    }

    /// What the adapter can do beyond or short of WebGPU (`wgpu::DownlevelFlags`): GL lacks
    /// depth-to-buffer copies; WebGL2 compute shaders and storage buffers.
    pub fn downlevel(&self) -> wgpu::DownlevelFlags {
        self.adapter.get_downlevel_capabilities().flags
    }

    /// Largest 2D texture edge the device accepts.
    pub fn max_texture_edge(&self) -> u32 {
        self.device.limits().max_texture_dimension_2d
    }
}
