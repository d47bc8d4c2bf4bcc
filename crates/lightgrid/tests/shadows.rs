//! Ray-cast shadows (`--shadows rays`, `lightgrid::shadows`) against what geometry says and
//! against the CPU shading reference that casts its own rays through every triangle in f64
//! (`common/shading.rs`, no hierarchy): a box on a plane under one light, whose shadow's
//! outline is worked out from the box itself; `forward` at sampled pixels of catalog scenes;
//! `--shadow-lights` choosing the casters and counting the rest.

mod common;

use common::shading::{check_with, display, Frame};
use glam::{Mat4, Vec3};
use lightgrid::consts::SCENE_AMBIENT;
use lightgrid::scene::catalog::{self, SceneParams};
use lightgrid::scene::{
    CameraPath, Light, LightAnchor, Lighting, Material, Mesh, Motion, Object, Scene, SceneLight,
    Shadows,
};
use lightgrid::{RenderSettings, Renderer};

const BOX_MIN: Vec3 = Vec3::new(-1.0, 0.0, -1.0);
const BOX_MAX: Vec3 = Vec3::new(1.0, 2.0, 1.0);
const LIGHT: Vec3 = Vec3::new(2.5, 5.0, 1.0);
const EYE: Vec3 = Vec3::new(-3.0, 14.0, 9.0);
const SIZE: u32 = 128;

/// A white ground with a box on it under one bright light of long range, seen from above.
fn box_on_a_plane() -> Scene {
    let white = Material::plain(Vec3::splat(0.8), 0.0, 8.0);
    let object = |mesh| Object {
        mesh,
        material: 0,
        local: Mat4::IDENTITY,
        motion: Motion::Static,
    };
    Scene {
        name: "box-on-a-plane".into(),
        meshes: vec![
            Mesh::ground(-20.0, -20.0, 20.0, 20.0, 0.0),
            Mesh::cuboid(BOX_MIN, BOX_MAX),
        ],
        materials: vec![white],
        objects: vec![object(0), object(1)],
        paths: vec![],
        lights: vec![SceneLight {
            light: Light::point(LIGHT, Vec3::ONE, 2.0, 40.0),
            anchor: LightAnchor::World,
        }],
        textures: vec![],
        camera_path: CameraPath::fixed(EYE, Vec3::new(1.5, 0.0, 1.5), 50.0, 0.1, 100.0),
        default_size: (SIZE, SIZE),
        lighting: Lighting::default(),
        derived_ranges: Vec::new(),
        tracks: Vec::new(),
    }
}

/// Does the segment from `p` to the light cross the box? Slabs, from the box's corners alone.
fn box_blocks(p: Vec3) -> bool {
    let d = LIGHT - p;
    let (t0, t1) = ((BOX_MIN - p) / d, (BOX_MAX - p) / d);
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element().min(1.0);
    near <= far
}

/// The ground point seen through framebuffer position (x, y), if the ray meets the ground
/// before the box.
fn ground_point(f: &Frame, x: f64, y: f64) -> Option<Vec3> {
    let d = f.ray(x, y).as_vec3();
    let t = EYE.y / -d.y;
    if t <= 0.0 {
        return None;
    }
    let p = EYE + d * t;
    // The box in front of the ground point: not the ground.
    let (t0, t1) = ((BOX_MIN - EYE) / d, (BOX_MAX - EYE) / d);
    let near = t0.min(t1).max_element();
    let far = t0.max(t1).min_element();
    (p.x.abs() < 20.0 && p.z.abs() < 20.0 && !(near <= far && near < t)).then_some(p)
}

