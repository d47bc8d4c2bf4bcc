//! Files made by other tools: the Khronos glTF sample models Debian ships
//! (`assimp-testmodels`, which `.ci/run` installs). Every glTF 2.0 file among them loads and
//! renders in every pipeline as its reference does, `forward` equal to the CPU reference, or
//! is refused naming its problem; ClearCoatTest's labels read as labels (its emissive texture
//! applied), and every glTF 1.0 file is refused as one. Without the models the tests fail,
//! never skip.

mod common;

use lightgrid::scene::source::{self, AddLights, SceneRequest};
use lightgrid::scene::Scene;
use lightgrid::{RenderSettings, Renderer};
use std::path::{Path, PathBuf};

const MODELS: &str = "/usr/share/assimp/models";

fn model(rel: &str) -> PathBuf {
    let p = Path::new(MODELS).join(rel);
    assert!(
        p.is_file(),
        "{} is missing: install Debian's assimp-testmodels (`.ci/run` does); these tests fail, never skip",
        p.display()
    );
    p
}

/// The file with `lights` point lights scattered over it (`--add-lights`).
fn open(rel: &str, lights: u32) -> (Scene, Vec<String>) {
    let path = model(rel);
    let opened = source::open(&SceneRequest {
        add_lights: Some(AddLights {
            count: lights,
            range: None,
        }),
        ..SceneRequest::new(path.to_str().unwrap())
    })
    .unwrap_or_else(|e| panic!("{rel}: {e}"));
    (opened.scene, opened.warnings)
}

fn render(r: &mut Renderer, scene: &Scene, pipeline: &str) -> lightgrid::Result<image::RgbaImage> {
    r.render(scene, 0, pipeline).map(|o| o.image)
}

/// Every pipeline against its reference (`forward`, or `forward_mono` for the mono
/// variants): at most `share` of the pixels over 8 levels (edges of thin geometry land a
/// pixel over between rasterization orders).
fn every_pipeline_as_forward(scene: &Scene, size: (u32, u32), share: f64) {
    let ctx = common::gpu();
    let mut r = Renderer::new(&ctx, size.0, size.1, RenderSettings::default()).unwrap();
    let mut images = std::collections::HashMap::new();
    for info in lightgrid::pipelines::PIPELINES {
        let image = render(&mut r, scene, info.id)
            .unwrap_or_else(|e| panic!("{}: {}: {e}", scene.name, info.id));
        images.insert(info.id, image);
    }
    for info in lightgrid::pipelines::PIPELINES {
        let over = common::pixels_over(&images[info.reference], &images[info.id], 8) as f64;
        let all = f64::from(size.0 * size.1);
        assert!(
            over <= all * share,
            "{}: {}: {over} of {all} pixels over 8 levels from {}",
            scene.name,
            info.id,
            info.reference
        );
    }
}

#[test]
fn clear_coat_tests_labels_read_as_labels() {
    let (scene, warnings) = open("glTF2/ClearCoat-glTF/ClearCoatTest.gltf", 64);
    // Its clear coat is an extension lightgrid names and does not apply.
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("KHR_materials_clearcoat is not read")),
        "{warnings:?}"
    );
    // The size the issue reads them at (at 320x180 the strokes blur into the bars).
    let size = (640, 360);
    let ctx = common::gpu();
    let mut r = Renderer::new(&ctx, size.0, size.1, RenderSettings::default()).unwrap();
    let labelled = render(&mut r, &scene, "forward").unwrap();
    // The same without the emissive texture: the labels' white emissive factor alone, a
    // solid bar each (what lightgrid drew before it read emissive textures).
    let mut bars = scene.clone();
    for m in &mut bars.materials {
        m.emissive_texture = None;
    }
    let barred = render(&mut r, &bars, "forward").unwrap();
    let bright = |p: &image::Rgba<u8>| p.0[..3].iter().all(|&c| c >= 200);
    let dark = |p: &image::Rgba<u8>| p.0[..3].iter().all(|&c| c < 150);
    let bar_pixels: Vec<(u32, u32)> = barred
        .enumerate_pixels()
        .filter(|(_, _, p)| bright(p))
        .map(|(x, y, _)| (x, y))
        .collect();
    let text = bar_pixels
        .iter()
        .filter(|&&(x, y)| dark(labelled.get_pixel(x, y)))
        .count();
    assert!(bar_pixels.len() > 300, "{} bar pixels", bar_pixels.len());
    // The strokes are thin at this size: 221 of 3,535 (6%) when measured; the bars drawn
    // without the texture have none.
    assert!(
        text * 33 >= bar_pixels.len(),
        "{text} of {} label pixels show dark text",
        bar_pixels.len()
    );
    every_pipeline_as_forward(&scene, (320, 180), 0.02);
}

