//! Rust structs in gpu_types.rs and their WGSL twins agree on size and every field offset.

use lightgrid::shader::{compose, src, validate};
use lightgrid::testing::gpu_types::{
    BvhNode, FrameUniforms, GpuLight, GpuMaterial, GridParams, LevelParams, SortParams,
};
use std::mem::{offset_of, size_of};

fn wgsl_layout(module: &naga::Module, name: &str) -> (u32, Vec<(String, u32)>) {
    let ty = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("WGSL struct {name} not found"))
        .1;
    match &ty.inner {
        naga::TypeInner::Struct { members, span } => (
            *span,
            members
                .iter()
                .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
                .collect(),
        ),
        other => panic!("{name} is not a struct: {other:?}"),
    }
}

macro_rules! check_layout {
    ($module:expr, $wgsl:literal, $rust:ty, [$($field:ident),* $(,)?]) => {{
        let (span, members) = wgsl_layout($module, $wgsl);
        assert_eq!(span as usize, size_of::<$rust>(), "size of {}", $wgsl);
        let rust: Vec<(String, u32)> = vec![$((stringify!($field).to_string(), offset_of!($rust, $field) as u32)),*];
        assert_eq!(members, rust, "fields and offsets of {}", $wgsl);
    }};
}

#[test]
fn gpu_structs_match_wgsl() {
    // A throwaway entry point keeps the module non-empty for validation.
    let shader = compose(
        "layout",
        &[
            src::TYPES,
            src::GRID_PARAMS,
            "@compute @workgroup_size(1) fn main() {}",
        ],
    );
    let module = validate(&shader).expect("types.wgsl validates");
    check_layout!(
        &module,
        "Light",
        GpuLight,
        [position, range, radiance, cos_inner, direction, cos_outer]
    );
    check_layout!(
        &module,
        "LightGridParams",
        GridParams,
        [
            tile_size,
            tiles_x,
            tiles_y,
            slices,
            slice_scale,
            slice_bias,
            lists,
            layer_cells,
            zbin_words,
            zbin_masks,
            pad_a,
            pad_b
        ]
    );
    check_layout!(
        &module,
        "Material",
        GpuMaterial,
        [
            diffuse,
            alpha,
            specular,
            shininess,
            emissive,
            flags,
            ambient,
            paint_power,
            paint,
            shader,
            texture,
            alpha_cutoff,
            emissive_texture,
            nearest,
            base,
            metallic,
            roughness,
            normal_scale,
            occlusion_strength,
            metal_rough_texture,
            normal_texture,
            occlusion_texture,
            uv_sets,
            wraps,
            uv_transforms
        ]
    );
    check_layout!(&module, "BvhNode", BvhNode, [lo, first, hi, count]);
    check_layout!(&module, "SortParams", SortParams, [n, shift, blocks, _pad]);
    check_layout!(
        &module,
        "LevelParams",
        LevelParams,
        [first, count, child_first, child_count]
    );
    check_layout!(
        &module,
        "FrameUniforms",
        FrameUniforms,
        [
            view,
            proj,
            view_proj,
            inv_view,
            eye,
            light_count,
            viewport,
            near,
            far,
            spot_cull,
            standard_depth,
            _pad1,
            _pad2
        ]
    );
}

#[test]
fn vertex_layout_matches_gpu_vertex() {
    use lightgrid::testing::gpu_types::GpuVertex;
    let layout = lightgrid::passes::vertex_layout();
    assert_eq!(layout.array_stride as usize, size_of::<GpuVertex>());
    let offsets: Vec<u64> = layout.attributes.iter().map(|a| a.offset).collect();
    assert_eq!(
        offsets,
        vec![
            offset_of!(GpuVertex, position) as u64,
            offset_of!(GpuVertex, normal) as u64,
            offset_of!(GpuVertex, uv) as u64,
            offset_of!(GpuVertex, material) as u64,
            offset_of!(GpuVertex, tangent) as u64,
            offset_of!(GpuVertex, color) as u64,
            offset_of!(GpuVertex, uv1) as u64,
        ]
    );
    // Each attribute's format is its field's size.
    let sizes: Vec<u64> = layout.attributes.iter().map(|a| a.format.size()).collect();
    assert_eq!(sizes, [12, 12, 8, 4, 8, 4, 8]);
}

/// The memory model's byte sizes are the formats' and structs' own, not numbers kept in sync
/// by hand.
#[test]
fn memory_model_sizes_match_the_formats_and_structs() {
    use lightgrid::memory::{DEPTH_BYTES, HDR_BYTES, INDEX_BYTES, LIGHT_BYTES};
    use lightgrid::passes::{GBufferFormat, DEPTH_FORMAT, HDR_FORMAT};
    let texel = |f: wgpu::TextureFormat| f.block_copy_size(None).unwrap();
    assert_eq!(texel(HDR_FORMAT), HDR_BYTES);
    assert_eq!(
        DEPTH_FORMAT.block_copy_size(Some(wgpu::TextureAspect::DepthOnly)),
        Some(DEPTH_BYTES)
    );
    for g in [GBufferFormat::F16, GBufferFormat::F32] {
        assert_eq!(texel(g.texture_format()), g.bytes_per_target());
    }
    assert_eq!(LIGHT_BYTES as usize, size_of::<GpuLight>());
    assert_eq!(INDEX_BYTES as usize, size_of::<u32>());
}
