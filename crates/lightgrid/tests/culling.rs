//! CPU light assignment never misses a light: 10,000 randomized cases against the
//! brute-force oracle, on tiles and clusters, including lights behind the camera, crossing the near plane,
//! containing the camera and at the screen edges, tile sizes from 4 to 64 and resolutions
//! that are not multiples of the tile size. CPU only.

mod common;

use glam::Vec3;
use lightgrid::culling::{assign_cpu, DepthRange, GridDims, GridLists, ViewSetup};
use lightgrid::scene::{Camera, Fragment, Light, Rng};
use lightgrid::testing::{
    assign_gather_cpu, build_bvh, cell_bounds_cpu, oracle_fragment_lights, oracle_tile_lights,
    project_sphere, traverse_bvh_cpu, EMPTY_CELL,
};

const TILES: [u32; 9] = [4, 5, 7, 8, 13, 16, 31, 32, 64];

struct Case {
    setup: ViewSetup,
    camera: Camera,
    lights: Vec<Light>,
}

fn random_case(rng: &mut Rng) -> Case {
    let eye = Vec3::new(
        rng.range(-20.0, 20.0),
        rng.range(-5.0, 20.0),
        rng.range(-20.0, 20.0),
    );
    let dir = Vec3::new(
        rng.range(-1.0, 1.0),
        rng.range(-0.6, 0.6),
        rng.range(-1.0, 1.0),
    )
    .normalize_or(Vec3::X);
    let camera = Camera {
        eye,
        target: eye + dir,
        up: Vec3::Y,
        fov_y: rng.range(30.0, 100.0).to_radians(),
        near: rng.range(0.05, 1.0),
        far: rng.range(40.0, 200.0),
    };
    let (w, h) = (17 + rng.below(90), 9 + rng.below(70));
    let setup = ViewSetup::new(&camera, w, h);
    let world = |v: Vec3| setup.world_point(v);
    let color = Vec3::ONE;
    let mut lights = Vec::new();
    for k in 0..24 {
        let r = rng.range(0.2, 12.0);
        // View-space placements covering the edge cases by construction.
        let v = match k % 6 {
            // Anywhere around the camera, including far behind it.
            0 | 1 => Vec3::new(
                rng.range(-30.0, 30.0),
                rng.range(-30.0, 30.0),
                rng.range(-40.0, 25.0),
            ),
            // Containing the camera.
            2 => {
                Vec3::new(
                    rng.range(-0.5, 0.5),
                    rng.range(-0.5, 0.5),
                    rng.range(-0.5, 0.5),
                ) * r
            }
            // Crossing the near plane.
            3 => Vec3::new(
                rng.range(-r, r),
                rng.range(-r, r),
                -camera.near + rng.range(-r, r),
            ),
            // Behind the camera but reaching forward past the near plane.
            4 => Vec3::new(
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
                rng.range(0.0, r),
            ),
            // Centred just outside a screen edge.
            _ => {
                let depth = rng.range(1.0, 40.0);
                let edge_x = if rng.unit() < 0.5 { -1.0 } else { 1.0 } * rng.range(0.9, 1.2);
                let y = rng.range(-1.2, 1.2);
                let (sx, sy) = if rng.unit() < 0.5 {
                    (edge_x, y)
                } else {
                    (y, edge_x)
                };
                Vec3::new(sx / setup.p00 * depth, sy / setup.p11 * depth, -depth)
            }
        };
        let position = world(v);
        lights.push(Light {
            position,
            color,
            intensity: 1.0,
            range: r,
            spot: common::random_spot(rng, position, eye),
        });
    }
    Case {
        setup,
        camera,
        lights,
    }
}

/// A depth buffer (reversed-Z values, `lightgrid::depth`) with sky, smooth surfaces,
/// near-plane samples and noise.
fn random_depth(rng: &mut Rng, case: &Case) -> Vec<f32> {
    let s = &case.setup;
    // Geometry never reaches the background value (0) exactly.
    let to_ndc = |w: f32| s.depth_of(w).clamp(1e-7, 1.0);
    let (a, b, c) = (
        rng.range(0.5, 30.0),
        rng.range(-20.0, 20.0),
        rng.range(-20.0, 20.0),
    );
    (0..s.width * s.height)
        .map(|i| {
            let (x, y) = (
                (i % s.width) as f32 / s.width as f32,
                (i / s.width) as f32 / s.height as f32,
            );
            let roll = rng.unit();
            if roll < 0.15 {
                lightgrid::depth::CLEAR
            } else if roll < 0.2 {
                to_ndc(s.near)
            } else {
                let w = (a + b * x + c * y).abs() + s.near + rng.range(0.0, 3.0);
                to_ndc(w.min(s.far))
            }
        })
        .collect()
}

/// Cases per randomized test: 10,000 in all across tiles and clusters (about 8 s in release on
/// two cores).
const TILE_CASES: usize = 4000;
const CLUSTER_CASES: usize = 3000;
const TWIN_CASES: usize = 3000;

