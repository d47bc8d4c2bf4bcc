//! `forward`, the reference every pipeline is compared with, checked against a shading
//! reference it did not produce: a CPU ray caster and the light function written here from
//! the papers' formulas and the shaders' documented contract (Blinn-Phong from a point or spot
//! light with a finite range, tiled-shading §1.1: the window (1 - (d/r)²)², a smoothstep
//! between a spot's outer and inner cones; the material shaders' grazing terms; the ambient
//! and emissive base; glass blended back to front over the opaque colour; the tone curve
//! 1 - e^(-x·exposure); sRGB encoding), not generated from the WGSL.
//!
//! At sampled pixels whose surface is unambiguous (the rays a third of a pixel around the
//! centre meet the same triangles, no second surface within 0.1 % of the depth, not a
//! texture), every channel of `forward`, `forward_mono` and `forward_mono_albedo` must be
//! within one level of the reference, on every catalog scene (with spots and headlights, every
//! material shader and the glass), on the test glTF room and on a catalog scene exported to
//! GLB and loaded back. A plane under one light, worked out by hand, checks the reference
//! itself.

mod common;

use common::shading::{check, check_brdf, display, Frame, Model};
use glam::Vec3;
use lightgrid::consts::SCENE_AMBIENT;
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::scene::{
    Brdf, CameraPath, Light, LightUnits, Lighting, Material, Mesh, Object, Scene, SceneLight,
};
use lightgrid::{RenderSettings, Renderer};

#[test]
fn forward_equals_the_reference_on_every_catalog_scene() {
    let ctx = common::gpu();
    let (mut glass, mut shaders) = (0, [0; 3]);
    for info in catalog::SCENES {
        let name = info.name;
        let params = SceneParams {
            spot_fraction: 0.3,
            headlights: info.robots,
            lights: info.variable_lights.then_some(300),
            ..Default::default()
        };
        let scene = catalog::build(name, &params).unwrap();
        let frame = scene.frame_count() / 3;
        let c = check(&ctx, &scene, frame, (160, 96), 5);
        eprintln!("{name} frame {frame}: {c:?}");
        assert!(c.pixels >= 150, "{name}: too few clean pixels: {c:?}");
        assert!(c.lit * 4 >= c.pixels, "{name}: too few lit pixels: {c:?}");
        glass += c.glass;
        for (all, n) in shaders.iter_mut().zip(c.shaders) {
            *all += n;
        }
    }
    // Every material shader and the glass were among the pixels checked.
    assert!(
        glass > 0 && shaders.iter().all(|&n| n > 0),
        "glass {glass}, shaders {shaders:?}"
    );
}

#[test]
fn forward_equals_the_reference_on_a_gltf_room() {
    let ctx = common::gpu();
    let bytes = common::gltf_fixture::room().glb();
    let opts = lightgrid::scene::gltf::LoadOptions::default();
    let scene = lightgrid::scene::gltf::load_bytes(&bytes, "room.glb", None, &opts)
        .unwrap()
        .scene;
    for frame in [0, scene.frame_count() / 2] {
        let c = check(&ctx, &scene, frame, (160, 96), 4);
        eprintln!("room frame {frame}: {c:?}");
        assert!(c.pixels >= 150 && c.lit * 4 >= c.pixels, "{c:?}");
        assert!(c.glass > 0, "no pixel behind the room's glass: {c:?}");
    }
}

/// The second glTF file: a catalog scene with spots and headlights written as GLB by
/// `gltf::export` and read back, so the importer's path (nodes, materials from `extras`,
/// KHR_lights_punctual spots, the exported camera) feeds the frame the reference checks.
#[test]
fn forward_equals_the_reference_on_an_exported_and_loaded_scene() {
    let ctx = common::gpu();
    let params = SceneParams {
        spot_fraction: 0.3,
        headlights: true,
        ..Default::default()
    };
    let original = catalog::build("robots-few", &params).unwrap();
    let bytes = lightgrid::scene::gltf::export(&original, 120, (160, 96)).unwrap();
    let opts = lightgrid::scene::gltf::LoadOptions::default();
    let scene = lightgrid::scene::gltf::load_bytes(&bytes, "robots-few.glb", None, &opts)
        .unwrap()
        .scene;
    let c = check(&ctx, &scene, 0, (160, 96), 4);
    eprintln!("exported robots-few: {c:?}");
    assert!(c.pixels >= 150 && c.lit * 4 >= c.pixels, "{c:?}");
}

