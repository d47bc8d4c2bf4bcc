//! Shader composition, one way for every shader: a shader stage with variants has a **key**
//! type (a small `Copy` value: sample count, G-buffer layout, depth bounds, ...) implementing
//! [`ShaderKey`]. The key names the stage's parts (its imports: shared WGSL modules then the
//! stage file, in a fixed order, as WGSL has no includes) and its [`Def`]s; [`compose_defs`]
//! declares every def as a WGSL `const` after the constants prelude, and a bool def is also
//! the condition of `#if NAME` / `#if !NAME` ... `#else` ... `#endif` lines in the parts, for
//! what a `const` cannot select (types, or code an adapter may lack, such as subgroup
//! operations). Every value of every key ([`ShaderKey::all`]) is validated by naga in the
//! tests (no GPU needed), with and without the adapter-dependent early depth test.
//!
//! WGSL `override`s remain only where one module is specialised per pipeline at pipeline
//! creation (`constants`); their names come from [`overrides`].

use crate::consts::wgsl_prelude;
use crate::scene::Shading;

/// Shared WGSL sources, in the order a shader lists them.
pub mod src {
    pub const TYPES: &str = include_str!("../shading/types.wgsl");
    pub const SCENE_BINDINGS: &str = include_str!("../shading/scene_bindings.wgsl");
    /// The light function and the shadow rays it casts.
    pub const LIGHTING: &str = concat!(
        include_str!("../shading/lighting.wgsl"),
        include_str!("../shading/shadows.wgsl")
    );
    pub const GEOMETRY: &str = include_str!("../passes/geometry.wgsl");
    /// Cell addressing (`grid_slice`, `grid_cell`); needs a `grid` binding.
    pub const GRID_CELL: &str = include_str!("../culling/grid/grid_cell.wgsl");
    /// Group-1 grid bindings and the shading accessor (includes `GRID_CELL`).
    /// The grid's bindings, cell addressing and z-bin walk; one of the light loops below
    /// follows it.
    pub const LIGHT_GRID: &str = concat!(
        include_str!("../culling/grid/grid_cell.wgsl"),
        include_str!("../culling/grid/zbin_walk.wgsl"),
        include_str!("../culling/grid/light_grid.wgsl")
    );
    /// The walk over a z-binned grid (in `LIGHT_GRID`; renamed for a LightCuller's caller).
    pub const ZBIN_WALK: &str = include_str!("../culling/grid/zbin_walk.wgsl");
    /// `grid_shade` and `grid_irradiance_mono`, one lane at a time (`--light-loop lane`).
    pub const LIGHT_LOOP_LANE: &str = include_str!("../culling/grid/light_loop_lane.wgsl");
    /// The same, scalarized over the subgroup (`--light-loop subgroup`).
    pub const LIGHT_LOOP_SUBGROUP: &str = include_str!("../culling/grid/light_loop_subgroup.wgsl");
    pub const LIT_OUT: &str = include_str!("../passes/lit_out.wgsl");
    /// `tone(c)`: the tone curve.
    pub const TONE: &str = include_str!("../shading/tone.wgsl");
    /// The MSAA texture types and `sample_position`; needs [`super::msaa_defs`].
    pub const MSAA: &str = include_str!("msaa.wgsl");
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

/// A value a shader's key gives it: declared as a WGSL `const` before every part, and for a
/// bool, the condition of `#if` lines.
#[derive(Clone, Debug, PartialEq)]
pub enum Def {
    Bool(&'static str, bool),
    U32(&'static str, u32),
    /// A `const` of WGSL type `.1` and value `.2` (an array of sample positions).
    Wgsl(&'static str, String, String),
}

impl Def {
    fn name(&self) -> &'static str {
        match self {
            Def::Bool(name, _) | Def::U32(name, _) | Def::Wgsl(name, _, _) => name,
        }
    }

    fn declaration(&self) -> String {
        match self {
            Def::Bool(name, v) => format!("const {name}: bool = {v};\n"),
            Def::U32(name, v) => format!("const {name}: u32 = {v}u;\n"),
            Def::Wgsl(name, ty, v) => format!("const {name}: {ty} = {v};\n"),
        }
    }
}

/// A shader stage's key: every value the renderer can ask for names one composed shader.
pub trait ShaderKey: Copy + std::fmt::Debug + 'static {
    /// The stage's name (the shader's label, the key's value appended).
    const STAGE: &'static str;

    /// Every value the code can request (the validation test composes each).
    fn all() -> Vec<Self>;

    /// The values this key defines (WGSL `const`s, conditions of `#if`).
    fn defs(self) -> Vec<Def>;

    /// The WGSL parts after the prelude and the defs, in order.
    fn parts(self) -> Vec<&'static str>;

    /// The composed shader of this value.
    fn shader(self) -> ComposedShader {
        compose_defs(
            &format!("{} {self:?}", Self::STAGE),
            &self.defs(),
            &self.parts(),
        )
    }

    /// The shaders of every value, for validation.
    fn all_shaders() -> Vec<ComposedShader> {
        Self::all().into_iter().map(Self::shader).collect()
    }
}

/// A stage whose only variant is the sample count of the targets it reads or writes: its
/// key is [`SamplesKey`], which defines the MSAA values ([`msaa_defs`]).
pub trait SampleStage: 'static {
    /// The stage's name (the shader's label).
    const STAGE: &'static str;

