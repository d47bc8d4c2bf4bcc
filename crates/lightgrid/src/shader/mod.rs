//! Shader composition, one way for every shader: a shader stage with variants has a **key**
//! type (a small `Copy` value: sample count, G-buffer layout, depth bounds, ...) implementing
//! [`ShaderKey`]. The key names the stage's parts (shared WGSL files then the stage's own, in
//! a fixed order, as WGSL has no includes; a group of files always used together is a slice,
//! and `parts!` splices groups and single files into one list) and
//! its [`Def`]s. A [`ComposedShader`] is the key's name, defs and parts; its text is made when
//! a module is: the constants prelude, then a WGSL `const` per def that some part names, then
//! the parts, a bool def also being the condition of `#if NAME` / `#if !NAME` ... `#else` ...
//! `#endif` lines, for what a `const` cannot select (types, attributes, or code an adapter
//! may lack, such as subgroup operations).
//!
//! Two more sets of defs join the key's when a module is made, through the same path: the
//! light function's ([`ComposedShader::specialized`], from a frame's [`Shading`]) and the
//! device's (`EARLY_DEPTH_TEST`, [`ComposedShader::source_for`]). The caller's WGSL of
//! `LightCuller::wgsl` is a key too, composed without the prelude. Every value of every key
//! ([`ShaderKey::all`]) is validated by naga in the tests (no GPU needed), in every shading
//! and with and without the early depth test.
//!
//! WGSL `override`s remain only where one module is specialised per pipeline at pipeline
//! creation (`constants`); their names come from [`overrides`].

use crate::consts::wgsl_prelude;
use crate::scene::Shading;

/// Shared WGSL sources, in the order a shader lists them. A slice is a group of files a
/// shader always takes together, in that order.
pub mod src {
    /// The structs every stage shares (light, material, frame uniforms, BVH node, ...).
    pub const TYPES: &str = include_str!("../shading/types.wgsl");
    /// `LightGridParams`, the grid's uniform (lightgrid's shaders and the caller's).
    pub const GRID_PARAMS: &str = include_str!("../culling/grid/grid_params.wgsl");
    /// Group 0 of the scene passes: frame uniforms, lights, materials, light bounds, the frame's
    /// counters and per-pixel counts.
    pub const SCENE_BINDINGS: &str = include_str!("../shading/scene_bindings.wgsl");
    /// The light function; needs the shading defs (`ComposedShader::specialized`).
    pub(crate) const LIGHT_FUNCTION: &str = include_str!("../shading/lighting.wgsl");
    /// The shadow rays and maps the light function casts and reads.
    pub(crate) const SHADOWS: &str = include_str!("../shading/shadows.wgsl");
    /// `scene_light(i)`: the light function's lights, from group 0's storage buffer.
    pub(crate) const SCENE_LIGHT: &str = include_str!("../shading/scene_light.wgsl");
    /// The light function, its lights and the shadows it casts.
    pub(crate) const LIGHTING: &[&str] = &[SCENE_LIGHT, LIGHT_FUNCTION, SHADOWS];
    pub(crate) const GEOMETRY: &str = include_str!("../passes/geometry.wgsl");
    /// Cell addressing (`light_grid_slice`, `light_grid_cell`); needs a `light_grid` binding.
    pub(crate) const GRID_CELL: &str = include_str!("../culling/grid/grid_cell.wgsl");
    /// The walk over a z-binned grid's masks.
    pub(crate) const ZBIN_WALK: &str = include_str!("../culling/grid/zbin_walk.wgsl");
    /// The group-1 grid bindings and the shading accessors.
    pub(crate) const GRID_BINDINGS: &str = include_str!("../culling/grid/light_grid.wgsl");
    /// The grid's bindings, cell addressing and z-bin walk; one of the light loops below
    /// follows it.
    pub(crate) const LIGHT_GRID: &[&str] = &[GRID_CELL, ZBIN_WALK, GRID_BINDINGS];
    /// The texture grid's bindings and accessors, and `scene_light` from its light texture
    /// (`--grid-storage textures`); follows `GRID_CELL`.
    pub(crate) const GRID_TEXELS: &str = include_str!("../culling/grid/light_grid_texels.wgsl");
    /// `light_grid_shade` and `light_grid_irradiance_mono`, one lane at a time
    /// (`--light-loop lane`).
    pub(crate) const LIGHT_LOOP_LANE: &str = include_str!("../culling/grid/light_loop_lane.wgsl");
    /// The same, scalarized over the subgroup (`--light-loop subgroup`).
    pub(crate) const LIGHT_LOOP_SUBGROUP: &str =
        include_str!("../culling/grid/light_loop_subgroup.wgsl");
    pub(crate) const LIT_OUT: &str = include_str!("../passes/lit_out.wgsl");
    /// `tone(c)`: the tone curve.
    pub(crate) const TONE: &str = include_str!("../shading/tone.wgsl");
    /// The MSAA texture types and `sample_position`; needs `super::msaa_defs`.
    pub const MSAA: &str = include_str!("msaa.wgsl");
}

