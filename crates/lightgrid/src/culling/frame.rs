//! What every culling stage reads: the frame ([`CullFrame`]: group 0 of the culling kernels,
//! the depth, the camera), where the cell bounds come from ([`CellSource`]), and how long a
//! list the device can bind. The ground floor of `culling/`: the grid, the bounds, the
//! strategies and the culler all read it.

use crate::error::{Error, Result};
use crate::scene::{Light, ViewSetup};

/// What every culling stage reads in one frame: group 0 of its kernels ([`cull_layout`]: the
/// camera uniforms, the lights and their bounding spheres in camera-relative space, the frame
/// counters), the depth buffer, and the camera on the CPU.
/// [`crate::culling::embed::culler::LightCuller`] fills it from a caller's inputs (lightgrid's
/// renderer is such a caller).
pub struct CullFrame<'a> {
    pub device: &'a wgpu::Device,
    pub queue: &'a wgpu::Queue,
    /// Group 0 of the culling kernels ([`cull_layout`]).
    pub bind_group: &'a wgpu::BindGroup,
    /// The counters bound at group 0 binding 3 (indirect dispatch arguments are copied out).
    pub counters: &'a wgpu::Buffer,
    /// The frame's depth (as recorded so far); `None` only for `CellSource::NearFar`.
    pub depth: Option<&'a wgpu::TextureView>,
    pub setup: ViewSetup,
    pub light_count: usize,
    /// The lights on the CPU (world space), for the strategies that work there (`cpu`,
    /// `bvh`); empty where only the GPU has them ([`crate::culling::embed::culler::LightCuller`]).
    pub lights: &'a [Light],
    /// `lights` holds the frame's lights (the renderer's frames always; a caller's when it
    /// hands them): `auto` may resolve to `cpu` on a software adapter.
    pub lights_on_cpu: bool,
    /// The frame draws transparent geometry (the grid's transparent lists are built).
    pub transparency: bool,
    /// The caller's depth view as given (the render-pass attachment of `fragments`).
    pub depth_attachment: Option<&'a wgpu::TextureView>,
    /// MSAA forward shading: the caller's draws of the fragments it shades from the grid
    /// (`CullExtras::fragments`).
    #[allow(clippy::type_complexity)]
    pub fragments: Option<&'a dyn Fn(&mut wgpu::RenderPass<'_>, &wgpu::BindGroup)>,
}

impl<'a> CullFrame<'a> {
    /// The depth view (a `CellSource::Depth` grid always has one).
    pub fn depth(&self) -> &wgpu::TextureView {
        self.depth
            .expect("a grid over the depth buffer is given the depth")
    }

    /// The caller's depth view (given with the depth).
    pub fn depth_attachment(&self) -> &wgpu::TextureView {
        self.depth_attachment
            .expect("a grid over the depth buffer is given the depth")
    }
}

/// Group 0 of every culling kernel: `shading/scene_bindings.wgsl`'s bindings 0 (the frame
/// uniforms) and 3 (frame counters), and the light records at 5
/// (`culling/embed/light_records.wgsl`): two storage buffers. The lights, materials, bounds
/// and textures of the renderer's group 0 are not part of it.
pub fn cull_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    use crate::gpu::{STORAGE_READ, STORAGE_RW, UNIFORM};
    let entry = |binding, ty| crate::gpu::buffer_entry(binding, ty);
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("culling (group 0)"),
        entries: &[
            entry(0, UNIFORM),
            entry(3, STORAGE_RW),
            entry(5, STORAGE_READ),
        ],
    })
}

/// A group 0 for [`cull_layout`] over `[uniforms, counters, light records]`.
pub fn bind_cull_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    [uniforms, counters, records]: [&wgpu::Buffer; 3],
) -> wgpu::BindGroup {
    fn entry(binding: u32, b: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
        wgpu::BindGroupEntry {
            binding,
            resource: b.as_entire_binding(),
        }
    }
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("culling (group 0)"),
        layout,
        entries: &[entry(0, uniforms), entry(3, counters), entry(5, records)],
    })
}

/// Where the cell bounds come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellSource {
    /// No depth information: every cell spans near..far (`tiled_forward`).
    NearFar,
    /// The frame's depth buffer (`targets.depth`), reduced on the GPU.
    Depth,
}

/// Most u32 entries one storage binding of this device holds.
pub fn max_index_entries(device: &wgpu::Device) -> u64 {
    let limits = device.limits();
    limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size)
        / 4
}

/// Index lists longer than the device can bind are an error, never a truncated list.
pub fn check_index_capacity(device: &wgpu::Device, entries: u64, stage: &str) -> Result<()> {
    let max = max_index_entries(device);
    if entries > max {
        return Err(Error::invalid(
            "--assign",
            format!(
                "{stage}: the light grid needs {entries} index entries, more than the {max} this device can bind; use fewer lights, a larger --tile or fewer --slices"
            ),
        ));
    }
    Ok(())
}