#[test]
fn cpu_assignment_contains_the_oracle_in_randomized_cases() {
    let mut rng = Rng::new(2024);
    let mut coverage = common::Coverage::default();
    let mut assigned_pairs = 0usize;
    let mut all_pairs = 0usize;
    for case_index in 0..TILE_CASES {
        let case = random_case(&mut rng);
        let depth = random_depth(&mut rng, &case);
        let s = &case.setup;
        let tile = TILES[case_index % TILES.len()];
        let dims = GridDims::new(s.width, s.height, tile).unwrap();
        let view_distance = common::view_distances(s, &depth);
        let oracle = oracle_tile_lights(s, &dims, &case.lights, &view_distance);
        let bounds = cell_bounds_cpu(s, &dims, &depth);
        let bounded = assign_cpu(s, &dims, &case.lights, DepthRange::Cells(&bounds));
        let plain = assign_cpu(s, &dims, &case.lights, DepthRange::NearFar);
        for (t, must) in oracle.iter().enumerate() {
            for l in must {
                assert!(
                    bounded.cell(t).contains(l),
                    "case {case_index}: depth-bounded grid misses light {l} in tile {t} \
                     ({}x{}, tile {tile}, light {:?}, camera {:?})",
                    s.width,
                    s.height,
                    case.lights[*l as usize],
                    case.camera
                );
            }
            for l in bounded.cell(t) {
                assert!(
                    plain.cell(t).contains(l),
                    "case {case_index}: depth bounds added light {l}"
                );
            }
        }
        coverage.add(s, &dims, &case.lights, &oracle);
        assigned_pairs += bounded.indices.len();
        all_pairs += dims.tile_count() * case.lights.len();
    }
    // The cases must really exercise hits of every kind: at least half of what they measured
    // (oracle (tile, light) pairs; the edge-case kinds are disjoint, and most hits come from
    // lights containing the camera, which reach every tile with samples).
    let measured = common::Coverage {
        cases: 4000,
        odd_cases: 3927,
        hits: 1_448_857,
        containing: 1_326_983,
        behind: 3254,
        crossing_near: 73_454,
        off_screen: 24_888,
        partial_tiles: 237_161,
    };
    coverage.at_least(&measured.halved(), "tiles");
    // The assignment must really cull (measured: 1,714,946 of 4,826,448 pairs listed).
    assert!(
        assigned_pairs < all_pairs / 2,
        "assignment barely culls: {assigned_pairs} of {all_pairs}"
    );
}

#[test]
fn clustered_assignment_contains_the_oracle_in_randomized_cases() {
    let mut rng = Rng::new(99);
    let mut coverage = common::Coverage::default();
    let mut cluster_pairs = 0usize;
    let mut tile_pairs = 0usize;
    for case_index in 0..CLUSTER_CASES {
        let case = random_case(&mut rng);
        let depth = random_depth(&mut rng, &case);
        let s = &case.setup;
        let tile = TILES[case_index % TILES.len()];
        let slices = [1, 4, 16, 32, 64][case_index % 5];
        let tiles = GridDims::new(s.width, s.height, tile).unwrap();
        let dims = tiles.clustered(slices, s.near, s.far).unwrap();
        let view_distance = common::view_distances(s, &depth);
        let oracle = oracle_tile_lights(s, &dims, &case.lights, &view_distance);
        let bounds = cell_bounds_cpu(s, &dims, &depth);
        let grid = assign_cpu(s, &dims, &case.lights, DepthRange::Cells(&bounds));
        assert_eq!(grid.cells.len(), dims.cell_count());
        for (c, must) in oracle.iter().enumerate() {
            for l in must {
                assert!(
                    grid.cell(c).contains(l),
                    "case {case_index}: cluster {c} (slice {} of {slices}) misses light {l}: {:?}, camera {:?}",
                    c / dims.tile_count(),
                    case.lights[*l as usize],
                    case.camera
                );
            }
        }
        coverage.add(s, &dims, &case.lights, &oracle);
        // Per sample, a cluster never lists more point lights than its depth-bounded tile
        // (spots are tested against each cell's bounding sphere, and a cluster's sphere need
        // not lie inside its tile's).
        let tile_bounds = cell_bounds_cpu(s, &tiles, &depth);
        let tiled = assign_cpu(s, &tiles, &case.lights, DepthRange::Cells(&tile_bounds));
        for c in 0..dims.cell_count() {
            let t = c % dims.tile_count();
            assert!(
                grid.cell(c)
                    .iter()
                    .filter(|&&l| case.lights[l as usize].spot.is_none())
                    .all(|l| tiled.cell(t).contains(l)),
                "case {case_index}: cluster {c} ⊄ tile"
            );
        }
        cluster_pairs += grid.indices.len();
        tile_pairs += tiled.indices.len();
    }
    // At least half of what the cases measured (oracle (cluster, light) pairs).
    let measured = common::Coverage {
        cases: 3000,
        odd_cases: 2950,
        hits: 1_648_805,
        containing: 1_484_458,
        behind: 3311,
        crossing_near: 105_415,
        off_screen: 29_482,
        partial_tiles: 282_541,
    };
    coverage.at_least(&measured.halved(), "clusters");
    // Measured: 2,163,744 (cluster, light) pairs listed, 1,260,430 (tile, light) pairs.
    assert!(
        cluster_pairs >= 2_163_744 / 2 && tile_pairs >= 1_260_430 / 2,
        "lists emptied: {cluster_pairs} cluster pairs, {tile_pairs} tile pairs"
    );
}