/// The glTF 2.0 models Debian ships that lightgrid refuses, each with what its message names.
const REFUSED: &[(&str, &str)] = &[
    (
        "BoxTextured-glTF-techniqueWebGL/BoxTextured.gltf",
        "requires extension KHR_technique_webgl",
    ),
    (
        "BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb",
        "NaN or infinite coordinate",
    ),
    (
        "IndexOutOfRange/AllIndicesOutOfRange.gltf",
        "index 65535 (accessor 0) is out of range",
    ),
    (
        "IndexOutOfRange/IndexOutOfRange.gltf",
        "index 255 (accessor 0) is out of range",
    ),
    (
        "MissingBin/BoxTextured.gltf",
        "BoxTextured0.bin: No such file",
    ),
    (
        "RecursiveNodes/RecursiveNodes.gltf",
        "the node graph has a cycle",
    ),
    (
        "SchemaFailures/sceneWrongType.gltf",
        "malformed JSON: invalid type: string \"hello\"",
    ),
    (
        "TestNoRootNode/NoScene.gltf",
        "the default scene 0 does not exist",
    ),
    (
        "TestNoRootNode/SceneWithoutNodes.gltf",
        "no triangles to render",
    ),
    (
        "draco/2CylinderEngine.gltf",
        "requires extension KHR_draco_mesh_compression",
    ),
    ("wrongTypes/badArray.gltf", "expected a sequence"),
    (
        "wrongTypes/badExtension.gltf",
        "expected struct TextureTransform",
    ),
    (
        "wrongTypes/badNumber.gltf",
        "\"not a number\", expected f32",
    ),
    ("wrongTypes/badObject.gltf", "expected an array of length 4"),
    ("wrongTypes/badUint.gltf", "integer `-1`, expected usize"),
];

/// `forward` against the reference that reads the file itself (`common::file_reference`),
/// every 2nd pixel within a level; the lights lightgrid added, its exposure and (for a file
/// without a perspective camera) the view it fitted are handed over, being lightgrid's
/// choices rather than the file's. How many pixels it judged (some, or the test fails).
fn equals_the_files_reference(path: &Path, scene: &Scene) -> usize {
    let size = (160, 90);
    let state = scene.frame(0);
    let exposure = f64::from(scene.lighting.exposure);
    let mut reference = common::file_reference::FileReference::open(path, size, exposure);
    if !reference.has_camera() {
        let c = &state.camera;
        let (eye, target, up) = (c.eye.as_dvec3(), c.target.as_dvec3(), c.up.as_dvec3());
        reference.set_camera(eye, target, up, f64::from(c.fov_y), f64::from(c.near));
    }
    for l in &state.lights {
        assert!(l.spot.is_none(), "added lights are points");
        let radiant = (l.color * l.intensity).as_dvec3();
        reference.add_point_light(l.position.as_dvec3(), radiant, f64::from(l.range));
    }
    let ctx = common::gpu();
    let mut r = Renderer::new(&ctx, size.0, size.1, RenderSettings::default()).unwrap();
    let image = render(&mut r, scene, "forward").unwrap();
    let checked = common::file_reference::compare(&reference, &image, 2, 1);
    assert!(checked > 0, "{}: no pixel judged", path.display());
    checked
}

/// Every `.gltf` and `.glb` under `dir`, sorted.
fn gltf_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            out.extend(gltf_files(&p));
        } else if p.extension().is_some_and(|e| e == "gltf" || e == "glb") {
            out.push(p);
        }
    }
    out.sort();
    out
}