/// A plane under one light, worked out by hand: the reference (and `forward`) at three
/// points against the formulas written out.
#[test]
fn a_plane_under_one_light_has_the_radiance_worked_out_by_hand() {
    let ctx = common::gpu();
    const EYE: Vec3 = Vec3::new(0.0, 10.0, 4.0);
    let (height, range, intensity) = (2.0f32, 5.0f32, 3.0f32);
    let material = Material::plain(Vec3::new(0.8, 0.5, 0.2), 0.25, 16.0);
    let light = Light::point(Vec3::new(0.0, height, 0.0), Vec3::ONE, intensity, range);
    // Looking down at the point under the light from above and to the side.
    let scene = one_plane(material, vec![light], EYE, Vec3::ZERO, Lighting::default());
    let f = Frame::new(&scene, 0, (64, 64));
    let mut r = Renderer::new(&ctx, 64, 64, RenderSettings::default()).unwrap();
    let image = r.render(&scene, 0, "forward").unwrap().image;
    // At the ground point p under pixel (px, py): the light at distance d, the eye at e.
    let clean: Vec<(u32, u32)> = [
        (20u32, 40u32),
        (40, 24),
        (50, 12),
        (28, 30),
        (36, 44),
        (12, 20),
    ]
    .into_iter()
    .filter(|&(x, y)| f.reference(x, y, Model::Full).is_some())
    .collect();
    assert!(clean.len() >= 3, "{clean:?}");
    for (px, py) in clean {
        let d = f.ray(f64::from(px) + 0.5, f64::from(py) + 0.5);
        let eye = EYE;
        let t = f64::from(eye.y) / -d.y;
        let p = eye + (d * t).as_vec3();
        let to_light = Vec3::new(0.0, height, 0.0) - p;
        let dist = to_light.length();
        let l = to_light / dist;
        let v = (eye - p).normalize();
        let n_dot_l = l.y;
        let window = (1.0 - (dist / range).powi(2)).powi(2);
        let h = (l + v).normalize();
        let radiance = intensity * window;
        let by_hand = material.ambient * SCENE_AMBIENT
            + material.diffuse * radiance * n_dot_l
            + material.specular * radiance * h.y.powf(material.shininess) * n_dot_l;
        let (reference, _) = f.reference(px, py, Model::Full).unwrap();
        assert!(
            (reference - by_hand).abs().max_element() < 1e-4 * by_hand.max_element().max(1.0),
            "({px}, {py}): reference {reference}, by hand {by_hand}"
        );
        let want = display(by_hand);
        let got = image.get_pixel(px, py).0;
        for c in 0..3 {
            assert!(
                got[c].abs_diff(want[c]) <= 1,
                "({px}, {py}): forward {:?}, by hand {want:?}",
                &got[..3]
            );
        }
    }
    // The point under the light is lit brightly; the window is zero beyond the range.
    assert!(display(Vec3::splat(intensity))[0] > 200);
}