    /// The WGSL parts after the prelude and the defs, for `samples` samples per pixel.
    fn parts(samples: u32) -> Vec<&'static str>;

    /// Does the renderer ask for the stage at `samples` samples per pixel? Every count unless
    /// the stage says otherwise.
    fn requested(samples: u32) -> bool {
        let _ = samples;
        true
    }
}

/// The key of a [`SampleStage`]: the sample count.
pub struct SamplesKey<S> {
    pub samples: u32,
    stage: std::marker::PhantomData<fn() -> S>,
}

impl<S> SamplesKey<S> {
    pub fn new(samples: u32) -> Self {
        SamplesKey {
            samples,
            stage: std::marker::PhantomData,
        }
    }
}

impl<S> Clone for SamplesKey<S> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<S> Copy for SamplesKey<S> {}

impl<S> std::fmt::Debug for SamplesKey<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{{ samples: {} }}", self.samples)
    }
}

impl<S: SampleStage> ShaderKey for SamplesKey<S> {
    const STAGE: &'static str = S::STAGE;

    fn all() -> Vec<Self> {
        every_sample_count()
            .filter(|&n| S::requested(n))
            .map(Self::new)
            .collect()
    }

    fn defs(self) -> Vec<Def> {
        msaa_defs(self.samples)
    }

    fn parts(self) -> Vec<&'static str> {
        S::parts(self.samples)
    }
}

/// Prelude + the given parts, in order (a shader without variants).
pub fn compose(name: &str, parts: &[&str]) -> ComposedShader {
    compose_defs(name, &[], parts)
}

/// Prelude, one `const` per def, then the parts, their `#if` lines resolved against the bool
/// defs. A condition naming no bool def, or an unbalanced `#if`, is a bug in the shader's key
/// or its WGSL: it panics, and the validation test composes every key's every value.
pub fn compose_defs(name: &str, defs: &[Def], parts: &[&str]) -> ComposedShader {
    let mut source = wgsl_prelude();
    source.push_str("// from the shader's key\n");
    for (i, def) in defs.iter().enumerate() {
        assert!(
            defs[..i].iter().all(|d| d.name() != def.name()),
            "{name}: {} defined twice",
            def.name()
        );
        source.push_str(&def.declaration());
    }
    for part in parts {
        source.push('\n');
        preprocess(name, part, defs, &mut source);
    }
    ComposedShader {
        name: name.to_string(),
        source,
    }
}

/// Append `part` to `out`, keeping the lines whose `#if` conditions hold. A directive line
/// becomes an empty line, so naga's error spans keep the part's line numbers.
fn preprocess(name: &str, part: &str, defs: &[Def], out: &mut String) {
    // One entry per open `#if`: (this branch is kept, the enclosing lines are kept).
    let mut open: Vec<(bool, bool)> = Vec::new();
    let kept = |open: &[(bool, bool)]| open.last().is_none_or(|&(branch, outer)| branch && outer);
    for line in part.lines() {
        let directive = line.trim();
        if let Some(cond) = directive.strip_prefix("#if ") {
            let (negated, flag) = match cond.trim().strip_prefix('!') {
                Some(flag) => (true, flag.trim()),
                None => (false, cond.trim()),
            };
            let value = defs.iter().find_map(|d| match d {
                Def::Bool(n, v) if *n == flag => Some(*v),
                _ => None,
            });
            let Some(value) = value else {
                panic!("{name}: `#if {cond}` names no bool def of the shader's key");
            };
            let outer = kept(&open);
            open.push((value != negated, outer));
        } else if directive == "#else" {
            let Some(top) = open.last_mut() else {
                panic!("{name}: `#else` without `#if`");
            };
            top.0 = !top.0;
        } else if directive == "#endif" {
            if open.pop().is_none() {
                panic!("{name}: `#endif` without `#if`");
            }
        } else if directive.starts_with('#') {
            panic!("{name}: unknown directive `{directive}`");
        } else if kept(&open) {
            out.push_str(line);
        }
        out.push('\n');
    }
    assert!(open.is_empty(), "{name}: `#if` without `#endif`");
}