/// The CPU twins of GPU gather and of the BVH traversal contain the oracle, on tiles and
/// clusters; the traversal (which only prunes with boxes) lists exactly what gather lists.
#[test]
fn gather_and_bvh_twins_contain_the_oracle_in_randomized_cases() {
    let mut rng = Rng::new(4242);
    let mut coverage = common::Coverage::default();
    let mut inner_nodes = 0usize;
    for case_index in 0..TWIN_CASES {
        let mut case = random_case(&mut rng);
        // Enough lights for a hierarchy with inner nodes now and then.
        if case_index % 4 == 0 {
            let extra = case.lights.clone();
            for _ in 0..50 {
                case.lights.extend(extra.iter().map(|l| Light {
                    position: l.position
                        + Vec3::new(
                            rng.range(-9.0, 9.0),
                            rng.range(-9.0, 9.0),
                            rng.range(-9.0, 9.0),
                        ),
                    range: l.range * rng.range(0.1, 1.0),
                    ..*l
                }));
            }
        }
        let depth = random_depth(&mut rng, &case);
        let s = &case.setup;
        let tiles = GridDims::new(s.width, s.height, TILES[case_index % TILES.len()]).unwrap();
        let dims = tiles
            .clustered([1, 8, 32][case_index % 3], s.near, s.far)
            .unwrap();
        let view_distance = common::view_distances(s, &depth);
        let oracle = oracle_tile_lights(s, &dims, &case.lights, &view_distance);
        let bounds = cell_bounds_cpu(s, &dims, &depth);
        let gather = assign_gather_cpu(s, &dims, &case.lights, &bounds);
        for (c, must) in oracle.iter().enumerate() {
            for l in must {
                assert!(
                    gather.cell(c).contains(l),
                    "case {case_index}: gather misses light {l} in cell {c}: {:?}, camera {:?}",
                    case.lights[*l as usize],
                    case.camera
                );
            }
        }
        coverage.add(s, &dims, &case.lights, &oracle);
        let bvh = build_bvh(s, &case.lights);
        inner_nodes += bvh.nodes.iter().filter(|n| !n.is_leaf()).count();
        let walked = traverse_bvh_cpu(s, &dims, &case.lights, &bounds, None, &bvh);
        assert_eq!(walked, gather, "case {case_index}: the BVH pruned a light");
    }
    // At least half of what the cases measured (oracle (cell, light) pairs).
    let measured = common::Coverage {
        cases: 3000,
        odd_cases: 2955,
        hits: 3_433_556,
        containing: 2_604_196,
        behind: 20_636,
        crossing_near: 349_579,
        off_screen: 155_192,
        partial_tiles: 652_110,
    };
    coverage.at_least(&measured.halved(), "gather and BVH twins");
    // Measured: 2250 inner nodes over the 750 hierarchies of 1224 lights.
    assert!(
        inner_nodes >= 2250 / 2,
        "only {inner_nodes} inner BVH nodes: the hierarchies are flat"
    );
}