/// GGX (`--brdf ggx`) on catalog scenes, in the papers' units: `forward`, `forward_mono` and
/// `forward_mono_albedo` equal the reference's GGX written from glTF's appendix B, with
/// spots, headlights, every material shader and the glass.
#[test]
fn forward_equals_the_ggx_reference_on_catalog_scenes() {
    let ctx = common::gpu();
    for name in ["robots-few", "random-top"] {
        let params = SceneParams {
            spot_fraction: 0.3,
            headlights: name.starts_with("robots"),
            ..Default::default()
        };
        let scene = catalog::build(name, &params).unwrap();
        let frame = scene.frame_count() / 3;
        let c = check_brdf(&ctx, &scene, frame, (160, 96), 5, Some(Brdf::Ggx));
        eprintln!("{name} frame {frame} ggx: {c:?}");
        assert!(c.pixels >= 150 && c.lit * 4 >= c.pixels, "{name}: {c:?}");
    }
    // And a glTF file's photometric lights shaded with Blinn-Phong (`--brdf phong`).
    let bytes = common::gltf_fixture::room().glb();
    let opts = lightgrid::scene::gltf::LoadOptions::default();
    let room = lightgrid::scene::gltf::load_bytes(&bytes, "room.glb", None, &opts)
        .unwrap()
        .scene;
    let c = check_brdf(&ctx, &room, 0, (160, 96), 4, Some(Brdf::Phong));
    eprintln!("room phong: {c:?}");
    assert!(c.pixels >= 150 && c.lit * 4 >= c.pixels, "{c:?}");
}

/// A 40 m ground of `material` under `lights`, seen from `eye`.
fn one_plane(
    material: Material,
    lights: Vec<Light>,
    eye: Vec3,
    target: Vec3,
    lighting: Lighting,
) -> Scene {
    Scene {
        name: "plane".into(),
        meshes: vec![Mesh::ground(-20.0, -20.0, 20.0, 20.0, 0.0)],
        materials: vec![material],
        objects: vec![Object {
            mesh: 0,
            material: 0,
            local: glam::Mat4::IDENTITY,
            motion: lightgrid::scene::Motion::Static,
        }],
        paths: vec![],
        lights: lights
            .into_iter()
            .map(|light| SceneLight {
                light,
                anchor: lightgrid::scene::LightAnchor::World,
            })
            .collect(),
        textures: vec![],
        camera_path: CameraPath::fixed(eye, target, 40.0, 0.1, 100.0),
        default_size: (64, 64),
        lighting,
        derived_ranges: Vec::new(),
        tracks: Vec::new(),
    }
}

/// What pixel (px, py) of `f` shows on the ground (y = 0, seen from `eye`) under a light
/// `height` above the origin: the unit vectors to the light and to the eye, the distance to
/// the light and KHR_lights_punctual's range window `clamp(1 − (d/r)⁴, 0, 1)²` for `range`.
fn toward_light(
    f: &Frame,
    eye: Vec3,
    height: f32,
    range: f32,
    px: u32,
    py: u32,
) -> (Vec3, Vec3, f32, f32) {
    let d = f.ray(f64::from(px) + 0.5, f64::from(py) + 0.5);
    let p = eye + (d * (f64::from(eye.y) / -d.y)).as_vec3();
    let to_light = Vec3::new(0.0, height, 0.0) - p;
    let dist = to_light.length();
    let window = (1.0 - (dist / range).powi(4)).clamp(0.0, 1.0).powi(2);
    (to_light / dist, (eye - p).normalize(), dist, window)
}

/// Candela, inverse square and GGX, exposure 1: a glTF file's conventions, unscaled.
const PHOTOMETRIC: Lighting = Lighting {
    units: LightUnits::Photometric,
    brdf: Brdf::Ggx,
    spot_cone: lightgrid::scene::SpotCone::Squared,
    exposure: 1.0,
};