#[test]
fn every_gltf_2_model_renders_as_forward_or_is_refused_naming_why() {
    let root = model("glTF2/BoxTextured-glTF/BoxTextured.gltf")
        .parent()
        .unwrap()
        .parent()
        .unwrap()
        .to_path_buf();
    let (mut rendered, mut refused) = (0, 0);
    for path in gltf_files(&root) {
        let rel = path
            .strip_prefix(&root)
            .unwrap()
            .to_str()
            .unwrap()
            .to_string();
        // The Asset Generator's points and lines: nothing to draw, said so.
        let points = rel.contains("Mesh_PrimitiveMode_")
            && ["00", "01", "02", "03", "07", "08", "09", "10"]
                .iter()
                .any(|n| rel.ends_with(&format!("_{n}.gltf")));
        let want_refusal = REFUSED
            .iter()
            .find(|(r, _)| *r == rel)
            .map(|(_, needle)| *needle)
            .or(points.then_some("its primitives are points and lines"));
        let opened = source::open(&SceneRequest {
            add_lights: Some(AddLights {
                count: 24,
                range: None,
            }),
            ..SceneRequest::new(path.to_str().unwrap())
        });
        match (opened, want_refusal) {
            (Err(e), Some(needle)) => {
                let e = e.to_string();
                assert!(
                    e.contains(needle),
                    "{rel}: refused as {e:?}, not naming {needle:?}"
                );
                refused += 1;
            }
            (Err(e), None) => panic!("{rel}: refused: {e}"),
            (Ok(_), Some(needle)) => panic!("{rel}: loaded, but should be refused ({needle})"),
            (Ok(opened), None) => {
                for w in &opened.warnings {
                    eprintln!("{rel}: warning: {w}");
                }
                let start = std::time::Instant::now();
                every_pipeline_as_forward(&opened.scene, (160, 90), 0.02);
                // Every 4th pixel against the CPU reference; a textured model may have none
                // it judges (texture edges, minified textures), an untextured one must.
                let ctx = common::gpu();
                let checked = common::shading::check(&ctx, &opened.scene, 0, (160, 90), 4);
                let untextured = opened.scene.textures.is_empty();
                assert!(
                    checked.pixels > 0 || !untextured,
                    "{rel}: no pixel checked against the reference"
                );
                let by_file = if untextured {
                    format!(
                        ", {} the reference that reads the file",
                        equals_the_files_reference(&path, &opened.scene)
                    )
                } else {
                    String::new()
                };
                eprintln!(
                    "{rel}: rendered; {} pixels equal the CPU reference{by_file} ({:.1} s)",
                    checked.pixels,
                    start.elapsed().as_secs_f64()
                );
                rendered += 1;
            }
        }
    }
    eprintln!("{rendered} glTF 2.0 models rendered, {refused} refused naming why");
    assert_eq!(
        refused,
        REFUSED.len() + 8,
        "every refusal in the table was met"
    );
    assert!(rendered >= 20, "{rendered} rendered");
}

#[test]
fn every_gltf_1_file_is_refused_as_one() {
    let mut files = Vec::new();
    for dir in std::fs::read_dir(
        model("glTF/TwoBoxes/TwoBoxes.gltf")
            .parent()
            .unwrap()
            .parent()
            .unwrap(),
    )
    .unwrap()
    {
        for f in std::fs::read_dir(dir.unwrap().path()).unwrap() {
            let p = f.unwrap().path();
            if p.extension().is_some_and(|e| e == "gltf") {
                files.push(p);
            }
        }
    }
    assert!(files.len() >= 5, "{files:?}");
    for f in files {
        let e = source::open(&SceneRequest::new(f.to_str().unwrap()))
            .err()
            .unwrap_or_else(|| panic!("{} loaded", f.display()))
            .to_string();
        assert!(
            e.contains("a glTF 1") && e.contains("only glTF 2.0 is read"),
            "{}: {e}",
            f.display()
        );
    }
}