/// The grid checks the GPU tests rely on (`common::FrameOracle::check` and
/// `common::check_grid_against_twin`) pass on an intact grid and fail when one light the oracle
/// needs is taken out of one cell.
#[test]
fn grid_checks_catch_one_missing_light() {
    use lightgrid::culling::{Assign, LightGrid};
    use std::panic::{catch_unwind, AssertUnwindSafe};
    let mut rng = Rng::new(5);
    let mut damaged_cases = 0;
    for case_index in 0..60 {
        let case = random_case(&mut rng);
        let depth = random_depth(&mut rng, &case);
        let s = &case.setup;
        let dims = GridDims::new(s.width, s.height, TILES[case_index % TILES.len()])
            .unwrap()
            .clustered([1, 8, 32][case_index % 3], s.near, s.far)
            .unwrap();
        let bounds = cell_bounds_cpu(s, &dims, &depth);
        let grid = assign_gather_cpu(s, &dims, &case.lights, &bounds);
        let oracle = common::FrameOracle::new(s, &dims, &case.lights, &depth);
        let twin_check = |what: &str, g: &LightGrid| {
            common::check_grid_against_twin(
                what,
                Assign::Gather,
                s,
                g,
                &case.lights,
                (&bounds, None),
                false,
                4,
            )
        };
        assert_eq!(oracle.check("intact", s, &grid).at_slice_boundary, 0);
        assert_eq!(twin_check("intact", &grid), 0);
        let pairs: Vec<(usize, u32)> = oracle
            .cells
            .iter()
            .enumerate()
            .flat_map(|(c, must)| must.iter().map(move |&l| (c, l)))
            .collect();
        if pairs.is_empty() {
            continue;
        }
        let (c, l) = pairs[rng.below(pairs.len() as u32) as usize];
        let lists: Vec<Vec<u32>> = (0..grid.cells.len())
            .map(|i| {
                let list = grid.cell(i).iter().copied();
                list.filter(|&x| i != c || x != l).collect()
            })
            .collect();
        let damaged = LightGrid::from_lists(dims, &lists);
        assert_eq!(damaged.indices.len() + 1, grid.indices.len());
        let oracle_caught =
            catch_unwind(AssertUnwindSafe(|| oracle.check("damaged", s, &damaged))).is_err();
        let twin_caught =
            catch_unwind(AssertUnwindSafe(|| twin_check("damaged", &damaged))).is_err();
        assert!(
            oracle_caught && twin_caught,
            "case {case_index}: light {l} taken out of cell {c} went unnoticed (oracle check \
             caught it: {oracle_caught}, twin check: {twin_caught})"
        );
        damaged_cases += 1;
    }
    assert!(
        damaged_cases >= 50,
        "only {damaged_cases} cases had a hit to remove"
    );
}

/// The hierarchy's structure: root first, every light in exactly one leaf, at most 32
/// children, every box containing its children's boxes and its lights' spheres.
#[test]
fn light_bvh_is_well_formed() {
    let mut rng = Rng::new(7);
    let camera = Camera {
        eye: Vec3::new(0.0, 2.0, 10.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y: 1.0,
        near: 0.1,
        far: 300.0,
    };
    let setup = ViewSetup::new(&camera, 64, 64);
    for n in [0usize, 1, 31, 32, 33, 1025, 40_000] {
        let lights: Vec<Light> = (0..n)
            .map(|_| Light {
                position: Vec3::new(
                    rng.range(-80.0, 80.0),
                    rng.range(-5.0, 30.0),
                    rng.range(-80.0, 80.0),
                ),
                color: Vec3::ONE,
                intensity: 1.0,
                range: rng.range(0.05, 6.0),
                spot: None,
            })
            .collect();
        let bvh = build_bvh(&setup, &lights);
        if n == 0 {
            assert!(bvh.nodes.is_empty() && bvh.order.is_empty());
            continue;
        }
        let mut seen = vec![0u32; n];
        let mut visited = vec![false; bvh.nodes.len()];
        let mut stack = vec![0usize];
        let contains = |outer: &lightgrid::testing::BvhNode, lo: Vec3, hi: Vec3| {
            Vec3::from(outer.lo).cmple(lo).all() && Vec3::from(outer.hi).cmpge(hi).all()
        };
        while let Some(i) = stack.pop() {
            assert!(!visited[i], "node {i} reached twice");
            visited[i] = true;
            let node = bvh.nodes[i];
            let kids = node.children();
            assert!(
                (1..=32).contains(&kids.len()),
                "{n} lights: node {i} has {} children",
                kids.len()
            );
            for k in kids {
                if node.is_leaf() {
                    let l = bvh.order[k as usize] as usize;
                    seen[l] += 1;
                    let c = setup.view_point(lights[l].position);
                    let r = Vec3::splat(lights[l].range);
                    assert!(
                        contains(&node, c - r, c + r),
                        "leaf {i} box misses light {l}"
                    );
                } else {
                    let child = bvh.nodes[k as usize];
                    assert!(k as usize > i, "children come after their parent");
                    assert!(contains(&node, Vec3::from(child.lo), Vec3::from(child.hi)));
                    stack.push(k as usize);
                }
            }
        }
        assert!(visited.iter().all(|&v| v), "{n} lights: unreachable nodes");
        assert!(
            seen.iter().all(|&k| k == 1),
            "{n} lights: a light is not in exactly one leaf"
        );
    }
}

/// Lights near each other get nearby Morton codes; the code is monotone along each axis.
#[test]
fn morton_codes_interleave_axes() {
    use lightgrid::testing::morton_code;
    let (lo, ext) = (Vec3::ZERO, Vec3::splat(1.0));
    assert_eq!(morton_code(Vec3::ZERO, lo, ext), 0);
    assert_eq!(morton_code(Vec3::ONE, lo, ext), (1 << 30) - 1);
    assert_eq!(morton_code(Vec3::new(1.0, 0.0, 0.0), lo, ext), 0x0924_9249);
    assert_eq!(
        morton_code(Vec3::new(0.0, 1.0, 0.0), lo, ext),
        0x0924_9249 << 1
    );
    let a = morton_code(Vec3::new(0.2, 0.5, 0.5), lo, ext);
    let b = morton_code(Vec3::new(0.7, 0.5, 0.5), lo, ext);
    assert!(a < b);
    // Outside the box clamps instead of wrapping.
    assert_eq!(morton_code(Vec3::splat(5.0), lo, ext), (1 << 30) - 1);
}

#[test]
fn slices_are_exponential_and_match_their_ranges() {
    let dims = GridDims::new(64, 64, 16)
        .unwrap()
        .clustered(16, 0.5, 800.0)
        .unwrap();
    assert_eq!(dims.cell_count(), 16 * 16);
    for k in 0..16 {
        let [lo, hi] = dims.slice_range(k);
        let mid = if k == 0 {
            0.6
        } else if k == 15 {
            900.0
        } else {
            (lo * hi).sqrt()
        };
        assert_eq!(dims.slice_of(mid), k, "slice {k} [{lo}, {hi}]");
        if k > 0 && k < 15 {
            assert!(
                (hi / lo - (1600f32).powf(1.0 / 16.0)).abs() < 1e-3,
                "exponential spacing"
            );
        }
    }
    assert!(GridDims::new(64, 64, 16)
        .unwrap()
        .clustered(0, 0.5, 800.0)
        .is_err());
    assert!(GridDims::new(64, 64, 16)
        .unwrap()
        .clustered(16, 0.0, 800.0)
        .is_err());
}

#[test]
fn projected_rectangle_contains_every_visible_point_of_the_sphere() {
    let mut rng = Rng::new(77);
    for _ in 0..2000 {
        let case = random_case(&mut rng);
        let s = &case.setup;
        for l in &case.lights {
            let v = s.to_view(l);
            let rect = project_sphere(s, &v);
            for _ in 0..64 {
                // A random point inside the ball, in front of the near plane.
                let d = Vec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                );
                if d.length() > 1.0 {
                    continue;
                }
                let p = v.center + d * v.radius;
                let w = -p.z;
                if w < s.near || w > s.far {
                    continue;
                }
                let px = ((s.p00 * p.x / w) * 0.5 + 0.5) * s.width as f32;
                let py = (0.5 - (s.p11 * p.y / w) * 0.5) * s.height as f32;
                if px < 0.0 || py < 0.0 || px >= s.width as f32 || py >= s.height as f32 {
                    continue;
                }
                let r = rect.unwrap_or_else(|| {
                    panic!("visible point {p:?} of light {v:?} but no rectangle")
                });
                let (ix, iy) = (px as u32, py as u32);
                assert!(
                    r.x0 <= ix && ix <= r.x1 && r.y0 <= iy && iy <= r.y1,
                    "pixel ({ix}, {iy}) of light {v:?} outside {r:?}"
                );
            }
        }
    }
}

