//! MSAA forward shading: lightgrid's renderer's draws of the fragments it will shade from a
//! grid, handed to its culler ([`crate::culling::CullExtras::fragments`]) as any renderer
//! would. A fragment covering part of a pixel is shaded at the pixel centre, which may lie
//! off its triangle; these draws (with the shading passes' depth tests: opaque against the
//! pre-pass depth, transparent in front of it) give each such fragment's view distance to
//! the culler's `light_grid_bound_fragment` (`fragment_bounds.wgsl`), so the cells' bounds
//! hold it.

use crate::frame::FrameInputs;
use crate::passes::geometry::{draw_scene, geometry_pipeline, GeometryPipelineDesc};
use crate::scene::Shading;
use crate::shader::{compose_defs, create_module, ComposedShader, ShaderKey, SCENE_PARTS};

/// The group the culler hands the draws.
const GROUP: u32 = 1;

/// The scene's parts, the culler's fragment-bounds module at group 1
/// ([`crate::LightCuller::fragment_bounds_wgsl`]'s key, less the parts the scene's already
/// hold) and the renderer's entry points.
pub(crate) fn shader() -> ComposedShader {
    let culler = crate::culling::fragment_bounds_key(GROUP);
    let mut parts = SCENE_PARTS.to_vec();
    parts.extend(
        culler
            .parts()
            .into_iter()
            .filter(|p| !SCENE_PARTS.contains(p)),
    );
    parts.push(include_str!("fragment_bounds.wgsl"));
    // Less what the constants prelude already declares.
    let defs: Vec<_> = (culler.defs().into_iter())
        .filter(|d| {
            !crate::consts::WGSL_CONSTS
                .iter()
                .any(|(n, _)| *n == d.name())
        })
        .collect();
    compose_defs("fragment_bounds", &defs, &parts)
}

/// The pipelines drawing a grid's fragments.
pub(crate) struct FragmentDraws {
    /// Whether a forward pass shades the opaque fragments from the grid (else only the
    /// transparent ones look cells up).
    forward_opaque: bool,
    opaque: wgpu::RenderPipeline,
    transparent: wgpu::RenderPipeline,
}

impl FragmentDraws {
    /// `layout`: the culler's fragment-bounds group ([`crate::LightCuller::fragment_bounds_layout`]).
    pub(crate) fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        layout: &wgpu::BindGroupLayout,
        samples: u32,
        forward_opaque: bool,
    ) -> Self {
        // Fragment bounds evaluate no light: any shading compiles them alike.
        let module = create_module(device, &shader().specialized(Shading::default()));
        let pipeline = |label, entry, depth_compare| {
            geometry_pipeline(
                device,
                &GeometryPipelineDesc {
                    label,
                    module: &module,
                    fragment_entry: Some(entry),
                    layouts: &[Some(scene_layout), Some(layout)],
                    color_targets: &[],
                    depth_write: false,
                    depth_compare,
                    samples,
                },
            )
        };
        FragmentDraws {
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
        }
    }

    /// Does frame `f` shade fragments from the grid at all?
    pub(crate) fn draws(&self, f: &FrameInputs) -> bool {
        self.forward_opaque || f.has_transparency()
    }

    /// Draw frame `f`'s fragments into the culler's pass, its group at 1.
    pub(crate) fn draw(
        &self,
        pass: &mut wgpu::RenderPass,
        group: &wgpu::BindGroup,
        f: &FrameInputs,
    ) {
        pass.set_pipeline(&self.opaque);
        let opaque = if self.forward_opaque { f.opaque } else { &[] };
        draw_scene(pass, &FrameInputs { opaque, ..*f }, &[group]);
        pass.set_pipeline(&self.transparent);
        for d in f.transparent {
            pass.draw_indexed(d.first..d.first + d.count, 0, 0..1);
        }
    }
}
