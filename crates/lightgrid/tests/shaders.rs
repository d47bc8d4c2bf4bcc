//! Every composed shader the registry and shared passes can produce validates with naga
//! (no GPU needed), and every shader starts with the constants prelude.

use lightgrid::consts::WGSL_CONSTS;
use lightgrid::pipelines::all_shaders;
use lightgrid::pipelines::PIPELINES;
use lightgrid::shader::validate;

#[test]
fn every_composed_shader_validates() {
    let shaders = all_shaders();
    assert!(
        shaders.len() > PIPELINES.len(),
        "pipelines plus shared passes"
    );
    let failures: Vec<String> = shaders.iter().filter_map(|s| validate(s).err()).collect();
    assert!(
        failures.is_empty(),
        "shader validation failed:\n{}",
        failures.join("\n")
    );
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
        for (name, _) in WGSL_CONSTS {
            let decl = format!("const {name}:");
            assert_eq!(
                s.source.matches(&decl).count(),
                1,
                "{}: {name} must be declared exactly once (by the prelude)",
                s.name
            );
        }
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
        let module = naga::front::wgsl::parse_str(&s.source).unwrap();
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