#[test]
fn lights_entirely_behind_the_camera_or_beyond_far_are_culled() {
    let camera = Camera {
        eye: Vec3::ZERO,
        target: -Vec3::Z,
        up: Vec3::Y,
        fov_y: 1.0,
        near: 0.5,
        far: 100.0,
    };
    let s = ViewSetup::new(&camera, 64, 48);
    let behind = s.to_view(&Light {
        position: Vec3::new(0.0, 0.0, 5.0),
        color: Vec3::ONE,
        intensity: 1.0,
        range: 4.0,
        spot: None,
    });
    assert_eq!(project_sphere(&s, &behind), None);
    let beyond = s.to_view(&Light {
        position: Vec3::new(0.0, 0.0, -120.0),
        color: Vec3::ONE,
        intensity: 1.0,
        range: 10.0,
        spot: None,
    });
    assert_eq!(project_sphere(&s, &beyond), None);
    // Containing the camera: covers the whole screen.
    let around = s.to_view(&Light {
        position: Vec3::new(0.1, 0.0, 0.2),
        color: Vec3::ONE,
        intensity: 1.0,
        range: 3.0,
        spot: None,
    });
    let r = project_sphere(&s, &around).unwrap();
    assert_eq!((r.x0, r.x1, r.y0, r.y1), (0, 63, 0, 47));
    // Small and to the right: only the right part of the screen.
    let right = s.to_view(&Light {
        position: Vec3::new(8.0, 0.0, -20.0),
        color: Vec3::ONE,
        intensity: 1.0,
        range: 1.0,
        spot: None,
    });
    let r = project_sphere(&s, &right).unwrap();
    assert!(r.x0 > 40 && r.x1 < 63 && r.y0 > 10 && r.y1 < 40, "{r:?}");
}