/// KHR_lights_punctual's falloff, by hand: a grey dielectric plane under one 30 cd light 2 m
/// up (range 8): at ground points 2 to 7 m from the light, `forward` shows the spec's
/// `I / d²` windowed by `clamp(1 − (d/r)⁴, 0, 1)²`, through glTF's BRDF, within one level.
#[test]
fn a_plane_under_one_photometric_light_falls_off_with_the_inverse_square() {
    let ctx = common::gpu();
    let eye = Vec3::new(0.0, 12.0, 6.0);
    let (height, range, candela) = (2.0f32, 8.0f32, 30.0f32);
    let mut material = Material::plain(Vec3::splat(0.6), 0.04, 30.0);
    material.ambient = Vec3::ZERO;
    let light = Light::point(Vec3::new(0.0, height, 0.0), Vec3::ONE, candela, range);
    let scene = one_plane(
        material,
        vec![light],
        eye,
        Vec3::new(0.0, 0.0, -1.0),
        PHOTOMETRIC,
    );
    let f = Frame::new(&scene, 0, (64, 64));
    let mut r = Renderer::new(&ctx, 64, 64, RenderSettings::default()).unwrap();
    let image = r.render(&scene, 0, "forward").unwrap().image;
    let mut distances = Vec::new();
    for py in (4..64).step_by(6) {
        for px in (4..64).step_by(6) {
            if f.reference(px, py, Model::Full).is_none() {
                continue;
            }
            let (l, v, dist, window) = toward_light(&f, eye, height, range, px, py);
            let e = Vec3::splat(candela / (dist * dist) * window * l.y);
            let (diffuse, specular) =
                common::shading::ggx(Vec3::Y, v, l, l.y, 30.0, material.specular, e);
            let by_hand = diffuse * material.diffuse + specular;
            let want = display(by_hand);
            let got = image.get_pixel(px, py).0;
            for c in 0..3 {
                assert!(
                    got[c].abs_diff(want[c]) <= 1,
                    "({px}, {py}) at {dist} m: forward {:?}, the spec {want:?}",
                    &got[..3]
                );
            }
            distances.push(dist);
        }
    }
    let (near, far) = distances
        .iter()
        .fold((f32::MAX, 0f32), |(a, b), &d| (a.min(d), b.max(d)));
    assert!(
        distances.len() >= 20 && near < 3.0 && far > 6.0,
        "{} points from {near} to {far} m",
        distances.len()
    );
}

/// KHR_lights_punctual's spot window, by hand: a 30 cd spot 2 m above a grey plane, pointing
/// down (inner cone 0.3 rad, outer 0.7), with the specification's conventions. At every
/// pixel whose ground point lies between the cones, `forward` shows
/// `t² · I / d² · window(d)` through glTF's BRDF, `t = (cos θ − cos outer) / (cos inner − cos
/// outer)`, within one level; points across the whole ramp are checked (the papers'
/// smoothstep differs from `t²` by up to a quarter of the light there).
#[test]
fn a_spot_falls_off_between_its_cones_as_the_specification_writes() {
    let ctx = common::gpu();
    let (eye, size) = (Vec3::new(0.0, 3.5, 2.5), 96);
    let (height, range, candela) = (2.0f32, 8.0f32, 30.0f32);
    let (inner, outer) = (0.3f32, 0.7f32);
    let mut material = Material::plain(Vec3::splat(0.6), 0.04, 30.0);
    material.ambient = Vec3::ZERO;
    let mut light = Light::point(Vec3::new(0.0, height, 0.0), Vec3::ONE, candela, range);
    light.spot = Some(lightgrid::scene::Spot::new(-Vec3::Y, inner, outer));
    let scene = one_plane(material, vec![light], eye, Vec3::ZERO, PHOTOMETRIC);
    let f = Frame::new(&scene, 0, (size, size));
    let mut r = Renderer::new(&ctx, size, size, RenderSettings::default()).unwrap();
    let image = r.render(&scene, 0, "forward").unwrap().image;
    let mut ramp = std::collections::BTreeSet::new();
    for py in 0..size {
        for px in 0..size {
            if f.reference(px, py, Model::Full).is_none() {
                continue;
            }
            let (l, v, dist, window) = toward_light(&f, eye, height, range, px, py);
            let cos_theta = l.y; // the angle from the downward axis
            let ramp_t = ((cos_theta - outer.cos()) / (inner.cos() - outer.cos())).clamp(0.0, 1.0);
            if ramp_t <= 0.02 || ramp_t >= 0.98 {
                continue;
            }
            let e = Vec3::splat(candela / (dist * dist) * window * l.y * ramp_t * ramp_t);
            let (diffuse, specular) =
                common::shading::ggx(Vec3::Y, v, l, l.y, 30.0, material.specular, e);
            let want = display(diffuse * material.diffuse + specular);
            let got = image.get_pixel(px, py).0;
            for c in 0..3 {
                assert!(
                    got[c].abs_diff(want[c]) <= 1,
                    "({px}, {py}) at t = {ramp_t}: forward {:?}, the spec {want:?}",
                    &got[..3]
                );
            }
            ramp.insert((ramp_t * 10.0) as u32);
        }
    }
    assert!(ramp.len() >= 9, "the ramp's tenths checked: {ramp:?}");
}