/// The shadow's outline lies where the box's corners put it, within a pixel: every ground
/// pixel whose whole square (centre and corners) is in shadow by the box's geometry shows only
/// the ambient term, and every one wholly out of it is lit, in `forward` and in pipelines of
/// each family, with rays and with shadow maps (atlas, and re-used by the light-volume
/// pipelines). The same scene without shadows has no dark ground pixel.
#[test]
fn a_box_on_a_plane_casts_the_shadow_its_corners_say() {
    let ctx = common::gpu();
    let scene = box_on_a_plane();
    let f = Frame::new(&scene, 0, (SIZE, SIZE));
    let white = scene.materials[0];
    let dark = display(white.ambient * SCENE_AMBIENT);
    let settings = RenderSettings {
        shadows: Shadows::Rays,
        ..RenderSettings::default()
    };
    let mut unshadowed = Renderer::new(&ctx, SIZE, SIZE, RenderSettings::default()).unwrap();
    let plain = unshadowed.render(&scene, 0, "forward").unwrap().image;
    let pipelines = [
        "forward",
        "clustered_deferred",
        "tiled_forward",
        "deferred_stencil",
        "light_prepass",
    ];
    for (shadows, pipeline) in [Shadows::Rays, Shadows::Maps]
        .into_iter()
        .flat_map(|s| pipelines.map(|p| (s, p)))
    {
        let settings = RenderSettings {
            shadows,
            ..settings
        };
        let mut r = Renderer::new(&ctx, SIZE, SIZE, settings).unwrap();
        let out = r.render(&scene, 0, pipeline).unwrap();
        let pipeline = format!("{pipeline} --shadows {}", shadows.name());
        let (mut in_shadow, mut lit) = (0, 0);
        for py in 0..SIZE {
            for px in 0..SIZE {
                let (x, y) = (f64::from(px), f64::from(py));
                let corners = [(0.5, 0.5), (0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                    .map(|(dx, dy)| ground_point(&f, x + dx, y + dy).map(box_blocks));
                let Some(Some(centre)) = corners.first().copied() else {
                    continue;
                };
                if corners.iter().any(|c| *c != Some(centre)) {
                    continue; // the outline, or the box's edge, crosses the pixel
                }
                let got = out.image.get_pixel(px, py).0;
                if centre {
                    in_shadow += 1;
                    let worst = (0..3).map(|c| got[c].abs_diff(dark[c])).max().unwrap();
                    assert!(
                        worst <= 1,
                        "{pipeline} ({px}, {py}) in shadow: {got:?}, ambient {dark:?}"
                    );
                    assert!(
                        plain.get_pixel(px, py).0[0] > dark[0] + 40,
                        "lit without shadows"
                    );
                } else {
                    lit += 1;
                    assert!(
                        got[0] > dark[0] + 40,
                        "{pipeline} ({px}, {py}) lit: {got:?}"
                    );
                }
            }
        }
        eprintln!("{pipeline}: {in_shadow} pixels in shadow, {lit} lit");
        assert!(
            in_shadow > 300 && lit > 3000,
            "{pipeline}: {in_shadow} / {lit}"
        );
        if shadows == Shadows::Rays {
            assert!(
                out.stats.shadow_rays.unwrap() > 0,
                "{pipeline}: no rays counted"
            );
        } else {
            let maps = out.stats.shadow_maps.unwrap();
            assert_eq!((maps.faces, maps.face), (6, 1024), "{pipeline}");
            // One cube either way: the atlas holds its six faces, as the re-used tiles do.
            assert_eq!(maps.bytes, 6 * 1024 * 1024 * 4, "{pipeline}");
        }
        assert_eq!(out.stats.unshadowed_lights, Some(0));
    }
}

/// `forward` with every light casting equals the CPU reference, which tests each light's
/// segment against every opaque triangle in f64, at sampled pixels (those whose shadow state
/// is the same a third of a pixel around the centre), on catalog scenes with moving robots,
/// spots and glass, in both BRDFs.
#[test]
fn forward_with_ray_shadows_equals_the_reference_that_casts_its_own() {
    let ctx = common::gpu();
    for (name, brdf) in [
        ("robots-few", None),
        ("random-top", Some(lightgrid::scene::Brdf::Ggx)),
    ] {
        let params = SceneParams {
            spot_fraction: 0.3,
            headlights: name.starts_with("robots"),
            ..Default::default()
        };
        let scene = catalog::build(name, &params).unwrap();
        let frame = scene.frame_count() / 3;
        let settings = RenderSettings {
            shadows: Shadows::Rays,
            brdf,
            ..RenderSettings::default()
        };
        let c = check_with(&ctx, &scene, frame, (128, 72), 4, settings);
        eprintln!("{name} frame {frame}: {c:?}");
        assert!(c.pixels >= 100, "{name}: {c:?}");
        assert!(
            c.shadowed * 10 >= c.pixels,
            "{name}: too few shadowed pixels: {c:?}"
        );
        assert!(c.lit * 4 >= c.pixels, "{name}: too few lit pixels: {c:?}");
    }
}

/// Far from the origin, with the camera's own tiny near plane: shadow space is anchored at
/// the scene, so `forward` with shadows still equals the reference (no surface shadows
/// itself), and every pipeline equals `forward`.
#[test]
fn ray_shadows_far_from_the_origin_equal_the_reference() {
    let ctx = common::gpu();
    let s = catalog::build("robots-few", &SceneParams::default()).unwrap();
    let mut s = common::moved(&s, Vec3::new(1e5, 0.0, -1e5));
    s.camera_path.near = 0.05;
    s.camera_path.far = 1e6;
    let settings = RenderSettings {
        shadows: Shadows::Rays,
        ..RenderSettings::default()
    };
    let c = check_with(&ctx, &s, s.frame_count() / 3, (128, 72), 4, settings);
    eprintln!("{}: {c:?}", s.name);
    assert!(c.pixels >= 100 && c.shadowed * 10 >= c.pixels, "{c:?}");
}

/// `--shadow-lights N`: N lights cast, the rest are counted as unshadowed; one caster gives an
/// image between none and all, and fewer rays than all.
#[test]
fn shadow_lights_choose_the_casters_and_count_the_rest() {
    let ctx = common::gpu();
    let scene = catalog::build("robots-few", &SceneParams::default()).unwrap();
    let frame = 120;
    let lights = scene.frame(frame).lights.len() as u32;
    let render = |shadows, shadow_lights| {
        let settings = RenderSettings {
            shadows,
            shadow_lights,
            ..RenderSettings::default()
        };
        let mut r = Renderer::new(&ctx, 160, 90, settings).unwrap();
        r.render(&scene, frame, "clustered_forward").unwrap()
    };
    let off = render(Shadows::Off, None);
    let one = render(Shadows::Rays, Some(1));
    let all = render(Shadows::Rays, None);
    assert_eq!(off.stats.shadow_rays, None);
    assert_eq!(one.stats.unshadowed_lights, Some(lights - 1));
    assert_eq!(all.stats.unshadowed_lights, Some(0));
    let (r1, ra) = (
        one.stats.shadow_rays.unwrap(),
        all.stats.shadow_rays.unwrap(),
    );
    assert!(r1 > 0 && r1 < ra, "one caster {r1} rays, all {ra}");
    let sum = |img: &image::RgbaImage| {
        img.pixels()
            .map(|p| u64::from(p.0[0]) + u64::from(p.0[1]))
            .sum::<u64>()
    };
    let (s_off, s_one, s_all) = (sum(&off.image), sum(&one.image), sum(&all.image));
    assert!(
        s_off > s_one && s_one > s_all,
        "{s_off} > {s_one} > {s_all}"
    );
}

/// Shadow maps (every light's cube in the atlas at 1024-texel faces) shade what the
/// reference's rays say at the same sampled pixels: no acne on lit surfaces, no light leaking
/// into shadows, on the street with its robots and on the block field.
#[test]
fn forward_with_shadow_maps_equals_the_reference_that_casts_rays() {
    let ctx = common::gpu();
    for name in ["robots-few", "random-top"] {
        let params = SceneParams {
            headlights: name.starts_with("robots"),
            spot_fraction: 0.3,
            ..Default::default()
        };
        let scene = catalog::build(name, &params).unwrap();
        let frame = scene.frame_count() / 3;
        let settings = RenderSettings {
            shadows: Shadows::Maps,
            shadow_atlas: 1024,
            ..RenderSettings::default()
        };
        let c = check_with(&ctx, &scene, frame, (128, 72), 4, settings);
        eprintln!("{name} frame {frame} maps: {c:?}");
        assert!(
            c.pixels >= 100 && c.shadowed * 10 >= c.pixels,
            "{name}: {c:?}"
        );
    }
}
