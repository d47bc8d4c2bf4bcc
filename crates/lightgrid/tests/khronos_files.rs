//! Files made by other tools: the Khronos glTF sample models Debian ships
//! (`assimp-testmodels`, which `.ci/run` installs). Each loads and renders in every pipeline
//! as `forward` does (or is refused naming why), ClearCoatTest's labels read as labels (its
//! emissive texture applied), and every glTF 1.0 file is refused as one. Without the models
//! the tests fail, never skip.

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

#[test]
fn khronos_models_render_in_every_pipeline_as_forward() {
    for (rel, lights) in [
        ("glTF2/BoxTextured-glTF/BoxTextured.gltf", 32),
        ("glTF2/BoxTextured-glTF-Binary/BoxTextured.glb", 32),
        ("glTF2/cameras/Cameras.gltf", 16),
        ("glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb", 64),
    ] {
        let (scene, warnings) = open(rel, lights);
        assert!(warnings.is_empty(), "{rel}: {warnings:?}");
        every_pipeline_as_forward(&scene, (192, 108), 0.02);
    }
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
