//! The catalog's scenes: exact light counts and ranges, determinism, and bad input.

use lightgrid::scene::catalog::{self, SceneParams, SCENES};
use lightgrid::scene::Light;
use lightgrid::Error;

fn lights_of(name: &str) -> Vec<Light> {
    let scene = catalog::build(name, &SceneParams::default()).expect(name);
    scene.frame(0).lights
}

#[test]
fn light_counts_and_ranges_are_the_papers() {
    let many = lights_of("robots-many");
    assert_eq!(many.len(), 924);
    assert!(many.iter().all(|l| l.range == 12.5));
    let few = lights_of("robots-few");
    assert_eq!(few.len(), 11);
    assert!(few.iter().all(|l| l.range == 40.0));
    assert_eq!(lights_of("scattered").len(), 3072);
    assert_eq!(lights_of("random-top").len(), 1024);
    assert_eq!(lights_of("random-fps").len(), 1024);
    for n in [1, 1000, 65_536] {
        let s = catalog::build(
            "stress",
            &SceneParams {
                seed: 1,
                lights: Some(n),
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(s.lights.len(), n as usize);
    }
}

#[test]
fn robots_few_lights_move_with_the_robots_and_many_stay() {
    let few = catalog::build("robots-few", &SceneParams::default()).unwrap();
    let (a, b) = (few.frame(0).lights, few.frame(50).lights);
    assert!(a.iter().zip(&b).all(|(x, y)| x.position != y.position));
    let many = catalog::build("robots-many", &SceneParams::default()).unwrap();
    assert_eq!(many.frame(0).lights, many.frame(50).lights);
}

#[test]
fn robots_camera_path_is_about_260_frames_and_street_is_29_1_wide() {
    let s = catalog::build("robots-many", &SceneParams::default()).unwrap();
    assert_eq!(s.frame_count(), 260);
    assert_eq!(catalog::MAIN_STREET_WIDTH, 29.1);
    assert_eq!(s.default_size, (640, 360));
    let scattered = catalog::build("scattered", &SceneParams::default()).unwrap();
    assert_eq!(scattered.default_size, (1280, 720));
}

#[test]
fn scenes_are_deterministic_from_the_seed() {
    for info in SCENES {
        let a = catalog::build(info.name, &SceneParams::default())
            .unwrap()
            .frame(3);
        let b = catalog::build(info.name, &SceneParams::default())
            .unwrap()
            .frame(3);
        assert_eq!(a.lights, b.lights, "{}", info.name);
        assert_eq!(a.transforms, b.transforms, "{}", info.name);
    }
    let a = lights_of("robots-many");
    let c = catalog::build(
        "robots-many",
        &SceneParams {
            seed: 2,
            lights: None,
            ..Default::default()
        },
    )
    .unwrap()
    .frame(0)
    .lights;
    assert_ne!(a, c, "another seed places lights differently");
}

#[test]
fn every_scene_builds_valid_geometry() {
    for info in SCENES {
        let s = catalog::build(info.name, &SceneParams::default()).unwrap();
        let state = s.frame(0);
        let g = s.geometry(&state);
        let (v, i) = (&g.vertices, &g.indices);
        assert!(!v.is_empty() && i.len() % 3 == 0, "{}", info.name);
        assert_eq!(
            g.opaque_indices < i.len(),
            info.transparency(),
            "{}: transparent triangles follow the opaque ones exactly when the scene has glass",
            info.name
        );
        assert!(i.iter().all(|&x| (x as usize) < v.len()), "{}", info.name);
        assert!(v.iter().all(|v| v.position.iter().all(|c| c.is_finite())));
        assert!(state.camera.view().is_finite(), "{}", info.name);
    }
}

#[test]
fn bad_input_is_a_typed_error() {
    let unknown = catalog::build("nope", &SceneParams::default()).unwrap_err();
    match unknown {
        Error::Unknown { valid, .. } => {
            assert!(valid.contains("robots-many") && valid.contains("stress"))
        }
        e => panic!("unexpected {e}"),
    }
    let zero = catalog::build(
        "stress",
        &SceneParams {
            seed: 1,
            lights: Some(0),
            ..Default::default()
        },
    );
    assert!(matches!(zero, Err(Error::Invalid { .. })));
    let too_many = catalog::build(
        "stress",
        &SceneParams {
            seed: 1,
            lights: Some(1_000_001),
            ..Default::default()
        },
    );
    assert!(matches!(too_many, Err(Error::Invalid { .. })));
    let fixed = catalog::build(
        "robots-many",
        &SceneParams {
            seed: 1,
            lights: Some(5),
            ..Default::default()
        },
    );
    assert!(matches!(fixed, Err(Error::Invalid { .. })));
}

#[test]
fn nan_or_non_positive_lights_are_rejected() {
    let mut s = catalog::build("robots-few", &SceneParams::default()).unwrap();
    s.lights[3].light.position.x = f32::NAN;
    assert!(s.validate().is_err());
    let mut s = catalog::build("robots-few", &SceneParams::default()).unwrap();
    s.lights[0].light.range = 0.0;
    assert!(s.validate().is_err());
}

/// `--headlights`: two spots per robot that turn with it (object-anchored directions follow the
/// robot's motion), refused on scenes without robots.
#[test]
fn headlights_turn_with_their_robots() {
    use lightgrid::scene::LightAnchor;
    let params = SceneParams {
        headlights: true,
        ..Default::default()
    };
    let scene = catalog::build("robots-few", &params).unwrap();
    let heads: Vec<_> = scene
        .lights
        .iter()
        .enumerate()
        .filter(|(_, l)| l.light.spot.is_some())
        .collect();
    assert_eq!(heads.len(), 22, "two per robot");
    let mut turned = 0;
    let first = scene.frame(0);
    for f in [0, 60, 130, 259] {
        let state = scene.frame(f);
        for (i, l) in &heads {
            let LightAnchor::Object(o) = l.anchor else {
                panic!("headlights ride on their robots")
            };
            let t = state.transforms[o];
            let forward = t.transform_vector3(glam::Vec3::Z).normalize();
            let dir = state.lights[*i].spot.unwrap().direction;
            assert!(
                dir.dot(forward) > 0.9,
                "frame {f}: headlight {i} does not look ahead"
            );
            assert!(dir.y < 0.0, "headlights look a little down");
            let before = first.lights[*i].spot.unwrap().direction;
            turned += usize::from(before.dot(dir) < 0.99);
        }
    }
    assert!(
        turned > 0,
        "no robot turned its headlights over the animation"
    );
    assert!(catalog::build("stress", &params).is_err());
}

/// The transparent objects come after the opaque geometry, farthest first, every frame; and
/// `--transparency off` leaves the rest of the scene as it was.
#[test]
fn transparent_objects_are_sorted_back_to_front_and_optional() {
    for name in ["robots-many", "random-fps"] {
        let on = catalog::build(name, &SceneParams::default()).unwrap();
        let off = catalog::build(
            name,
            &SceneParams {
                transparency: false,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(on.has_transparency() && !off.has_transparency(), "{name}");
        assert_eq!(on.lights.len(), off.lights.len(), "{name}");
        assert_eq!(
            on.static_geometry(),
            off.static_geometry(),
            "{name}: the opaque static geometry does not depend on the glass"
        );
        for frame in [0, 60, 150] {
            let state = on.frame(frame);
            let g = on.geometry(&state);
            let eye = state.camera.eye;
            let order = on.transparent_order(&state);
            let transparent = on.objects.iter().filter(|o| on.is_transparent(o)).count();
            assert_eq!(order.len(), transparent, "{name}");
            let distance = |i: usize| {
                let o = &on.objects[i];
                state.transforms[i]
                    .transform_point3(on.meshes[o.mesh].centre())
                    .distance(eye)
            };
            assert!(
                order.windows(2).all(|w| distance(w[0]) >= distance(w[1])),
                "{name} frame {frame}: not farthest first"
            );
            // The frame's index list holds exactly those objects' triangles after the opaque.
            let triangles: usize = order
                .iter()
                .map(|&i| on.meshes[on.objects[i].mesh].triangle_count())
                .sum();
            assert_eq!(g.transparent_triangles(0).len(), triangles, "{name}");
            // The first transparent triangle is the farthest object's.
            let first = &on.meshes[on.objects[order[0]].mesh];
            let t0 = g.transparent_triangles(0)[0][0];
            assert!(
                first.positions.iter().any(|p| p.distance(t0) < 1e-3),
                "{name} frame {frame}: the farthest object is drawn first"
            );
        }
    }
}

/// Per-material draws: every run of the frame's geometry holds only triangles of materials
/// with the run's shader, the opaque runs come first grouped by shader, and the robots'
/// scene has runs of more than one shader.
#[test]
fn geometry_runs_are_grouped_by_material_shader() {
    for name in ["robots-many", "scattered"] {
        let s = catalog::build(name, &SceneParams::default()).unwrap();
        let g = s.geometry(&s.frame(10));
        let mut covered = 0;
        for d in &g.draws {
            assert_eq!(d.first as usize, covered, "{name}: runs are contiguous");
            covered += d.count as usize;
            for &i in &g.indices[d.first as usize..(d.first + d.count) as usize] {
                let m = g.vertices[i as usize].material as usize;
                assert_eq!(s.materials[m].shader.gpu().0, d.shader, "{name}");
            }
        }
        assert_eq!(covered, g.indices.len(), "{name}: every index is drawn");
        let (opaque, transparent) = g.split_draws();
        let opaque_end = opaque.last().map_or(0, |d| (d.first + d.count) as usize);
        assert_eq!(opaque_end, g.opaque_indices, "{name}");
        assert_eq!(transparent.is_empty(), !s.has_transparency(), "{name}");
        let shaders: std::collections::HashSet<u32> = opaque.iter().map(|d| d.shader).collect();
        assert!(shaders.len() > 1, "{name}: more than one shader");
        // The static part and the moving part are each grouped: at most two runs per shader.
        for k in &shaders {
            let runs = opaque.iter().filter(|d| d.shader == *k).count();
            assert!(runs <= 2, "{name}: shader {k} in {runs} opaque runs");
        }
    }
}

/// `scattered`'s lights move as in the Forward+ demo: at frame 0 where they were placed, then
/// each around a circle of its own (never further than its diameter from the start), all of
/// them moving, the geometry unchanged.
#[test]
fn scattered_lights_circle_from_their_places() {
    use lightgrid::scene::LightAnchor;
    let scene = catalog::build("scattered", &SceneParams::default()).unwrap();
    let start = scene.frame(0);
    for f in [1, 45, 130, 259] {
        let state = scene.frame(f);
        let mut moved = 0;
        for ((l, now), then) in scene.lights.iter().zip(&state.lights).zip(&start.lights) {
            let LightAnchor::Circle { radius, .. } = l.anchor else {
                panic!("every scattered light moves")
            };
            assert_eq!(then.position, l.light.position, "frame 0 is the placement");
            let d = now.position - then.position;
            assert!(d.y.abs() < 1e-4, "lights circle a vertical axis");
            assert!(
                d.length() <= 2.0 * radius + 1e-3,
                "frame {f}: {d} off a {radius} circle"
            );
            moved += usize::from(d.length() > 1e-3);
            assert_eq!((now.range, now.intensity), (then.range, then.intensity));
        }
        assert_eq!(moved, scene.lights.len(), "frame {f}: every light moved");
    }
    assert_eq!(
        start.transforms,
        scene.frame(259).transforms,
        "the geometry stays put"
    );
}