#[test]
fn cell_bounds_ignore_sky_mark_empty_cells_and_cover_slice_boundaries() {
    let camera = Camera {
        eye: Vec3::ZERO,
        target: -Vec3::Z,
        up: Vec3::Y,
        fov_y: 1.0,
        near: 0.5,
        far: 100.0,
    };
    let s = ViewSetup::new(&camera, 10, 5);
    let tiles = GridDims::new(10, 5, 4).unwrap();
    assert_eq!((tiles.tiles_x, tiles.tiles_y), (3, 2));
    let to_depth = |w: f32| s.depth_of(w);
    let mut depth = vec![lightgrid::depth::CLEAR; 50];
    depth[0] = to_depth(2.0);
    depth[13] = to_depth(1.0); // (3, 1): tile 0
    depth[9] = to_depth(50.0); // (9, 0): tile 2, a partial tile
    let b = cell_bounds_cpu(&s, &tiles, &depth);
    let close = |a: f32, b: f32| (a - b).abs() <= 1e-4 * b;
    assert!(close(b[0][0], 1.0) && close(b[0][1], 2.0), "{:?}", b[0]);
    assert!(close(b[2][0], 50.0) && close(b[2][1], 50.0));
    assert_eq!(b[1], EMPTY_CELL, "tile without samples is empty");
    // Clustered: each sample lands in its slice; one on a slice boundary in both.
    let dims = tiles.clustered(8, s.near, s.far).unwrap();
    let boundary = dims.slice_range(3)[0];
    depth[1] = to_depth(boundary);
    let c = cell_bounds_cpu(&s, &dims, &depth);
    let cell = |k: u32, t: usize| c[k as usize * tiles.tile_count() + t];
    assert!(close(cell(dims.slice_of(1.0), 0)[0], 1.0));
    assert!(
        cell(2, 0)[0] <= cell(2, 0)[1] && cell(3, 0)[0] <= cell(3, 0)[1],
        "both sides of the boundary"
    );
    let occupied = c.iter().filter(|[lo, hi]| lo <= hi).count();
    // Slices 1 (w = 1), 2 (w = 2 and the boundary sample), 3 (the boundary sample), 6 (w = 50).
    assert_eq!(occupied, 4, "{c:?}");
    assert!(
        close(cell(2, 0)[1], boundary),
        "the boundary sample widens the slice below it"
    );
    assert!(GridDims::new(10, 5, 0).is_err() && GridDims::new(10, 5, 65).is_err());
}

#[test]
fn light_volume_classes_follow_the_clip_planes() {
    use lightgrid::passes::classify_lights;
    let camera = Camera {
        eye: Vec3::ZERO,
        target: -Vec3::Z,
        up: Vec3::Y,
        fov_y: 1.0,
        near: 0.5,
        far: 100.0,
    };
    let s = ViewSetup::new(&camera, 64, 48);
    let light = |z: f32, range: f32| Light {
        position: Vec3::new(0.0, 0.0, z),
        color: Vec3::ONE,
        intensity: 1.0,
        range,
        spot: None,
    };
    let lights = [
        light(-20.0, 5.0),  // 0: in the middle: front faces
        light(-1.0, 3.0),   // 1: contains the camera: back faces
        light(-50.0, 80.0), // 2: reaches both planes: full screen
        light(-98.0, 5.0),  // 3: reaches the far plane only: front faces
        light(10.0, 5.0),   // 4: behind the camera: nothing
        light(-120.0, 5.0), // 5: beyond far: nothing
    ];
    let c = classify_lights(&s, &lights, false);
    assert_eq!(
        (c.front.clone(), c.back.clone(), c.full.clone()),
        (vec![0, 3], vec![1], vec![2])
    );
    assert!(c.stencil.is_empty());
    let c = classify_lights(&s, &lights, true);
    // The z-fail stencil test needs unclipped back faces: far-plane lights keep the plain draws.
    assert_eq!(
        (c.stencil.clone(), c.front.clone(), c.full.clone()),
        (vec![0, 1], vec![3], vec![2])
    );
}

#[test]
fn auto_assignment_resolves_by_adapter_and_light_count() {
    use lightgrid::culling::{Assign, AUTO_GATHER_MAX_LIGHTS};
    for n in [0, 1, 1000, 1_000_000] {
        assert_eq!(
            Assign::Auto.resolve(n, true),
            Assign::Cpu,
            "software, {n} lights"
        );
    }
    assert_eq!(Assign::Auto.resolve(100, false), Assign::Gather);
    assert_eq!(
        Assign::Auto.resolve(AUTO_GATHER_MAX_LIGHTS, false),
        Assign::Gather
    );
    assert_eq!(
        Assign::Auto.resolve(AUTO_GATHER_MAX_LIGHTS + 1, false),
        Assign::BvhGpu
    );
    for a in Assign::all().filter(|&a| a != Assign::Auto) {
        assert_eq!(a.resolve(5, true), a);
        assert_eq!(a.resolve(5_000_000, false), a);
    }
    let names: Vec<&str> = Assign::all().map(|a| a.name()).collect();
    assert_eq!(
        names,
        ["cpu", "gather", "scatter", "bvh", "bvh-gpu", "zbin", "auto"]
    );
}

