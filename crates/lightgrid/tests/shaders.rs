//! Every composed shader the library can create validates with naga (no GPU needed): every
//! value of every shader key (`shader::ShaderKey::all`), with and without the adapter-dependent
//! early depth test; every shader starts with the constants prelude.

use lightgrid::consts::{MSAA_COUNTS, WGSL_CONSTS};
use lightgrid::frame::{CellBox, DepthBounds, DepthMask, DepthReduction};
use lightgrid::passes::GBufferLayout;
use lightgrid::pipelines::all_shaders;
use lightgrid::pipelines::PIPELINES;
use lightgrid::shader::{overrides, validate, validate_for, ComposedShader};

#[test]
fn every_composed_shader_validates() {
    let shaders = all_shaders();
    assert!(
        shaders.len() > PIPELINES.len(),
        "pipelines plus shared passes"
    );
    let failures: Vec<String> = shaders
        .iter()
        .flat_map(|s| [validate_for(s, true).err(), validate_for(s, false).err()])
        .flatten()
        .collect();
    assert!(
        failures.is_empty(),
        "shader validation failed:\n{}",
        failures.join("\n")
    );
}

/// The shaders of one keyed stage (labelled `"<stage> <key>"`).
fn stage<'a>(shaders: &'a [ComposedShader], stage: &str) -> Vec<&'a ComposedShader> {
    let prefix = format!("{stage} ");
    shaders
        .iter()
        .filter(|s| s.name.starts_with(&prefix))
        .collect()
}

/// Each keyed stage is composed for every value its key can take: every MSAA count the
/// renderer can request, every depth-bounds × reduction × depth mask × cell box, every G-buffer layout, each once.
#[test]
fn every_key_value_is_composed_once() {
    let shaders = all_shaders();
    let mut names = std::collections::HashSet::new();
    for s in &shaders {
        assert!(names.insert(&s.name), "{} composed twice", s.name);
    }
    let msaa = MSAA_COUNTS.len();
    let expected = [
        (
            "cell_bounds",
            msaa * DepthBounds::ALL.len()
                * DepthReduction::ALL.len()
                * DepthMask::ALL.len()
                * CellBox::ALL.len(),
        ),
        ("depth_range", msaa),
        ("tonemap", msaa),
        ("depth_samples", msaa),
        ("deferred", GBufferLayout::ALL.len() * msaa),
        ("light_prepass", msaa),
        // Each light loop (--light-loop lane, subgroup).
        ("tiled_light_prepass", 2 * msaa),
        // The grid pipelines' kernel with each light loop, and the single kernel.
        ("tiled_deferred", 3 * msaa),
        // Only above one sample per pixel.
        ("sample_expand", msaa - 1),
    ];
    for (name, count) in expected {
        let found = stage(&shaders, name);
        assert_eq!(found.len(), count, "{name}: {found:#?}");
        for samples in MSAA_COUNTS
            .iter()
            .filter(|&&n| name != "sample_expand" || n > 1)
        {
            let decl = format!("const SAMPLES: u32 = {samples}u;");
            assert!(
                found.iter().any(|s| s.source().contains(&decl)),
                "{name} at {samples} samples"
            );
        }
    }
}

/// `--depth-reduction subgroup` is the only cell-bounds variant with subgroup operations: the
/// others are created on adapters without subgroups, which must not see them even unreached.
#[test]
fn only_the_subgroup_reduction_needs_subgroups() {
    let shaders = all_shaders();
    let cell_bounds = stage(&shaders, "cell_bounds");
    let no_subgroups = naga::valid::Capabilities::all()
        - naga::valid::Capabilities::SUBGROUP
        - naga::valid::Capabilities::SUBGROUP_BARRIER;
    for s in cell_bounds {
        let module = validate(s).unwrap();
        let without =
            naga::valid::Validator::new(naga::valid::ValidationFlags::all(), no_subgroups)
                .validate(&module);
        assert_eq!(
            without.is_ok(),
            !s.name.contains("Subgroup"),
            "{}: {without:?}",
            s.name
        );
    }
}