/// The directional albedo of glTF's BRDF as the reference writes it: `∫ f (n·l) dω` over the
/// hemisphere for view cosine `mu_v`, by a midpoint rule in (cos θ, φ).
fn albedo(alpha: f32, mu_v: f32, f0: f32, diffuse: f32, n: usize) -> f32 {
    let shininess = 2.0 / (alpha * alpha) - 2.0;
    let v = Vec3::new((1.0 - mu_v * mu_v).sqrt(), 0.0, mu_v);
    let mut sum = 0.0f64;
    for i in 0..n {
        let mu = (i as f32 + 0.5) / n as f32;
        for j in 0..2 * n {
            let phi = (j as f32 + 0.5) / (2 * n) as f32 * std::f32::consts::TAU;
            let s = (1.0 - mu * mu).sqrt();
            let l = Vec3::new(s * phi.cos(), s * phi.sin(), mu);
            let (d, sp) = common::shading::ggx(
                Vec3::Z,
                v,
                l,
                mu,
                shininess,
                Vec3::splat(f0),
                Vec3::splat(mu),
            );
            sum += f64::from((d * diffuse + sp).x);
        }
    }
    (sum * std::f64::consts::TAU / (2 * n * n) as f64) as f32
}

/// A white furnace, on the GPU: a plane lit from 4,096 lights spread evenly in solid angle
/// over its upper hemisphere (each standing for 2π/4096 sr of radiance 1) shows its
/// directional albedo. For a mirror-white metal (F0 = 1) at roughness α = 1 single-scattering
/// GGX loses energy by the model's known amount: seen from straight above the albedo is
/// exactly 1 − ln 2 (D = 1/π, V = 1/(2(n·l + 1))); from 60° more. A white dielectric
/// (F0 = 0.04, diffuse 1) stays at or below 1 there. `forward` must show what the integral
/// says, within 3%, and never more light than arrived.
#[test]
fn ggx_neither_creates_nor_loses_energy_beyond_the_models_known_loss() {
    // The reference's own furnace first: α = 1, seen from above.
    let a = albedo(1.0, 0.9999, 1.0, 0.0, 400);
    assert!(
        (a - (1.0 - std::f32::consts::LN_2)).abs() < 0.003,
        "{a} against 1 - ln 2"
    );
    for alpha in [0.1f32, 0.25, 0.5, 1.0] {
        for mu_v in [1.0f32, 0.5, 0.2] {
            let metal = albedo(alpha, mu_v.min(0.9999), 1.0, 0.0, 300);
            assert!(metal <= 1.005, "metal α {alpha} μ {mu_v}: {metal}");
            // Sharp lobes lose little; the loss grows with roughness.
            if alpha <= 0.1 && mu_v > 0.4 {
                assert!(metal > 0.95, "metal α {alpha} μ {mu_v}: {metal}");
            }
        }
    }
    let ctx = common::gpu();
    let (n_mu, n_phi, radius) = (32usize, 128usize, 10.0f32);
    let count = n_mu * n_phi;
    let candela = std::f32::consts::TAU * radius * radius / count as f32;
    let mut lights = Vec::new();
    for i in 0..n_mu {
        let mu = (i as f32 + 0.5) / n_mu as f32;
        for j in 0..n_phi {
            let phi = (j as f32 + 0.5) / n_phi as f32 * std::f32::consts::TAU;
            let s = (1.0 - mu * mu).sqrt();
            let dir = Vec3::new(s * phi.cos(), mu, s * phi.sin());
            lights.push(Light::point(dir * radius, Vec3::ONE, candela, 1e4));
        }
    }
    // Seen from nearly above (the camera is tilted 8°) and from 60°.
    for (view_deg, f0, diffuse) in [(8.0f32, 1.0f32, 0.0f32), (60.0, 1.0, 0.0), (8.0, 0.04, 1.0)] {
        let mut material = Material::plain(Vec3::splat(diffuse), f0, 0.0);
        material.ambient = Vec3::ZERO;
        let t = view_deg.to_radians();
        let eye = Vec3::new(0.0, 3.0 * t.cos(), 3.0 * t.sin());
        let scene = one_plane(material, lights.clone(), eye, Vec3::ZERO, PHOTOMETRIC);
        let mut r = Renderer::new(&ctx, 32, 32, RenderSettings::default()).unwrap();
        let image = r.render(&scene, 0, "forward").unwrap().image;
        // The centre pixel's radiance, back through sRGB and the tone curve.
        let level = f32::from(image.get_pixel(16, 16).0[0]) / 255.0;
        let linear = if level <= 0.04045 {
            level / 12.92
        } else {
            ((level + 0.055) / 1.055).powf(2.4)
        };
        let got = -(1.0 - linear).ln();
        let want = albedo(1.0, t.cos(), f0, diffuse, 300);
        eprintln!("view {view_deg}°, F0 {f0}, diffuse {diffuse}: forward {got}, albedo {want}");
        assert!(
            (got - want).abs() <= 0.03 * want,
            "view {view_deg}°: forward shows {got}, the albedo is {want}"
        );
        assert!(got <= 1.01, "more light out than in: {got}");
    }
}

