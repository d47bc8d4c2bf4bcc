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