/// The modules every scene-geometry shader starts with: structs, group-0 bindings, the light
/// function and the shared vertex stage.
pub(crate) const SCENE_PARTS: &[&str] = &[
    src::TYPES,
    src::GRID_PARAMS,
    src::SCENE_BINDINGS,
    src::SCENE_LIGHT,
    src::LIGHT_FUNCTION,
    src::SHADOWS,
    src::GEOMETRY,
    src::LIT_OUT,
];

/// As [`SCENE_PARTS`], with the texture grid in place of the light buffer: its bindings,
/// cell addressing and accessors, `scene_light` reading its light texture.
pub(crate) const TEXEL_SCENE_PARTS: &[&str] = &[
    src::TYPES,
    src::GRID_PARAMS,
    src::SCENE_BINDINGS,
    src::GRID_CELL,
    src::GRID_TEXELS,
    src::LIGHT_FUNCTION,
    src::SHADOWS,
    src::GEOMETRY,
    src::LIT_OUT,
];

/// One WGSL part of a shader, or a group of parts in order: what [`parts!`] splices.
pub(crate) trait Part {
    /// Append this part (or each of the group's) to `parts`.
    fn add_to(self, parts: &mut Vec<&'static str>);
}

impl Part for &'static str {
    fn add_to(self, parts: &mut Vec<&'static str>) {
        parts.push(self);
    }
}

impl Part for &'static [&'static str] {
    fn add_to(self, parts: &mut Vec<&'static str>) {
        parts.extend_from_slice(self);
    }
}

/// A shader's parts in order, from single files (`&str`) and groups (`&[&str]`).
macro_rules! parts {
    ($($part:expr),* $(,)?) => {{
        let mut parts: Vec<&'static str> = Vec::new();
        $($crate::shader::Part::add_to($part, &mut parts);)*
        parts
    }};
}
pub(crate) use parts;

/// A named shader: its key's defs and parts, composed into WGSL text when a module is made
/// ([`Self::source_for`]).
#[derive(Clone, Debug)]
pub struct ComposedShader {
    /// The label: the stage's name and key value; names the module and composition errors.
    pub name: String,
    /// Starts with the constants prelude (every shader but the caller's).
    prelude: bool,
    defs: Vec<Def>,
    parts: Vec<&'static str>,
}