/// The only `override`s are the pipeline specialisations named in `shader::overrides`, which
/// the pipelines set through the same names; each is declared by some shader.
#[test]
fn overrides_are_the_named_ones() {
    let mut declared = std::collections::HashSet::new();
    for s in all_shaders() {
        let module = validate(&s).unwrap();
        for (_, o) in module.overrides.iter() {
            let name = o.name.clone().unwrap_or_default();
            assert!(
                overrides::ALL.contains(&name.as_str()),
                "{}: override {name} is not in shader::overrides",
                s.name
            );
            declared.insert(name);
        }
    }
    for name in overrides::ALL {
        assert!(declared.contains(name), "no shader declares {name}");
    }
}

#[test]
fn every_pipeline_has_shaders_and_a_unique_id() {
    let mut ids = std::collections::HashSet::new();
    for p in PIPELINES {
        assert!(ids.insert(p.id), "duplicate pipeline id {}", p.id);
        assert!(!(p.shaders)().is_empty(), "{} has no shaders", p.id);
    }
    assert_eq!(PIPELINES[0].id, "forward", "the reference comes first");
    assert!(
        !PIPELINES[0].uses_grid,
        "forward must never read a light grid"
    );
}

#[test]
fn constants_come_from_the_prelude_not_typed_by_hand() {
    for s in all_shaders() {
        // The caller's WGSL has no prelude: it declares only `light_grid` names
        // (`the_embedded_modules_declare_only_prefixed_names`).
        if s.name.contains("(caller)") {
            continue;
        }
        let source = s.source();
        for (name, _) in WGSL_CONSTS {
            let decl = format!("const {name}:");
            assert_eq!(
                source.matches(&decl).count(),
                1,
                "{}: {name} must be declared exactly once (by the prelude)",
                s.name
            );
        }
    }
}

/// The light function's BRDF and falloff are written in when a module is made: a shader
/// holding it compiles only specialized, so no pipeline can shade with a default by mistake.
#[test]
fn the_light_function_compiles_only_specialized() {
    let forward = lightgrid::pipelines::find("forward").unwrap();
    let shader = &(forward.shaders)()[0];
    let raw = naga::front::wgsl::parse_str(&shader.source());
    assert!(raw.is_err(), "an unspecialized module parsed");
    for shading in lightgrid::scene::Shading::all() {
        let s = shader.specialized(shading);
        assert!(
            naga::front::wgsl::parse_str(&s.source()).is_ok(),
            "{shading:?}"
        );
    }
}

#[test]
fn a_broken_shader_is_rejected() {
    let bad = lightgrid::shader::compose("bad", &["fn f() -> f32 { return undefined_name; }"]);
    assert!(validate(&bad).is_err());
}

/// A fragment shader that may write the frame counters has a side effect, which would move the
/// depth test after shading and lose early-Z (tiled forward with pre-Z ran 2-3x slower on
/// lavapipe): every such entry point forces the early depth test.
#[test]
fn fragment_shaders_writing_the_counters_force_the_early_depth_test() {
    let mut checked = 0;
    for s in all_shaders() {
        let s = s.specialized(lightgrid::scene::Shading::default());
        let module = naga::front::wgsl::parse_str(&s.source()).unwrap();
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap();
        let Some(counters) = module
            .global_variables
            .iter()
            .find(|(_, g)| g.name.as_deref() == Some("frame_counters"))
            .map(|(h, _)| h)
        else {
            continue;
        };
        for (i, ep) in module.entry_points.iter().enumerate() {
            let writes = info.get_entry_point(i)[counters].contains(naga::valid::GlobalUse::WRITE);
            if ep.stage == naga::ShaderStage::Fragment && writes {
                assert_eq!(
                    ep.early_depth_test,
                    Some(naga::EarlyDepthTest::Force),
                    "{}::{} writes the frame counters: it needs {}",
                    s.name,
                    ep.name,
                    lightgrid::shader::EARLY_DEPTH_TEST
                );
                checked += 1;
            }
        }
    }
    assert!(
        checked >= 3,
        "forward, forward_mono and tiled forward: {checked}"
    );
}
