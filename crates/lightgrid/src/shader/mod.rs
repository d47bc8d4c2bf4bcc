//! Shader composition: the generated constants prelude, then shared WGSL modules, then the
//! stage file. WGSL has no includes, so a composed shader is a plain concatenation in a fixed
//! order; every composed shader is validated by naga in the tests (no GPU needed).

use crate::consts::wgsl_prelude;

/// Shared WGSL sources, in the order a shader lists them.
pub mod src {
    pub const TYPES: &str = include_str!("../shading/types.wgsl");
    pub const SCENE_BINDINGS: &str = include_str!("../shading/scene_bindings.wgsl");
    pub const LIGHTING: &str = include_str!("../shading/lighting.wgsl");
    pub const GEOMETRY: &str = include_str!("../passes/geometry.wgsl");
    /// Cell addressing (`grid_slice`, `grid_cell`); needs a `grid` binding.
    pub const GRID_CELL: &str = include_str!("../culling/grid_cell.wgsl");
    /// Group-1 grid bindings and the shading accessor (includes `GRID_CELL`).
    pub const LIGHT_GRID: &str = concat!(
        include_str!("../culling/grid_cell.wgsl"),
        include_str!("../culling/light_grid.wgsl")
    );
    pub const LIT_OUT: &str = include_str!("../passes/lit_out.wgsl");
    /// `tone(c)`: the tone curve.
    pub const TONE: &str = include_str!("../shading/tone.wgsl");
}

/// The modules every scene-geometry shader starts with: structs, group-0 bindings, the light
/// function and the shared vertex stage.
pub const SCENE_PARTS: &[&str] = &[
    src::TYPES,
    src::SCENE_BINDINGS,
    src::LIGHTING,
    src::GEOMETRY,
    src::LIT_OUT,
];

/// A named, composed WGSL shader.
#[derive(Clone, Debug)]
pub struct ComposedShader {
    pub name: String,
    pub source: String,
}

/// Prelude + the given parts, in order.
pub fn compose(name: &str, parts: &[&str]) -> ComposedShader {
    let mut source = wgsl_prelude();
    for part in parts {
        source.push('\n');
        source.push_str(part);
    }
    ComposedShader {
        name: name.to_string(),
        source,
    }
}

/// Parse and validate with naga; the error message carries naga's annotated source span.
pub fn validate(shader: &ComposedShader) -> Result<naga::Module, String> {
    let module = naga::front::wgsl::parse_str(&shader.source)
        .map_err(|e| format!("{}: {}", shader.name, e.emit_to_string(&shader.source)))?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| format!("{}: {}", shader.name, e.emit_to_string(&shader.source)))?;
    Ok(module)
}

/// WGSL of a frame's sample count, for shaders that read its multisampled targets: `SAMPLES`,
/// the texture types (`DepthTexture`, `SampleTexture`: multisampled above one sample, so
/// `textureLoad(t, p, s)` reads sample `s`, or level 0 of a plain texture at one sample) and
/// `sample_position(s)`, the standard position of sample `s` in its pixel
/// (`consts::msaa_sample_positions`).
pub fn msaa_wgsl(samples: u32) -> String {
    let ms = samples > 1;
    let positions: Vec<String> = crate::consts::msaa_sample_positions(samples)
        .iter()
        .map(|[x, y]| format!("vec2<f32>({x:?}, {y:?})"))
        .collect();
    format!(
        "const SAMPLES: u32 = {samples}u;\n\
         alias DepthTexture = {};\n\
         alias SampleTexture = {};\n\
         fn sample_position(s: u32) -> vec2<f32> {{\n\
         \x20   var positions = array<vec2<f32>, {samples}>({});\n\
         \x20   return positions[s];\n\
         }}\n",
        if ms {
            "texture_depth_multisampled_2d"
        } else {
            "texture_depth_2d"
        },
        if ms {
            "texture_multisampled_2d<f32>"
        } else {
            "texture_2d<f32>"
        },
        positions.join(", ")
    )
}

/// The attribute forward fragment shaders carry to keep early-Z although they may write the
/// frame counters (a side effect that would otherwise move the depth test after shading).
pub const EARLY_DEPTH_TEST: &str = "@early_depth_test(force)";

/// Create a wgpu shader module from a composed shader. On a device without
/// `SHADER_EARLY_DEPTH_TEST` (a native-only feature: Vulkan, GLES 3.1+) the forced early depth
/// test is dropped: the image is the same (no shader discards or writes depth), only early-Z
/// may be lost.
pub fn create_module(device: &wgpu::Device, shader: &ComposedShader) -> wgpu::ShaderModule {
    let source = if device
        .features()
        .contains(wgpu::Features::SHADER_EARLY_DEPTH_TEST)
    {
        std::borrow::Cow::Borrowed(shader.source.as_str())
    } else {
        std::borrow::Cow::Owned(shader.source.replace(EARLY_DEPTH_TEST, ""))
    };
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(&shader.name),
        source: wgpu::ShaderSource::Wgsl(source),
    })
}

/// A compute pipeline from a composed shader's `entry` point and explicit layouts.
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    shader: &ComposedShader,
    entry: &str,
    layouts: &[Option<&wgpu::BindGroupLayout>],
) -> wgpu::ComputePipeline {
    compute_pipeline_with(device, label, shader, entry, layouts, &[])
}

/// As [`compute_pipeline`], with values for the shader's `override` constants.
pub fn compute_pipeline_with(
    device: &wgpu::Device,
    label: &str,
    shader: &ComposedShader,
    entry: &str,
    layouts: &[Option<&wgpu::BindGroupLayout>],
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    let module = create_module(device, shader);
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: layouts,
        immediate_size: 0,
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&layout),
        module: &module,
        entry_point: Some(entry),
        compilation_options: wgpu::PipelineCompilationOptions {
            constants,
            ..Default::default()
        },
        cache: None,
    })
}