/// Dispatches above the per-dimension limit fold into two dimensions that cover every item.
#[test]
fn one_dimensional_dispatches_fold_past_the_workgroup_limit() {
    use lightgrid::gpu::groups_1d;
    assert_eq!(groups_1d(0), (1, 1));
    assert_eq!(groups_1d(1), (1, 1));
    assert_eq!(groups_1d(65_535), (65_535, 1));
    assert_eq!(groups_1d(65_536), (65_535, 2));
    for n in [65_536u32, 200_000, 4_000_000] {
        let (x, y) = groups_1d(n);
        assert!(x <= 65_535 && y <= 65_535);
        assert!(u64::from(x) * u64::from(y) >= u64::from(n));
        assert!(
            u64::from(x) * u64::from(y - 1) < u64::from(n),
            "no spare row"
        );
    }
}

/// A spot's bounding sphere holds everything it lights and is tight (some lit point lies near
/// its surface); the cone test never rejects a sphere that holds a lit point. Cones from 1° to
/// 179°, points sampled inside the cone sector and spheres around them.
#[test]
fn spot_bounds_and_cone_test_never_lose_a_lit_point() {
    use lightgrid::scene::{Spot, SpotCull};
    let mut rng = Rng::new(13);
    let camera = Camera {
        eye: Vec3::new(0.0, 2.0, 10.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y: 1.0,
        near: 0.1,
        far: 100.0,
    };
    let mut setup = ViewSetup::new(&camera, 64, 64);
    setup.spot_cull = SpotCull::Cone;
    let (mut lit, mut rejected) = (0, 0);
    for case in 0..2000 {
        let outer = (1.0 + 178.0 * (case as f32 / 1999.0)).to_radians();
        let dir = Vec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        let light = Light {
            position: Vec3::new(
                rng.range(-5.0, 5.0),
                rng.range(-5.0, 5.0),
                rng.range(-5.0, 5.0),
            ),
            color: Vec3::ONE,
            intensity: 1.0,
            range: rng.range(0.5, 20.0),
            spot: Some(Spot::new(dir, outer * 0.5, outer)),
        };
        let (c, r) = light.bounding_sphere();
        let v = setup.to_view(&light);
        let mut farthest = 0.0f32;
        // Lit points: sampled inside the sector (angle to the axis up to the outer cone,
        // distance up to the range), reaching its rim.
        let spot = light.spot.unwrap();
        let perp = spot.direction.any_orthonormal_vector();
        for _ in 0..100 {
            let phi = rng.range(0.0, std::f32::consts::TAU);
            let q = perp * phi.cos() + spot.direction.cross(perp) * phi.sin();
            let a = outer * rng.unit().sqrt() * 0.999;
            let d = light.range * rng.unit().cbrt() * 0.999;
            let p = light.position + (spot.direction * a.cos() + q * a.sin()) * d;
            assert!(
                light.reaches(p),
                "case {case}: a point inside the sector is not lit"
            );
            lit += 1;
            let dist = p.distance(c);
            farthest = farthest.max(dist);
            assert!(
                dist <= r * (1.0 + 1e-5) + 1e-5,
                "case {case}: lit point outside the bound"
            );
            let pv = setup.view_point(p);
            assert!(v.reaches(pv), "view-space reach disagrees");
            let around = pv + Vec3::new(rng.range(-1.0, 1.0), 0.0, 0.0);
            assert!(
                v.may_reach_sphere(around, pv.distance(around)),
                "case {case}: the cone test rejected a sphere holding a lit point"
            );
        }
        // The rim and the apex lie on the sphere: sampled points come close to it.
        assert!(
            farthest > r * 0.8,
            "case {case}: bound {r} much larger than the cone ({farthest})"
        );
        // Small spheres around unlit points may be rejected, never those holding a lit one.
        for _ in 0..100 {
            let p = light.position
                + Vec3::new(
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                    rng.range(-1.0, 1.0),
                ) * light.range;
            let pv = setup.view_point(p);
            if !light.reaches(p) && !v.may_reach_sphere(pv, 0.01) {
                rejected += 1;
            }
        }
    }
    assert_eq!(lit, 200_000);
    // Measured: 137,612 of the 200,000 cube samples rejected (unlit, small sphere); at least
    // half of that must stay.
    assert!(rejected > 68_000, "the cone test must cull: {rejected}");
}

/// Test (b) of the spot-light issue, measured and not shipped (`culling::ray_test_count`: the
/// post's ray through each tile's centre against a cone thickened on the CPU,
/// tiled-deferred-tricks Trick 2, with its constants). Over randomized cases it misses tiles
/// the oracle says a spot lights, which is why `--spot-cull cone` tests against each cell's
/// bounding sphere instead. The counts are printed (`--nocapture`) for README.
#[test]
fn the_posts_ray_against_a_thickened_cone_misses_lit_tiles() {
    use lightgrid::culling::ray_test_count;
    let mut rng = Rng::new(2024);
    let (mut lit_pairs, mut missed) = (0u64, 0u64);
    for _ in 0..1000 {
        let case = random_case(&mut rng);
        let depth = random_depth(&mut rng, &case);
        let count = ray_test_count(&case.setup, 8, &case.lights, &depth).unwrap();
        assert!(count.missed_pairs <= count.lit_pairs);
        lit_pairs += count.lit_pairs;
        missed += count.missed_pairs;
    }
    eprintln!("ray vs thickened cone: {missed} of {lit_pairs} lit (tile, spot) pairs missed");
    assert!(
        lit_pairs > 10_000,
        "{lit_pairs} lit pairs: the cases must light tiles"
    );
    assert!(
        missed > 0,
        "the post's test missed nothing here: measure again before shipping it"
    );
}

/// Transparent fragments in front of the opaque samples (or anywhere up to the far plane
/// where a pixel has none): a few per pixel on a random subset of pixels, some just in front
/// of the opaque depth, some at the near plane, some at slice boundaries' scale.
fn random_fragments(rng: &mut Rng, s: &ViewSetup, view_distance: &[f32]) -> Vec<Fragment> {
    let mut out = Vec::new();
    for y in 0..s.height {
        for x in 0..s.width {
            if rng.unit() > 0.3 {
                continue;
            }
            let opaque = view_distance[(y * s.width + x) as usize].min(s.far);
            for k in 0..1 + rng.below(3) {
                let t = match k {
                    0 => rng.unit(),
                    1 => 0.999,
                    _ => 0.0,
                };
                let w = s.near * (opaque / s.near).powf(t);
                if w >= s.near && w < opaque {
                    out.push(Fragment { x, y, w });
                }
            }
        }
    }
    out
}

/// tiled-forward-shading §4.5's two lists: every transparent fragment's list (separate or
/// shared) holds every light reaching it, on tiles and clusters, for the CPU assignment and
/// the gather/BVH twin; the opaque lists of separate grids still hold the oracle's lights and
/// never more than the shared list.
#[test]
fn transparent_lists_contain_the_oracle_in_randomized_cases() {
    let mut rng = Rng::new(4242);
    let (mut fragments_checked, mut lit_pairs) = (0usize, 0usize);
    let (mut separate_entries, mut shared_entries) = (0usize, 0usize);
    for case_index in 0..600 {
        let case = random_case(&mut rng);
        let depth = random_depth(&mut rng, &case);
        let s = &case.setup;
        let tile = TILES[case_index % TILES.len()];
        let slices = [1, 1, 8, 32][case_index % 4];
        let tiles = GridDims::new(s.width, s.height, tile).unwrap();
        let base = if slices > 1 {
            tiles.clustered(slices, s.near, s.far).unwrap()
        } else {
            tiles
        };
        let view_distance = common::view_distances(s, &depth);
        let fragments = random_fragments(&mut rng, s, &view_distance);
        fragments_checked += fragments.len();
        for lists in [GridLists::Separate, GridLists::Shared] {
            let dims = base.with_lists(lists);
            let bounds = cell_bounds_cpu(s, &dims, &depth);
            assert_eq!(bounds.len(), dims.cell_count());
            let must = oracle_fragment_lights(s, &dims, &case.lights, &fragments);
            let opaque = oracle_tile_lights(s, &dims, &case.lights, &view_distance);
            let grids = [
                (
                    "cpu",
                    assign_cpu(s, &dims, &case.lights, DepthRange::Cells(&bounds)),
                ),
                ("gather", assign_gather_cpu(s, &dims, &case.lights, &bounds)),
            ];
            for (name, grid) in &grids {
                for (c, list) in must.iter().enumerate().chain(opaque.iter().enumerate()) {
                    for l in list {
                        assert!(
                            grid.cell(c).contains(l),
                            "case {case_index} {name} {} lists: cell {c} (layer {}, slice {} of {slices}, tile {tile}) misses light {l}: {:?}, camera {:?}",
                            lists.name(),
                            dims.layer_of_cell(c),
                            dims.slice_of_cell(c),
                            case.lights[*l as usize],
                            case.camera
                        );
                    }
                }
            }
            if lists == GridLists::Separate {
                lit_pairs += must.iter().map(Vec::len).sum::<usize>();
                // The opaque layer, pruned by the tiles' minimum too.
                separate_entries += (0..dims.layer_cells())
                    .map(|c| grids[0].1.cell(c).len())
                    .sum::<usize>();
            } else {
                shared_entries += grids[0].1.indices.len();
            }
        }
    }
    assert!(fragments_checked > 100_000, "{fragments_checked} fragments");
    assert!(lit_pairs > 10_000, "{lit_pairs} lit (cell, light) pairs");
    // Separate lists make the opaque samples' lists shorter than the shared ones.
    assert!(
        separate_entries < shared_entries,
        "opaque lists {separate_entries} vs shared {shared_entries}"
    );
}
