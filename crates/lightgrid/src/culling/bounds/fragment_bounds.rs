//! MSAA only: the cells' bounds widened to the view distance every forward fragment will look
//! its cell up at (`fragment_bounds.wgsl`). A fragment covering part of a pixel is shaded at
//! the pixel centre, which may lie off its triangle, so its depth can lie outside the bounds
//! of every sample of its cell; a pass with the shading passes' depth tests records where the
//! fragments that will be shaded lie, and the cell-bounds kernel unions that with the samples'
//! bounds. A fragment still outside is counted and its frame refused (`light_grid_shade_fragment`).

use crate::culling::grid::GridDims;
use crate::frame::{FrameEncoder, FrameInputs};
use crate::gpu::{bind_resources, grow_storage, storage_buffer};
use crate::passes::geometry::{draw_scene, geometry_pipeline, GeometryPipelineDesc};
use crate::scene::Shading;
use crate::shader::{compose, create_module, src, ComposedShader, SCENE_PARTS};

pub(crate) fn shader() -> ComposedShader {
    let mut parts = SCENE_PARTS.to_vec();
    parts.push(src::GRID_CELL);
    parts.push(include_str!("fragment_bounds.wgsl"));
    compose("fragment_bounds", &parts)
}

pub(crate) struct FragmentBounds {
    /// Whether a forward pass shades the opaque fragments (else only the transparent ones
    /// look cells up).
    forward_opaque: bool,
    layout: wgpu::BindGroupLayout,
    opaque: wgpu::RenderPipeline,
    transparent: wgpu::RenderPipeline,
    buffer: wgpu::Buffer,
}

impl FragmentBounds {
    pub(crate) fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        samples: u32,
        forward_opaque: bool,
    ) -> Self {
        // Fragment bounds evaluate no light: any shading compiles them alike.
        let module = create_module(device, &shader().specialized(Shading::default()));
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            visibility: wgpu::ShaderStages::FRAGMENT,
            ..crate::gpu::buffer_entry(binding, ty)
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("fragment bounds (group 1)"),
            entries: &[
                entry(0, crate::gpu::UNIFORM),
                entry(1, crate::gpu::STORAGE_RW),
            ],
        });
        let pipeline = |label, entry, depth_compare| {
            geometry_pipeline(
                device,
                &GeometryPipelineDesc {
                    label,
                    module: &module,
                    fragment_entry: Some(entry),
                    layouts: &[Some(scene_layout), Some(&layout)],
                    color_targets: &[],
                    depth_write: false,
                    depth_compare,
                    samples,
                },
            )
        };
        FragmentBounds {
            forward_opaque,
            // The tests of the passes whose fragments these bound: the opaque shading passes'
            // against the pre-pass depth, the transparent pass's against the opaque depth.
            opaque: pipeline(
                "assign: fragment bounds (opaque)",
                "fs_opaque",
                crate::depth::SURFACE,
            ),
            transparent: pipeline(
                "assign: fragment bounds (transparent)",
                "fs_transparent",
                crate::depth::NEARER,
            ),
            layout,
            buffer: storage_buffer(device, "fragment bounds", 1 << 14),
        }
    }

    /// The buffer the cell-bounds kernel reads (binding 5).
    pub(crate) fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// Record the pass over the frame's depth target; `params` holds `dims`' GridParams.
    pub(crate) fn encode(
        &mut self,
        f: &FrameInputs,
        enc: &mut FrameEncoder,
        dims: &GridDims,
        params: &wgpu::Buffer,
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
        if !self.forward_opaque && !f.has_transparency() {
            return;
        }
        let label = crate::consts::pass_labels::FRAGMENT_BOUNDS;
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[],
            depth_stencil_attachment: Some(crate::passes::loaded_depth(&f.targets.depth)),
            timestamp_writes: timer.render_pass(label),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.opaque);
        let opaque = if self.forward_opaque { f.opaque } else { &[] };
        draw_scene(&mut pass, &FrameInputs { opaque, ..*f }, &[&group]);
        pass.set_pipeline(&self.transparent);
        for d in f.transparent {
            pass.draw_indexed(d.first..d.first + d.count, 0, 0..1);
        }
    }
}