/// A value a shader's key gives it: declared as a WGSL `const` before every part, and for a
/// bool, the condition of `#if` lines.
#[derive(Clone, Debug, PartialEq)]
pub enum Def {
    /// A `const NAME: bool`, also the condition of `#if NAME` / `#if !NAME` lines.
    Bool(&'static str, bool),
    /// A `const NAME: u32`.
    U32(&'static str, u32),
    /// A `const` of WGSL type `.1` and value `.2` (an array of sample positions).
    Wgsl(&'static str, String, String),
}

impl Def {
    /// The name it declares.
    pub(crate) fn name(&self) -> &'static str {
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

    /// Does the shader start with the constants prelude? Every stage of lightgrid's does; the
    /// caller's WGSL does not (it declares only `light_grid` names).
    const PRELUDE: bool = true;

    /// The composed shader of this value.
    fn shader(self) -> ComposedShader {
        ComposedShader {
            name: format!("{} {self:?}", Self::STAGE),
            prelude: Self::PRELUDE,
            defs: self.defs(),
            parts: self.parts(),
        }
    }

    /// The shaders of every value, for validation.
    fn all_shaders() -> Vec<ComposedShader> {
        Self::all().into_iter().map(Self::shader).collect()
    }
}

/// A stage whose only variant is the sample count of the targets it reads or writes: its
/// key is [`SamplesKey`], which defines the MSAA values ([`msaa_defs`]).
pub(crate) trait SampleStage: 'static {
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
pub(crate) struct SamplesKey<S> {
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

/// A shader without variants: the prelude, then the given parts in order.
pub fn compose(name: &str, parts: &[&'static str]) -> ComposedShader {
    compose_defs(name, &[], parts)
}

/// A shader with the given defs and parts (what a [`ShaderKey`] value composes).
pub(crate) fn compose_defs(name: &str, defs: &[Def], parts: &[&'static str]) -> ComposedShader {
    ComposedShader {
        name: name.to_string(),
        prelude: true,
        defs: defs.to_vec(),
        parts: parts.to_vec(),
    }
}

/// The text of a shader: the prelude (if asked), one `const` per def some part names, then the
/// parts, their `#if` lines resolved against the bool defs. A def defined twice, a condition
/// naming no bool def or an unbalanced `#if` is a bug in the shader's key or its WGSL: it
/// panics, and the validation test composes every key's every value.
fn compose_text(name: &str, prelude: bool, defs: &[Def], parts: &[&str]) -> String {
    let mut source = if prelude {
        wgsl_prelude()
    } else {
        String::new()
    };
    source.push_str("// from the shader's key\n");
    for (i, def) in defs.iter().enumerate() {
        assert!(
            defs[..i].iter().all(|d| d.name() != def.name()),
            "{name}: {} defined twice",
            def.name()
        );
        if parts.iter().any(|p| p.contains(def.name())) {
            source.push_str(&def.declaration());
        }
    }
    for part in parts {
        source.push('\n');
        preprocess(name, part, defs, &mut source);
    }
    source
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
pub(crate) fn msaa_defs(samples: u32) -> Vec<Def> {
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
pub(crate) fn every_sample_count() -> impl Iterator<Item = u32> {
    crate::consts::MSAA_COUNTS.into_iter()
}

/// The names of the WGSL `override`s: a pipeline specialises one module with them at creation
/// (`constants`). The validation test checks that the shaders declare these and no others.
pub mod overrides {
    /// `scene_bindings.wgsl`: a pipeline drawing into multisampled targets.
    pub(crate) const MULTISAMPLED: &str = "MULTISAMPLED";
    /// `lighting.wgsl`: the material shader a forward pipeline draws.
    pub(crate) const MATERIAL_SHADER: &str = "MATERIAL_SHADER";
    /// `msaa_sample_outputs.wgsl`: the deferred MSAA kernel resolving in workgroup memory.
    pub(crate) const RESOLVE_IN_KERNEL: &str = "RESOLVE_IN_KERNEL";
    /// `sample_expand.wgsl`: the frame's width in pixels.
    pub(crate) const WIDTH: &str = "WIDTH";
    /// `cell_bounds.wgsl`: invocations per workgroup, one per row of the grid's tiles.
    pub(crate) const CELL_THREADS: &str = "CELL_THREADS";
    /// `depth_texels.wgsl`: the tile edge of the texture grid's tile depth bounds.
    pub(crate) const TILE: &str = "TILE";
    /// Every override of the library's shaders.
    #[cfg_attr(not(feature = "testing"), allow(dead_code))]
    pub const ALL: [&str; 6] = [
        MULTISAMPLED,
        MATERIAL_SHADER,
        RESOLVE_IN_KERNEL,
        WIDTH,
        CELL_THREADS,
        TILE,
    ];
}

/// Parse and validate with naga, in every [`Shading`], as a device with the early depth test
/// gets it; the error message carries naga's annotated source span.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub fn validate(shader: &ComposedShader) -> Result<naga::Module, String> {
    validate_for(shader, true)
}

/// As [`validate`], the shader as `create_module` gives it to a device with or without
/// `SHADER_EARLY_DEPTH_TEST`: in every [`Shading`] (each makes other code live; one text that
/// two shadings make alike is validated once); the module of the first.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub fn validate_for(
    shader: &ComposedShader,
    early_depth_test: bool,
) -> Result<naga::Module, String> {
    let mut first = None;
    let mut seen = std::collections::HashSet::new();
    for shading in Shading::all() {
        let source = shader.specialized(shading).source_for(early_depth_test);
        if !seen.insert(source.clone()) {
            continue;
        }
        let module = validate_one(&shader.name, &source)?;
        first.get_or_insert(module);
    }
    Ok(first.expect("one at least"))
}

#[cfg_attr(not(feature = "testing"), allow(dead_code))]
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

/// The light function's defs of a shading: its BRDF, falloff, shadows, spot cone
/// (`lighting.wgsl`) and whether materials read per-sample inputs (`geometry.wgsl`).
pub(crate) fn shading_defs(shading: Shading) -> Vec<Def> {
    vec![
        Def::U32("SHADING_BRDF", shading.brdf.gpu()),
        Def::U32("SHADING_FALLOFF", shading.units.falloff()),
        Def::U32("SHADING_SHADOWS", shading.shadows_gpu()),
        Def::U32("SHADING_SPOT_CONE", shading.spot_cone.gpu()),
        Def::Bool("SHADING_MATERIAL_INPUTS", shading.material_inputs),
    ]
}

/// The device's def: does the device take `@early_depth_test(force)`
/// (`SHADER_EARLY_DEPTH_TEST`, native only: Vulkan, GLES 3.1+)?
pub(crate) const EARLY_DEPTH_TEST_DEF: &str = "EARLY_DEPTH_TEST";

/// The attribute forward fragment shaders carry, under `#if EARLY_DEPTH_TEST`, to keep early-Z
/// although they may write the frame counters (a side effect that would otherwise move the
/// depth test after shading).
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub const EARLY_DEPTH_TEST: &str = "@early_depth_test(force)";

impl ComposedShader {
    /// The same shader with more defs.
    fn with(&self, defs: Vec<Def>) -> ComposedShader {
        let mut out = self.clone();
        out.defs.extend(defs);
        out
    }

    /// The shader with the light function's defs of `shading` (`shading_defs`): every
    /// module holding the light function is made from this, and one made without them does
    /// not compile. A shader naming none of them is unchanged.
    pub fn specialized(&self, shading: Shading) -> ComposedShader {
        self.with(shading_defs(shading))
    }

    /// The text a device with `SHADER_EARLY_DEPTH_TEST` gets.
    pub fn source(&self) -> String {
        self.source_for(true)
    }

    /// The text a device gets, with the one def that depends on the adapter rather than on
    /// a key: without `SHADER_EARLY_DEPTH_TEST` the forced early depth test is left out. The
    /// image is the same (no shader carrying it discards or writes depth), only early-Z may be
    /// lost; `validate_for` checks both forms of every shader.
    pub fn source_for(&self, early_depth_test: bool) -> String {
        let device = Def::Bool(EARLY_DEPTH_TEST_DEF, early_depth_test);
        let shader = self.with(vec![device]);
        compose_text(&shader.name, shader.prelude, &shader.defs, &shader.parts)
    }
}

/// Create a wgpu shader module from a composed shader, as the device's features allow
/// ([`ComposedShader::source_for`]).
pub(crate) fn create_module(device: &wgpu::Device, shader: &ComposedShader) -> wgpu::ShaderModule {
    let early_depth_test = device
        .features()
        .contains(wgpu::Features::SHADER_EARLY_DEPTH_TEST);
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(&shader.name),
        source: wgpu::ShaderSource::Wgsl(shader.source_for(early_depth_test).into()),
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
pub(crate) fn compute_pipeline_with(
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

    fn body(source: &str) -> &str {
        let key = "// from the shader's key\n";
        &source[source.find(key).unwrap() + key.len()..]
    }

    #[test]
    fn defs_are_consts_and_select_the_if_branches() {
        let part = "a N\n#if ON\nb\n#if !OFF\nc\n#else\nd\n#endif\n#else\ne\n#endif\nf\n";
        let defs = [
            Def::Bool("ON", true),
            Def::Bool("OFF", false),
            Def::U32("N", 3),
            Def::U32("UNNAMED", 4),
        ];
        let s = compose_defs("t", &defs, &[part]).source();
        let body = body(&s);
        // A def no part names is not declared.
        assert!(body.starts_with(
            "const ON: bool = true;\nconst OFF: bool = false;\nconst N: u32 = 3u;\n\n"
        ));
        assert_eq!(body_lines(&s), ["a N", "b", "c", "f"]);
        // Directives leave empty lines: naga's spans keep the part's line numbers.
        assert_eq!(body.lines().count(), 3 + 1 + part.lines().count());
        let off = compose_defs(
            "t",
            &[Def::Bool("ON", false), Def::Bool("OFF", true)],
            &[part],
        );
        assert_eq!(body_lines(&off.source()), ["a N", "e", "f"]);
    }

    fn body_lines(s: &str) -> Vec<&str> {
        body(s)
            .lines()
            .filter(|l| !l.is_empty() && !l.starts_with("const "))
            .collect()
    }

    #[test]
    fn the_device_and_the_shading_add_their_defs() {
        let part = "@fragment\n#if EARLY_DEPTH_TEST\n@early_depth_test(force)\n#endif\nfn f() -> u32 { return SHADING_BRDF; }\n";
        let s = compose("t", &[part]);
        assert!(s.source_for(true).contains(EARLY_DEPTH_TEST));
        assert!(!s.source_for(false).contains(EARLY_DEPTH_TEST));
        assert!(!s.source().contains("const SHADING_BRDF"));
        for shading in Shading::all() {
            let text = s.specialized(shading).source();
            let decl = format!("const SHADING_BRDF: u32 = {}u;", shading.brdf.gpu());
            assert!(text.contains(&decl), "{shading:?}");
            // Only the defs the parts name.
            assert!(!text.contains("SHADING_FALLOFF"));
        }
    }

    #[test]
    #[should_panic(expected = "names no bool def")]
    fn a_condition_without_a_def_is_refused() {
        compose_defs("t", &[Def::U32("N", 1)], &["#if N\n#endif\n"]).source();
    }

    #[test]
    #[should_panic(expected = "without `#endif`")]
    fn an_unclosed_if_is_refused() {
        compose_defs("t", &[Def::Bool("ON", true)], &["#if ON\n"]).source();
    }

    #[test]
    #[should_panic(expected = "defined twice")]
    fn a_def_twice_is_refused() {
        compose_defs("t", &[Def::U32("N", 1), Def::U32("N", 2)], &[]).source();
    }

    #[test]
    fn the_msaa_defs_select_the_texture_types() {
        for samples in every_sample_count() {
            let s = compose_defs("t", &msaa_defs(samples), &[src::MSAA]);
            let text = s.source();
            let multisampled = text.contains("texture_depth_multisampled_2d");
            assert_eq!(multisampled, samples > 1, "{samples}");
            assert!(text.contains(&format!("const SAMPLES: u32 = {samples}u;")));
            validate(&s).unwrap();
        }
    }
}