/// The defs of a frame's sample count, for shaders that read its multisampled targets (with
/// [`src::MSAA`]): `SAMPLES`, `MULTISAMPLED_TARGETS` (the texture types) and
/// `SAMPLE_POSITIONS`, the standard positions (`consts::msaa_sample_positions`).
pub fn msaa_defs(samples: u32) -> Vec<Def> {
    let positions: Vec<String> = crate::consts::msaa_sample_positions(samples)
        .iter()
        .map(|[x, y]| format!("vec2<f32>({x:?}, {y:?})"))
        .collect();
    let ty = format!("array<vec2<f32>, {samples}>");
    vec![
        Def::U32("SAMPLES", samples),
        Def::Bool("MULTISAMPLED_TARGETS", samples > 1),
        Def::Wgsl(
            "SAMPLE_POSITIONS",
            ty.clone(),
            format!("{ty}({})", positions.join(", ")),
        ),
    ]
}

/// Every MSAA count the renderer can request (`consts::MSAA_COUNTS`), for the keys' `all()`.
pub fn every_sample_count() -> impl Iterator<Item = u32> {
    crate::consts::MSAA_COUNTS.into_iter()
}

/// The names of the WGSL `override`s: a pipeline specialises one module with them at creation
/// (`constants`). The validation test checks that the shaders declare these and no others.
pub mod overrides {
    /// `scene_bindings.wgsl`: a pipeline drawing into multisampled targets.
    pub const MULTISAMPLED: &str = "MULTISAMPLED";
    /// `lighting.wgsl`: the material shader a forward pipeline draws.
    pub const MATERIAL_SHADER: &str = "MATERIAL_SHADER";
    /// `msaa_sample_outputs.wgsl`: the deferred MSAA kernel resolving in workgroup memory.
    pub const RESOLVE_IN_KERNEL: &str = "RESOLVE_IN_KERNEL";
    /// `sample_expand.wgsl`: the frame's width in pixels.
    pub const WIDTH: &str = "WIDTH";
    /// `cell_bounds.wgsl`: invocations per workgroup, one per row of the grid's tiles.
    pub const CELL_THREADS: &str = "CELL_THREADS";
    /// Every override of the library's shaders.
    pub const ALL: [&str; 5] = [
        MULTISAMPLED,
        MATERIAL_SHADER,
        RESOLVE_IN_KERNEL,
        WIDTH,
        CELL_THREADS,
    ];
}

/// Parse and validate with naga; the error message carries naga's annotated source span.
pub fn validate(shader: &ComposedShader) -> Result<naga::Module, String> {
    validate_source(&shader.name, &shader.source)
}

/// As [`validate`], the shader as [`create_module`] gives it to a device with or without
/// `SHADER_EARLY_DEPTH_TEST`.
pub fn validate_for(
    shader: &ComposedShader,
    early_depth_test: bool,
) -> Result<naga::Module, String> {
    validate_source(&shader.name, &shader.source_for(early_depth_test))
}

/// Parse and validate, the shader in every [`Shading`] (each makes other code live; one
/// source that two shadings make alike is validated once); the module of the first.
fn validate_source(name: &str, source: &str) -> Result<naga::Module, String> {
    let mut first = None;
    let mut seen = std::collections::HashSet::new();
    for shading in Shading::all() {
        let specialized = specialize(source, shading);
        if !seen.insert(specialized.clone()) {
            continue;
        }
        let module = validate_one(name, &specialized)?;
        first.get_or_insert(module);
    }
    Ok(first.expect("one at least"))
}

fn validate_one(name: &str, source: &str) -> Result<naga::Module, String> {
    let module = naga::front::wgsl::parse_str(source)
        .map_err(|e| format!("{name}: {}", e.emit_to_string(source)))?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| format!("{name}: {}", e.emit_to_string(source)))?;
    Ok(module)
}

/// The placeholders `lighting.wgsl` declares its BRDF and falloff with.
const SHADING_BRDF_VALUE: &str = "SHADING_BRDF_VALUE";
const SHADING_FALLOFF_VALUE: &str = "SHADING_FALLOFF_VALUE";
const SHADING_SHADOWS_VALUE: &str = "SHADING_SHADOWS_VALUE";
const SHADING_MATERIAL_INPUTS_VALUE: &str = "SHADING_MATERIAL_INPUTS_VALUE";
const SHADING_SPOT_CONE_VALUE: &str = "SHADING_SPOT_CONE_VALUE";

fn specialize(source: &str, shading: Shading) -> String {
    source
        .replace(SHADING_BRDF_VALUE, &format!("{}u", shading.brdf.gpu()))
        .replace(
            SHADING_FALLOFF_VALUE,
            &format!("{}u", shading.units.falloff()),
        )
        .replace(
            SHADING_SHADOWS_VALUE,
            &format!("{}u", shading.shadows_gpu()),
        )
        .replace(
            SHADING_SPOT_CONE_VALUE,
            &format!("{}u", shading.spot_cone.gpu()),
        )
        .replace(
            SHADING_MATERIAL_INPUTS_VALUE,
            if shading.material_inputs {
                "true"
            } else {
                "false"
            },
        )
}