/// A scene made for another engine (100 boxes, 1,024 lights of 4,000 cd with range 6)
/// renders as pools of light, not white: with the automatic exposure, under 5 % of the frame
/// saturates (any channel at 250 or more) and its mean luminance is between 0.08 and 0.5 of
/// white, and `forward` equals the reference there.
#[test]
fn a_gltf_scene_made_for_another_engine_renders_pools_of_light() {
    let ctx = common::gpu();
    let bytes = common::gltf_fixture::engine_street(1024).glb();
    // Kept for trying it with the CLI (README, "Light units, BRDFs and exposure").
    std::fs::write(common::output_dir().join("engine-street.glb"), &bytes).unwrap();
    let opts = lightgrid::scene::gltf::LoadOptions::default();
    let scene = lightgrid::scene::gltf::load_bytes(&bytes, "street.glb", None, &opts)
        .unwrap()
        .scene;
    assert_eq!(scene.lighting.units, LightUnits::Photometric);
    assert_eq!(scene.lighting.brdf, Brdf::Ggx);
    let (w, h) = (320, 180);
    let mut r = Renderer::new(&ctx, w, h, RenderSettings::default()).unwrap();
    let image = r.render(&scene, 0, "forward").unwrap().image;
    let pixels = image.pixels().count() as f32;
    let saturated = image
        .pixels()
        .filter(|p| p.0[..3].iter().any(|&c| c >= 250))
        .count() as f32
        / pixels;
    let luminance = image
        .pixels()
        .map(|p| {
            let c = p.0.map(|c| f32::from(c) / 255.0);
            0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
        })
        .sum::<f32>()
        / pixels;
    eprintln!(
        "exposure {}: saturated {saturated}, mean luminance {luminance}",
        scene.lighting.exposure
    );
    lightgrid::image_io::save_png(&image, &common::output_dir().join("engine-street.png")).unwrap();
    assert!(saturated < 0.05, "{saturated} of the frame saturates");
    assert!(
        (0.08..=0.5).contains(&luminance),
        "mean luminance {luminance}"
    );
    let c = check(&ctx, &scene, 0, (160, 96), 6);
    assert!(c.pixels >= 100 && c.lit * 2 >= c.pixels, "{c:?}");
}
