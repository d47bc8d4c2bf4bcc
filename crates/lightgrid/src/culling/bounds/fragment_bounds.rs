//! MSAA forward shading only: the cells' bounds widened to the view distance every forward
//! fragment will look its cell up at. A fragment covering part of a pixel is shaded at the
//! pixel centre, which may lie off its triangle, so its depth can lie outside the bounds of
//! every sample of its cell. The renderer that shades from the grid draws those fragments in
//! a render pass the culler begins (`CullExtras::fragments`), each writing
//! its view distance into this buffer (`embed/fragments.wgsl`), and the cell-bounds kernel
//! unions that with the samples' bounds. A fragment still outside is counted and its frame
//! refused (lightgrid's `light_grid_shade_fragment`).

use crate::culling::frame::CullFrame;
use crate::culling::grid::GridDims;
use crate::frame::FrameEncoder;
use crate::gpu::{bind_resources, grow_storage, storage_buffer};

/// The fragments' bounds and the group their pass writes them through.
pub(crate) struct FragmentBounds {
    layout: wgpu::BindGroupLayout,
    buffer: wgpu::Buffer,
}

/// The group of `LightCuller::fragment_bounds_wgsl`: the grid's parameters and the bounds,
/// visible to fragment shaders.
fn layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
        visibility: wgpu::ShaderStages::FRAGMENT,
        ..crate::gpu::buffer_entry(binding, ty)
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("light grid fragment bounds"),
        entries: &[
            entry(0, crate::gpu::UNIFORM),
            entry(1, crate::gpu::STORAGE_RW),
        ],
    })
}

/// The caller's depth as its pre-pass left it (and its stencil, if the format has one).
fn loaded(view: &wgpu::TextureView) -> wgpu::RenderPassDepthStencilAttachment<'_> {
    let stencil = view.texture().format().has_stencil_aspect();
    wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations {
            load: wgpu::LoadOp::Load,
            store: wgpu::StoreOp::Store,
        }),
        stencil_ops: stencil.then_some(wgpu::Operations {
            load: wgpu::LoadOp::Load,
            store: wgpu::StoreOp::Store,
        }),
    }
}

impl FragmentBounds {
    pub(crate) fn new(device: &wgpu::Device) -> Self {
        FragmentBounds {
            layout: layout(device),
            buffer: storage_buffer(device, "fragment bounds", 1 << 14),
        }
    }

    /// The layout of the group handed to the caller's draws.
    pub(crate) fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The buffer the cell-bounds kernel reads (binding 4).
    pub(crate) fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// Clear the bounds and record the pass over the frame's depth (loaded, read only) in
    /// which `draw` draws the fragments; `params` holds `dims`' GridParams.
    pub(crate) fn encode(
        &mut self,
        f: &CullFrame,
        enc: &mut FrameEncoder,
        dims: &GridDims,
        params: &wgpu::Buffer,
        draw: &dyn Fn(&mut wgpu::RenderPass<'_>, &wgpu::BindGroup),
    ) {
        let device = f.device;
        grow_storage(
            device,
            &mut self.buffer,
            "fragment bounds",
            (dims.cell_count() * 8) as u64,
        );
        let group = bind_resources(
            device,
            "fragment bounds",
            &self.layout,
            &[params.as_entire_binding(), self.buffer.as_entire_binding()],
        );
        let (encoder, timer) = enc.parts();
        encoder.clear_buffer(&self.buffer, 0, None);
        let label = crate::consts::pass_labels::FRAGMENT_BOUNDS;
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[],
            depth_stencil_attachment: Some(loaded(f.depth_attachment())),
            timestamp_writes: timer.render_pass(label),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        draw(&mut pass, &group);
    }
}