/// The attribute forward fragment shaders carry to keep early-Z although they may write the
/// frame counters (a side effect that would otherwise move the depth test after shading).
pub const EARLY_DEPTH_TEST: &str = "@early_depth_test(force)";

impl ComposedShader {
    /// The shader with the light function's BRDF and falloff written in (`lighting.wgsl`'s
    /// `SHADING_BRDF` and `SHADING_FALLOFF`): every module holding the light function is made
    /// from this, and one made without it does not compile. A shader without the light
    /// function is unchanged.
    pub fn specialized(&self, shading: Shading) -> ComposedShader {
        ComposedShader {
            name: self.name.clone(),
            source: specialize(&self.source, shading),
        }
    }

    /// The source a device gets. The one edit that depends on the adapter rather than on a
    /// key: without `SHADER_EARLY_DEPTH_TEST` (a native-only feature: Vulkan, GLES 3.1+) the
    /// forced early depth test is dropped. The image is the same (no shader carrying it
    /// discards or writes depth), only early-Z may be lost. It stays a text edit, not a def,
    /// because WGSL has no conditional attribute and an `#if` around each of the entry points
    /// carrying it would double them; [`validate_for`] checks both forms of every shader.
    pub fn source_for(&self, early_depth_test: bool) -> std::borrow::Cow<'_, str> {
        if early_depth_test {
            std::borrow::Cow::Borrowed(self.source.as_str())
        } else {
            std::borrow::Cow::Owned(self.source.replace(EARLY_DEPTH_TEST, ""))
        }
    }
}

/// Create a wgpu shader module from a composed shader, as the device's features allow
/// ([`ComposedShader::source_for`]).
pub fn create_module(device: &wgpu::Device, shader: &ComposedShader) -> wgpu::ShaderModule {
    let early_depth_test = device
        .features()
        .contains(wgpu::Features::SHADER_EARLY_DEPTH_TEST);
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(&shader.name),
        source: wgpu::ShaderSource::Wgsl(shader.source_for(early_depth_test)),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn body(shader: &ComposedShader) -> &str {
        let key = "// from the shader's key\n";
        &shader.source[shader.source.find(key).unwrap() + key.len()..]
    }

    #[test]
    fn defs_are_consts_and_select_the_if_branches() {
        let part = "a\n#if ON\nb\n#if !OFF\nc\n#else\nd\n#endif\n#else\ne\n#endif\nf\n";
        let defs = [
            Def::Bool("ON", true),
            Def::Bool("OFF", false),
            Def::U32("N", 3),
        ];
        let s = compose_defs("t", &defs, &[part]);
        let body = body(&s);
        assert!(body
            .starts_with("const ON: bool = true;\nconst OFF: bool = false;\nconst N: u32 = 3u;\n"));
        assert_eq!(body_lines(&s), ["a", "b", "c", "f"]);
        // Directives leave empty lines: naga's spans keep the part's line numbers.
        assert_eq!(body.lines().count(), defs.len() + 1 + part.lines().count());
        let off = compose_defs(
            "t",
            &[Def::Bool("ON", false), Def::Bool("OFF", true)],
            &[part],
        );
        assert_eq!(body_lines(&off), ["a", "e", "f"]);
    }

    fn body_lines(s: &ComposedShader) -> Vec<&str> {
        body(s)
            .lines()
            .filter(|l| !l.is_empty() && !l.starts_with("const "))
            .collect()
    }

    #[test]
    #[should_panic(expected = "names no bool def")]
    fn a_condition_without_a_def_is_refused() {
        compose_defs("t", &[Def::U32("N", 1)], &["#if N\n#endif\n"]);
    }

    #[test]
    #[should_panic(expected = "without `#endif`")]
    fn an_unclosed_if_is_refused() {
        compose_defs("t", &[Def::Bool("ON", true)], &["#if ON\n"]);
    }

    #[test]
    #[should_panic(expected = "defined twice")]
    fn a_def_twice_is_refused() {
        compose_defs("t", &[Def::U32("N", 1), Def::U32("N", 2)], &[]);
    }

    #[test]
    fn the_msaa_defs_select_the_texture_types() {
        for samples in every_sample_count() {
            let s = compose_defs("t", &msaa_defs(samples), &[src::MSAA]);
            let multisampled = s.source.contains("texture_depth_multisampled_2d");
            assert_eq!(multisampled, samples > 1, "{samples}");
            assert!(s
                .source
                .contains(&format!("const SAMPLES: u32 = {samples}u;")));
            validate(&s).unwrap();
        }
    }
}
