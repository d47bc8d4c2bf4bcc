//! Helpers shared by the integration tests: the GPU context, image comparison with its
//! tolerances, and the light-grid checks (CPU twin, brute-force oracle, edge-case coverage).
#![allow(dead_code)]

pub mod file_reference;
pub mod gltf_fixture;
pub mod shading;

use glam::Vec3;
use lightgrid::culling::{assign_cpu, DepthRange, GridDims, GridLists, LightGrid, ViewSetup};
use lightgrid::gpu::GpuContext;
use lightgrid::pipelines::Assign;
use lightgrid::scene::{Camera, Light, Rng, Spot};
use lightgrid::testing::{
    assign_gather_cpu_masked, cell_bounds_cpu, cell_boxes_cpu, cell_masks_cpu, oracle_tile_lights,
    zbins_cpu, CellCull, CellMask, NO_MASK,
};
use std::path::PathBuf;

/// Every pipeline whose grid `--assign` builds, from the registry.
pub fn grid_pipelines() -> Vec<&'static str> {
    lightgrid::pipelines::PIPELINES
        .iter()
        .filter(|p| p.assign)
        .map(|p| p.id)
        .collect()
}

/// Every strategy of the registry.
pub fn strategies() -> Vec<Assign> {
    lightgrid::testing::STRATEGIES
        .iter()
        .map(|s| s.assign)
        .collect()
}

/// The strategies that build per-cell lists (every one but z-binning): those 2.5D masks and
/// tight boxes cut.
pub fn list_strategies() -> Vec<Assign> {
    strategies()
        .into_iter()
        .filter(|&a| a != Assign::ZBin)
        .collect()
}

/// A GPU context, or a failing test. A missing adapter is never a pass: install
/// `mesa-vulkan-drivers` for Mesa's software Vulkan adapter (what CI does). The device has
/// WebGPU's default limits (8 storage buffers per stage, 4 bind groups), what every browser
/// offers: every pipeline and strategy the tests render runs within them, and a binding
/// beyond them fails the tests.
pub fn gpu() -> GpuContext {
    gpu_with(lightgrid::gpu::DeviceLimits::WebGpu)
}

/// [`gpu`] with `limits`: the adapter's for what asks for more than WebGPU's defaults (the
/// 32-bit G-buffer's 64 bytes of colour attachments per sample).
pub fn gpu_with(limits: lightgrid::gpu::DeviceLimits) -> GpuContext {
    let wanted = std::env::var("LIGHTGRID_ADAPTER").ok();
    match GpuContext::with_limits(wanted.as_deref(), limits) {
        Ok(ctx) => {
            // CI installs lavapipe; a GL fallback there would mean the install step broke.
            if std::env::var("CI").is_ok_and(|v| v == "true") && wanted.is_none() {
                assert_eq!(
                    ctx.info.backend,
                    wgpu::Backend::Vulkan,
                    "under CI the GPU tests must run on Vulkan (lavapipe), got {}",
                    ctx.adapter_label()
                );
            }
            ctx
        }
        Err(e) => panic!(
            "GPU test cannot run: {e}\n(GPU tests fail without an adapter, they never skip; \
             CI installs mesa-vulkan-drivers)"
        ),
    }
}

/// Where failing image tests write the actual image and the diff image.
pub fn output_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/test-output");
    std::fs::create_dir_all(&dir).expect("create target/test-output");
    dir
}

/// Blessed reference images live here; `LIGHTGRID_BLESS=1` rewrites them.
pub fn golden_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

/// `LIGHTGRID_BLESS=1` rewrites the goldens instead of comparing with them: refused under
/// any non-empty `CI` (`true`, `1`, a CI's name), where it would turn every image check into
/// a pass.
pub fn blessing() -> bool {
    let var = |name| std::env::var(name).ok();
    blessing_with(var("LIGHTGRID_BLESS").as_deref(), var("CI").as_deref())
        .unwrap_or_else(|e| panic!("{e}"))
}

/// [`blessing`]'s rule for the two variables' values (None: unset).
pub fn blessing_with(bless: Option<&str>, ci: Option<&str>) -> Result<bool, String> {
    let bless = bless == Some("1");
    match ci {
        Some(ci) if bless && !ci.is_empty() => Err(format!(
            "LIGHTGRID_BLESS=1 is refused under CI={ci}: goldens are re-blessed by hand, never by CI"
        )),
        _ => Ok(bless),
    }
}

/// An image comparison's bounds, in 8-bit sRGB levels; a pixel's difference is its largest
/// channel difference (as in `image_io::diff`). The mean and p99 bound round-off spread over
/// the frame; `max_over` bounds how many pixels may differ by more than `level`, so a region
/// that one missing light darkens cannot hide below the mean and the 99th percentile.
#[derive(Clone, Copy, Debug)]
pub struct ImageTolerance {
    pub max_mean: f64,
    pub max_p99: f64,
    pub level: u8,
    pub max_over: u64,
    /// A second (level, max_over) bound: a tight level with room for the few pixels the main
    /// level exists for (the MSAA edge pixels that differ by design), so a dim missing light,
    /// which changes many pixels by a few levels, cannot hide under the main level.
    pub fine: Option<(u8, u64)>,
}

/// What [`compare_images`] measured.
pub struct ImageComparison {
    pub summary: lightgrid::image_io::DiffSummary,
    /// Pixels whose difference exceeds the tolerance's `level`.
    pub over: u64,
    /// Pixels over the `fine` bound's level (0 without one).
    pub over_fine: u64,
    /// The visual diff image (`image_io::diff`).
    pub visual: image::RgbaImage,
    pub tolerance: ImageTolerance,
}

impl ImageComparison {
    /// The bounds this comparison breaks, as text (empty: within tolerance).
    pub fn violations(&self) -> Vec<String> {
        let (d, t) = (&self.summary, &self.tolerance);
        let mut v = Vec::new();
        if d.mean > t.max_mean {
            v.push(format!("mean {:.4} > {}", d.mean, t.max_mean));
        }
        if d.p99 > t.max_p99 {
            v.push(format!("p99 {} > {}", d.p99, t.max_p99));
        }
        if self.over > t.max_over {
            v.push(format!(
                "{} pixels differ by more than {} levels (at most {} allowed)",
                self.over, t.level, t.max_over
            ));
        }
        if let Some((level, max_over)) = t.fine.filter(|&(_, max)| self.over_fine > max) {
            v.push(format!(
                "{} pixels differ by more than {level} levels (at most {max_over} allowed)",
                self.over_fine
            ));
        }
        v
    }

    pub fn passes(&self) -> bool {
        self.violations().is_empty()
    }

    /// One line for a failure message: every measure and every bound.
    pub fn describe(&self) -> String {
        let (d, t) = (&self.summary, &self.tolerance);
        format!(
            "mean {:.4} p99 {} max {}, {} pixels over {} levels{} (allowed mean {} p99 {}, {} over {}{}){}",
            d.mean,
            d.p99,
            d.max,
            self.over,
            t.level,
            t.fine.map_or(String::new(), |(l, _)| format!(", {} over {l}", self.over_fine)),
            t.max_mean,
            t.max_p99,
            t.max_over,
            t.level,
            t.fine.map_or(String::new(), |(l, m)| format!(", {m} over {l}")),
            match self.violations() {
                v if v.is_empty() => String::new(),
                v => format!(": {}", v.join("; ")),
            }
        )
    }
}

/// Per-pixel differences (largest absolute channel difference, alpha ignored) of two images of
/// the same size, as a histogram over the 256 levels.
pub fn difference_histogram(a: &image::RgbaImage, b: &image::RgbaImage) -> [u64; 256] {
    lightgrid::image_io::difference_histogram(a, b).expect("image sizes differ")
}

/// How many pixels differ by more than `level`.
pub fn pixels_over(a: &image::RgbaImage, b: &image::RgbaImage, level: u8) -> u64 {
    difference_histogram(a, b)[usize::from(level) + 1..]
        .iter()
        .sum()
}

/// `image_io::diff` plus the count of pixels over the tolerance's level (and over its `fine`
/// level).
pub fn compare_images(
    expected: &image::RgbaImage,
    actual: &image::RgbaImage,
    tolerance: ImageTolerance,
) -> ImageComparison {
    compare_images_outside(expected, actual, tolerance, None)
}

/// [`compare_images`] with the `fine` bound counting only the pixels `excluded` does not
/// mark (row-major; the MSAA edge pixels of [`msaa_edge_pixels`]).
pub fn compare_images_outside(
    expected: &image::RgbaImage,
    actual: &image::RgbaImage,
    tolerance: ImageTolerance,
    excluded: Option<&[bool]>,
) -> ImageComparison {
    let (summary, visual) = lightgrid::image_io::diff(expected, actual).unwrap();
    let over_fine = tolerance.fine.map_or(0, |(level, _)| {
        (expected.pixels().zip(actual.pixels()).enumerate())
            .filter(|(i, _)| !excluded.is_some_and(|e| e[*i]))
            .filter(|(_, (p, q))| (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap() > level)
            .count() as u64
    });
    ImageComparison {
        summary,
        over: pixels_over(expected, actual, tolerance.level),
        over_fine,
        visual,
        tolerance,
    }
}

/// The pixels of an MSAA frame (its depth, one plane per sample) whose samples do not lie on
/// one plane, with their eight neighbours: where a deferred pipeline shades each sample's
/// surface and forward the pixel centre's, so they differ by design. Depth (`A / w - B`) is
/// affine in screen space over a plane, so a pixel is an edge when one of its samples is
/// background and another is not, or when the fourth sample departs from the plane through
/// the other three (at the standard 4x sample positions) by more than 1e-5 of its depth.
pub fn msaa_edge_pixels(depth_samples: &[Vec<f32>], (w, h): (u32, u32)) -> Vec<bool> {
    assert_eq!(depth_samples.len(), 4, "the standard 4x sample positions");
    const AT: [(f64, f64); 4] = [
        (0.375, 0.125),
        (0.875, 0.375),
        (0.125, 0.625),
        (0.625, 0.875),
    ];
    let n = (w * h) as usize;
    let edge: Vec<bool> = (0..n)
        .map(|i| {
            let d: Vec<f64> = depth_samples
                .iter()
                .map(|plane| f64::from(plane[i]))
                .collect();
            if d.iter().any(|&x| x <= 0.0) {
                return d.iter().any(|&x| x > 0.0);
            }
            // The plane d = a + b x + c y through samples 0, 1 and 2, at sample 3.
            let [(x0, y0), (x1, y1), (x2, y2), (x3, y3)] = AT;
            let det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
            let b = ((d[1] - d[0]) * (y2 - y0) - (d[2] - d[0]) * (y1 - y0)) / det;
            let c = ((x1 - x0) * (d[2] - d[0]) - (x2 - x0) * (d[1] - d[0])) / det;
            let predicted = d[0] + b * (x3 - x0) + c * (y3 - y0);
            (predicted - d[3]).abs() > 1e-5 * d[3]
        })
        .collect();
    (0..n)
        .map(|i| {
            let (x, y) = ((i as u32 % w) as i64, (i as u32 / w) as i64);
            (-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    let (nx, ny) = (x + dx, y + dy);
                    nx >= 0
                        && ny >= 0
                        && nx < i64::from(w)
                        && ny < i64::from(h)
                        && edge[(ny * i64::from(w) + nx) as usize]
                })
            })
        })
        .collect()
}

/// The lights the missing-light self-tests add and then leave out, as a culling bug that drops
/// one light from its cells would: the tolerances must catch a light that is dim, not only
/// the brightest one.
#[derive(Clone, Copy, Debug)]
pub enum MissingLight {
    /// The scene's median light (colour, intensity, range) 0.8 of its range above the
    /// surface seen at the middle of the image's lower fifth (the near ground, where a lit
    /// region covers pixels): only the outer edge of its range reaches anything, at most
    /// (1 - 0.8²)² = 13% of its radiance.
    DimAtRangeEdge,
    /// The same light half its range above a distant surface of the image's middle row (the
    /// one farther than three quarters of that row's): brighter, but small in the frame.
    Distant,
}

impl MissingLight {
    pub const ALL: [MissingLight; 2] = [MissingLight::DimAtRangeEdge, MissingLight::Distant];
}

/// `scene` with the light of `case` added as its last light, placed from what frame `frame`
/// shows at `size` (the CPU ray caster of `shading` finds the surfaces).
pub fn with_missing_light(
    scene: &lightgrid::scene::Scene,
    frame: u32,
    size: (u32, u32),
    case: MissingLight,
) -> lightgrid::scene::Scene {
    let f = shading::Frame::new(scene, frame, size);
    let eye = scene.frame(frame).camera.eye;
    let seen = |x: u32, y: u32| {
        let (cx, cy) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
        f.seen(cx, cy)
            .map(|(hit, _, _)| eye + (f.ray(cx, cy) * hit.t).as_vec3())
    };
    let (w, h) = size;
    let (surface, height) = match case {
        MissingLight::DimAtRangeEdge => (seen(w / 2, h * 4 / 5), 0.8),
        MissingLight::Distant => {
            let mut row: Vec<Vec3> = (0..w).filter_map(|x| seen(x, h / 2)).collect();
            row.sort_by(|a, b| a.distance(eye).total_cmp(&b.distance(eye)));
            (row.get(row.len() * 3 / 4).copied(), 0.5)
        }
    };
    let surface = surface.expect("a surface to light");
    let mut lights: Vec<Light> = scene.lights.iter().map(|l| l.light).collect();
    lights.sort_by(|a, b| a.intensity.total_cmp(&b.intensity));
    let median = lights[lights.len() / 2];
    let mut out = scene.clone();
    out.lights.push(lightgrid::scene::SceneLight {
        light: Light::point(
            surface + Vec3::Y * (median.range * height),
            median.color,
            median.intensity,
            median.range,
        ),
        anchor: lightgrid::scene::LightAnchor::World,
    });
    out
}

/// The missing-light self-test of `tolerance`: `reference` rendered the scene with the light
/// of `case`, `with` is the image under test with it and `without` the same image without it.
/// The first passes; the second must fail, and by the count of pixels over the level (mean
/// and p99 alone let a small region through). Also that the light mattered: at least 10
/// pixels of the reference change by more than 4 levels without it, or the case tests
/// nothing.
pub fn assert_missing_light_fails(
    what: &str,
    case: MissingLight,
    tolerance: ImageTolerance,
    [reference, with, without]: [&image::RgbaImage; 3],
    excluded: Option<&[bool]>,
) {
    let intact = compare_images_outside(reference, with, tolerance, excluded);
    assert!(
        intact.passes(),
        "{what}, {case:?}: with the light: {}",
        intact.describe()
    );
    let missing = compare_images_outside(reference, without, tolerance, excluded);
    eprintln!(
        "MEASURED {what}, {case:?}: with {}; without {}",
        intact.describe(),
        missing.describe()
    );
    let caught_by_count = missing.over > tolerance.max_over
        || tolerance
            .fine
            .is_some_and(|(_, max)| missing.over_fine > max);
    assert!(
        caught_by_count,
        "{what}, {case:?}: a missing light passes the count bound: {}",
        missing.describe()
    );
    let changed = pixels_over(reference, without, 4);
    assert!(
        changed >= 10,
        "{what}, {case:?}: the light changes only {changed} pixels"
    );
}

/// `image` with a disc of `pixels` pixels darkened by `levels` in every channel: what
/// one missing light does to the samples it alone reached. The disc goes where the image is
/// brightest (its centre on the pixel whose disc has the largest sum of channel maxima), so
/// that darkening really changes it; returns the damaged image and how many pixels of it now
/// differ by the full `levels`.
pub fn darken_disc(image: &image::RgbaImage, pixels: u32, levels: u8) -> (image::RgbaImage, u32) {
    let (w, h) = image.dimensions();
    // The `pixels` offsets nearest the centre: a disc of exactly that many pixels.
    let r = (f64::from(pixels) / std::f64::consts::PI).sqrt().ceil() as i64 + 1;
    let mut offsets: Vec<(i64, i64)> = (-r..=r)
        .flat_map(|dy| (-r..=r).map(move |dx| (dx, dy)))
        .collect();
    offsets.sort_by_key(|&(dx, dy)| (dx * dx + dy * dy, dy, dx));
    offsets.truncate(pixels as usize);
    let value = |x: i64, y: i64| -> u64 {
        if x < 0 || y < 0 || x >= i64::from(w) || y >= i64::from(h) {
            return 0;
        }
        let p = image.get_pixel(x as u32, y as u32);
        u64::from(p[0].max(p[1]).max(p[2]).min(levels))
    };
    let mut best = (0u64, 0i64, 0i64);
    for cy in 0..i64::from(h) {
        for cx in 0..i64::from(w) {
            let sum: u64 = offsets
                .iter()
                .map(|&(dx, dy)| value(cx + dx, cy + dy))
                .sum();
            if sum > best.0 {
                best = (sum, cx, cy);
            }
        }
    }
    let (_, cx, cy) = best;
    let mut out = image.clone();
    let mut full = 0;
    for &(dx, dy) in &offsets {
        let (x, y) = (cx + dx, cy + dy);
        if x < 0 || y < 0 || x >= i64::from(w) || y >= i64::from(h) {
            continue;
        }
        let p = out.get_pixel_mut(x as u32, y as u32);
        let before = p[0].max(p[1]).max(p[2]);
        for c in 0..3 {
            p[c] = p[c].saturating_sub(levels);
        }
        if before >= levels {
            full += 1;
        }
    }
    (out, full)
}

/// Each sample's view distance from a [0, 1] depth buffer; infinite where there is no geometry
/// (what `oracle_tile_lights` reads).
pub fn view_distances(setup: &ViewSetup, depth: &[f32]) -> Vec<f32> {
    setup.view_distances(depth)
}

/// With probability 0.4, a spot cone for a light at `position`: pointing at the camera at
/// `eye`, away from it, or anywhere; narrow (2°) to wide (179°), so cones cross the near plane,
/// contain the camera, point toward and away from it and reach past screen edges.
pub fn random_spot(rng: &mut Rng, position: Vec3, eye: Vec3) -> Option<Spot> {
    let (pick, kind, outer) = (rng.unit(), rng.below(4), rng.range(2.0, 179.0));
    let any = Vec3::new(
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
    );
    let inner = rng.range(0.1, 0.95);
    if pick >= 0.4 {
        return None;
    }
    let direction = match kind {
        0 => eye - position,
        1 => position - eye,
        _ => any,
    };
    let outer = outer.to_radians();
    Some(Spot::new(direction, outer * inner, outer))
}

/// `n` lights placed relative to `camera` where light assignment goes wrong: containing the
/// camera, crossing the near plane, behind the camera reaching forward, centred just outside a
/// screen edge, and scattered through the frustum (one of each in turn, the last twice).
pub fn edge_case_lights(rng: &mut Rng, camera: &Camera, setup: &ViewSetup, n: usize) -> Vec<Light> {
    let world = |v: Vec3| setup.world_point(v);
    let mut lights = Vec::with_capacity(n);
    for k in 0..n {
        let r = rng.range(0.3, 10.0);
        let v = match k % 6 {
            0 => Vec3::new(rng.range(-r, r), rng.range(-r, r), rng.range(-r, r)) * 0.5,
            1 => Vec3::new(
                rng.range(-r, r),
                rng.range(-r, r),
                -camera.near + rng.range(-r, r),
            ),
            2 => Vec3::new(
                rng.range(-3.0, 3.0),
                rng.range(-3.0, 3.0),
                rng.range(0.0, r),
            ),
            3 => {
                let depth = rng.range(1.0, 60.0);
                let edge = if rng.unit() < 0.5 { -1.0 } else { 1.0 } * rng.range(0.95, 1.15);
                let other = rng.range(-1.1, 1.1);
                let (sx, sy) = if k % 12 < 6 {
                    (edge, other)
                } else {
                    (other, edge)
                };
                Vec3::new(sx / setup.p00 * depth, sy / setup.p11 * depth, -depth)
            }
            _ => {
                let depth = rng.range(0.5, 80.0);
                Vec3::new(
                    rng.range(-1.0, 1.0) / setup.p00 * depth,
                    rng.range(-1.0, 1.0) / setup.p11 * depth,
                    -depth,
                )
            }
        };
        let position = world(v);
        lights.push(Light {
            position,
            color: Vec3::new(rng.unit(), rng.unit(), rng.unit()),
            intensity: rng.range(0.5, 3.0),
            range: r,
            spot: random_spot(rng, position, camera.eye),
        });
    }
    lights
}

/// The grid a strategy's CPU twin builds from the given cell bounds (and, for a grid built
/// with `--depth-mask on` or `--cell-box on`, its cells' culling records).
pub fn twin(
    assign: Assign,
    setup: &ViewSetup,
    grid: &LightGrid,
    lights: &[Light],
    (bounds, masks): (&[[f32; 2]], Option<&[CellCull]>),
    near_far: bool,
) -> LightGrid {
    let dims = &grid.dims;
    match assign {
        Assign::Cpu | Assign::Scatter if near_far => {
            assign_cpu(setup, dims, lights, DepthRange::NearFar)
        }
        Assign::Cpu | Assign::Scatter => {
            let range = match masks {
                Some(m) => DepthRange::Culled(bounds, m),
                None => DepthRange::Cells(bounds),
            };
            assign_cpu(setup, dims, lights, range)
        }
        Assign::Gather | Assign::Bvh | Assign::BvhGpu => {
            assign_gather_cpu_masked(setup, dims, lights, bounds, masks)
        }
        Assign::ZBin => zbins_cpu(setup, dims, lights, bounds).into_grid(*dims),
        Assign::Auto => unreachable!("resolved by the renderer"),
    }
}

pub fn with_ranges_scaled(lights: &[Light], f: f32) -> Vec<Light> {
    // Spot cones widen (f > 1) or narrow (f < 1) with the range, by an angle that covers
    // the GPU's and the CPU's round-off in the cone test.
    let d_cos = 2e-3 * (f - 1.0).signum();
    lights
        .iter()
        .map(|l| Light {
            range: l.range * f,
            spot: l.spot.map(|s| {
                let cos_outer = (s.cos_outer - d_cos).clamp(-1.0, 1.0 - 2e-4);
                Spot {
                    cos_outer,
                    cos_inner: s.cos_inner.max(cos_outer + 1e-4),
                    ..s
                }
            }),
            ..*l
        })
        .collect()
}

/// The GPU cell bounds against `cell_bounds_cpu` of the same depth buffer: equal within f32
/// round-off, occupied in the same cells except at most `max_occupancy_differences` (a sample
/// within round-off of a slice boundary), some cell occupied and, for clusters, some empty.
pub fn check_cell_bounds(
    what: &str,
    setup: &ViewSetup,
    dims: &GridDims,
    bounds: &[[f32; 2]],
    depth: &[f32],
    max_occupancy_differences: usize,
) {
    check_opened_cell_bounds(
        what,
        setup,
        dims,
        bounds,
        depth,
        max_occupancy_differences,
        lightgrid::frame::DepthBounds::Both,
    )
}

/// [`check_cell_bounds`] with `--depth-bounds` applied to the twin (`open_bounds`).
pub fn check_opened_cell_bounds(
    what: &str,
    setup: &ViewSetup,
    dims: &GridDims,
    bounds: &[[f32; 2]],
    depth: &[f32],
    max_occupancy_differences: usize,
    depth_bounds: lightgrid::frame::DepthBounds,
) {
    let mut cpu = cell_bounds_cpu(setup, dims, depth);
    lightgrid::testing::open_bounds(setup, dims, depth_bounds, &mut cpu);
    assert_eq!(bounds.len(), cpu.len(), "{what}: cell count");
    let mut emptiness = 0;
    let near = |a: f32, b: f32, rel: f32| (a - b).abs() <= rel * b.abs();
    for (c, (g, b)) in bounds.iter().zip(&cpu).enumerate() {
        match (g[0] <= g[1], b[0] <= b[1]) {
            (true, true) => {
                if near(g[0], b[0], 1e-5) && near(g[1], b[1], 1e-5) {
                    continue;
                }
                // A sample within round-off of a slice boundary counted on the other side:
                // the bound that differs lies on the boundary.
                let [lo, hi] = dims.slice_range(dims.slice_of_cell(c));
                let on_boundary = (near(g[0], b[0], 1e-5) || near(g[0].min(b[0]), lo, 3e-4))
                    && (near(g[1], b[1], 1e-5) || near(g[1].max(b[1]), hi, 3e-4));
                assert!(
                    dims.slices > 1 && on_boundary,
                    "{what}: cell {c} bounds {g:?} vs twin {b:?} (slice {lo}..{hi})"
                );
                emptiness += 1;
            }
            (false, false) => {}
            _ => emptiness += 1, // a sample within round-off of a slice boundary
        }
    }
    assert!(
        emptiness <= max_occupancy_differences,
        "{what}: {emptiness} cells differ in occupancy"
    );
    assert!(
        bounds.iter().any(|b| b[0] <= b[1]),
        "{what}: no cell holds samples"
    );
    if dims.slices > 1 {
        assert!(
            bounds.iter().any(|b| b[0] > b[1]),
            "{what}: every cluster occupied"
        );
    }
}

/// A GPU strategy's grid against its CPU twin fed with the same cell bounds: well formed
/// (counts add up, no light twice in a cell); equal to the twin for `cpu`; for GPU strategies
/// every cell's set lies between the twin's with all light ranges 0.1% smaller and 0.1% larger
/// (f32 round-off of the view transform and frustum planes differs between the GPU and the
/// CPU), and differs from the exact twin in at most `max_disagreements` (cell, light) pairs.
/// Returns the number of disagreements with the exact twin.
#[allow(clippy::too_many_arguments)]
pub fn check_grid_against_twin(
    what: &str,
    assign: Assign,
    setup: &ViewSetup,
    grid: &LightGrid,
    lights: &[Light],
    bounds: (&[[f32; 2]], Option<&[CellCull]>),
    near_far: bool,
    max_disagreements: usize,
) -> usize {
    let cell_bounds = bounds.0;
    let total: u64 = grid.cells.iter().map(|c| u64::from(c[1])).sum();
    assert_eq!(total, grid.indices.len() as u64, "{what}");
    let sets = sorted_cells(what, grid);
    let exact = twin(assign, setup, grid, lights, bounds, near_far);
    if assign == Assign::Cpu {
        assert_eq!(grid, &exact, "{what}");
        return 0;
    }
    let lo = twin(
        assign,
        setup,
        grid,
        &with_ranges_scaled(lights, 0.999),
        bounds,
        near_far,
    );
    let hi = twin(
        assign,
        setup,
        grid,
        &with_ranges_scaled(lights, 1.001),
        bounds,
        near_far,
    );
    let mut differing = 0;
    for (c, set) in sets.iter().enumerate() {
        // A spot's cone test is not monotonic in its angle for cells behind the apex (it
        // is conservative, not a distance), so the narrower and wider twins are taken
        // together with the exact one: the lights both the exact and the shrunk twin list
        // must be listed, and only lights the exact or the grown twin list may be.
        let exact_cell = exact.cell(c);
        if let Some(l) = lo
            .cell(c)
            .iter()
            .find(|l| exact_cell.contains(l) && set.binary_search(l).is_err())
        {
            panic!(
                "{what}: cell {c} (layer {}, slice {}, bounds {:?}) misses light {l}: {:?}",
                grid.dims.layer_of_cell(c),
                grid.dims.slice_of_cell(c),
                cell_bounds[c],
                lights[*l as usize]
            );
        }
        let reach = hi.cell(c);
        if let Some(l) = set
            .iter()
            .find(|l| !reach.contains(l) && !exact_cell.contains(l))
        {
            panic!(
                "{what}: cell {c} (layer {}, slice {}, bounds {:?}) lists light {l} out of reach: {:?}",
                grid.dims.layer_of_cell(c),
                grid.dims.slice_of_cell(c),
                cell_bounds[c],
                lights[*l as usize]
            );
        }
        differing += set.len().abs_diff(exact.cell(c).len());
    }
    assert!(
        differing <= max_disagreements,
        "{what}: {differing} round-off disagreements with the twin"
    );
    differing
}

/// Every cell's list, sorted, asserting that no cell lists a light twice.
pub fn sorted_cells(what: &str, grid: &LightGrid) -> Vec<Vec<u32>> {
    (0..grid.cells.len())
        .map(|c| {
            let mut list = grid.cell(c).to_vec();
            list.sort_unstable();
            let n = list.len();
            list.dedup();
            assert_eq!(n, list.len(), "{what}: cell {c} lists a light twice");
            list
        })
        .collect()
}

/// What [`check_grid_contains_oracle`] found.
#[derive(Clone, Copy, Debug, Default)]
pub struct OracleCheck {
    /// (cell, light) pairs the oracle found, all listed by the grid.
    pub hits: u64,
    /// Of those, pairs found in the neighbouring slice instead: every sample of the cell that
    /// the light reaches lies within f32 round-off of the slice boundary, where the GPU may
    /// have put it into the other slice.
    pub at_slice_boundary: u64,
}

/// The brute-force oracle of one frame: for every cell, the lights reaching one of its samples
/// on the frame's own depth buffer. Lights are 0.1% smaller for the oracle, so a sample within
/// f32 round-off of a sphere's surface decides nothing.
pub struct FrameOracle {
    pub dims: GridDims,
    pub cells: Vec<Vec<u32>>,
    view_distance: Vec<f32>,
    shrunk: Vec<Light>,
}

impl FrameOracle {
    pub fn new(setup: &ViewSetup, dims: &GridDims, lights: &[Light], depth: &[f32]) -> Self {
        let view_distance = view_distances(setup, depth);
        let shrunk = with_ranges_scaled(lights, 0.999);
        let cells = oracle_tile_lights(setup, dims, &shrunk, &view_distance);
        FrameOracle {
            dims: *dims,
            cells,
            view_distance,
            shrunk,
        }
    }

    /// No missing light: every light the oracle finds for a cell is listed for that cell;
    /// only a cluster sample within round-off of a slice boundary may count for the
    /// neighbouring slice, which must then list the light.
    pub fn check(&self, what: &str, setup: &ViewSetup, grid: &LightGrid) -> OracleCheck {
        // The same cells, whether lists or z-bins stand for them.
        let cells = |d: GridDims| GridDims {
            zbin_lights: None,
            ..d
        };
        let dims = cells(self.dims);
        assert_eq!(
            cells(grid.dims),
            dims,
            "{what}: the oracle is for other cells"
        );
        let sets = sorted_cells(what, grid);
        let mut check = OracleCheck::default();
        for (c, must) in self.cells.iter().enumerate() {
            for &l in must {
                check.hits += 1;
                if sets[c].binary_search(&l).is_ok() {
                    continue;
                }
                let light = &self.shrunk[l as usize];
                assert!(
                    dims.slices > 1
                        && listed_across_the_slice_boundary(
                            setup,
                            &dims,
                            &sets,
                            light,
                            l,
                            c,
                            &self.view_distance
                        ),
                    "{what}: cell {c} (tile {} slice {}) misses light {l} {light:?} that reaches \
                     its samples",
                    c % dims.tile_count(),
                    c / dims.tile_count(),
                );
                check.at_slice_boundary += 1;
            }
        }
        check
    }
}

/// What [`check_cell_culls`] saw.
#[derive(Default, Debug)]
pub struct CullCells {
    /// Opaque cells whose 2.5D mask leaves bins out.
    pub partial_masks: usize,
    /// Opaque cells with a tight box.
    pub boxes: usize,
}

/// The GPU's culling records against their CPU twins over the frame's depth samples.
///
/// 2.5D depth masks (`--depth-mask on`), with the GPU's own bins (`lo`, `inv`): every bin the
/// twin sets with half the slack is set, and (without MSAA forward fragments or shared
/// transparent lists, which set whole ranges the twin does not see: `exact_samples` false)
/// none is set that the twin does not set with twice the slack.
///
/// Tight boxes (`--cell-box on`), with the GPU's bounds: every occupied opaque cell has one
/// holding the twin's box with half the slack (the samples' footprints) and, with
/// `exact_samples`, held by the twin's box with twice the slack, both within f32 round-off of
/// the pixel edges.
///
/// Off, every cell has no mask / no box; the transparent layer of separate lists never has
/// either.
#[allow(clippy::too_many_arguments)]
pub fn check_cell_culls(
    what: &str,
    setup: &ViewSetup,
    dims: &GridDims,
    culls: &[CellCull],
    bounds: &[[f32; 2]],
    planes: &[&[f32]],
    (mask_on, box_on): (bool, bool),
    exact_samples: bool,
) -> CullCells {
    assert_eq!(culls.len(), dims.cell_count(), "{what}: record count");
    let mut seen = CullCells::default();
    let layer = dims.layer_cells();
    if !mask_on {
        assert!(
            culls.iter().all(|m| m.mask == NO_MASK),
            "{what}: a mask without --depth-mask on"
        );
    } else {
        let slack = lightgrid::consts::ASSIGN_DEPTH_SLACK;
        let scales: Vec<CellMask> = culls.iter().map(|c| c.mask).collect();
        let narrow = cell_masks_cpu(setup, dims, planes, &scales, None, slack * 0.5);
        let wide = cell_masks_cpu(setup, dims, planes, &scales, None, slack * 2.0);
        for c in 0..dims.cell_count() {
            let (g, n, w) = (scales[c][0], narrow[c][0], wide[c][0]);
            if c >= layer {
                assert_eq!(
                    scales[c], NO_MASK,
                    "{what}: transparent cell {c} has a mask"
                );
                continue;
            }
            assert_eq!(
                g & n,
                n,
                "{what}: cell {c} leaves out sample bins: gpu {g:032b} cpu {n:032b}"
            );
            if exact_samples && dims.lists != GridLists::Shared {
                assert_eq!(
                    g & !w,
                    0,
                    "{what}: cell {c} sets bins without samples: gpu {g:032b} cpu {w:032b}"
                );
            }
            if g != 0 && g != u32::MAX {
                seen.partial_masks += 1;
            }
        }
    }
    if !box_on {
        assert!(
            culls.iter().all(|m| m.view_box().is_none()),
            "{what}: a box without --cell-box on"
        );
        return seen;
    }
    let slack = lightgrid::consts::ASSIGN_DEPTH_SLACK;
    let narrow = cell_boxes_cpu(setup, dims, planes, bounds, None, slack * 0.5);
    let wide = cell_boxes_cpu(setup, dims, planes, bounds, None, slack * 2.0);
    // Within f32 round-off of the footprints' corners (WGSL's division is not exact).
    let tol = |v: Vec3, extent: Vec3| v.abs() * 1e-5 + extent * 1e-4 + Vec3::splat(1e-6);
    for c in 0..dims.cell_count() {
        let g = culls[c].view_box();
        if c >= layer && dims.lists == GridLists::Separate {
            assert!(g.is_none(), "{what}: transparent cell {c} has a box");
            continue;
        }
        let [w0, w1] = bounds[c];
        if w0 > w1 {
            continue;
        }
        if c < layer {
            seen.boxes += 1;
        }
        let Some((lo, hi)) = g else {
            panic!(
                "{what}: occupied cell {c} (bounds {:?}) has no box",
                bounds[c]
            );
        };
        assert!(
            lo.cmple(hi).all(),
            "{what}: cell {c}'s box is inverted: {lo} {hi}"
        );
        if let Some((nlo, nhi)) = narrow[c] {
            let t = tol(nlo.abs().max(nhi.abs()), nhi - nlo);
            assert!(
                lo.cmple(nlo + t).all() && hi.cmpge(nhi - t).all(),
                "{what}: cell {c}'s box {lo} {hi} leaves out samples' footprints {nlo} {nhi}"
            );
        }
        if exact_samples && dims.lists != GridLists::Shared {
            let (wlo, whi) = wide[c].expect("an occupied cell has samples");
            let t = tol(wlo.abs().max(whi.abs()), whi - wlo);
            assert!(
                lo.cmpge(wlo - t).all() && hi.cmple(whi + t).all(),
                "{what}: cell {c}'s box {lo} {hi} is wider than its samples' {wlo} {whi}"
            );
        }
    }
    seen
}

/// [`FrameOracle::check`] of a frame's grid on its depth buffer.
pub fn check_grid_contains_oracle(
    what: &str,
    setup: &ViewSetup,
    grid: &LightGrid,
    lights: &[Light],
    depth: &[f32],
) -> OracleCheck {
    FrameOracle::new(setup, &grid.dims, lights, depth).check(what, setup, grid)
}

/// Every transparent fragment of the frame (its transparent objects rasterized on the CPU in
/// front of the opaque depth) finds every light that reaches it in its cell's list
/// (tiled-forward-shading §4.5). Returns the number of fragments checked.
pub fn check_grid_covers_transparent_fragments(
    what: &str,
    setup: &ViewSetup,
    grid: &LightGrid,
    lights: &[Light],
    depth: &[f32],
    triangles: &[[Vec3; 3]],
) -> usize {
    let fragments = lightgrid::scene::rasterize(setup, triangles, &setup.view_distances(depth));
    let must = lightgrid::testing::oracle_fragment_lights(setup, &grid.dims, lights, &fragments);
    for (c, list) in must.iter().enumerate() {
        for l in list {
            assert!(
                grid.cell(c).contains(l),
                "{what}: transparent cell {c} (layer {}, slice {}) misses light {l} ({:?})",
                grid.dims.layer_of_cell(c),
                grid.dims.slice_of_cell(c),
                lights[*l as usize]
            );
        }
    }
    fragments.len()
}

/// Whether every sample of cell `c` that `light` reaches is within round-off of its slice's
/// boundary and the neighbouring slice's cell lists the light.
fn listed_across_the_slice_boundary(
    setup: &ViewSetup,
    dims: &GridDims,
    sets: &[Vec<u32>],
    light: &Light,
    l: u32,
    c: usize,
    w: &[f32],
) -> bool {
    let v = setup.to_view(light);
    let (t, k) = (c % dims.tile_count(), (c / dims.tile_count()) as u32);
    let (x0, y0, x1, y1) = dims.tile_rect(t);
    for y in y0..y1 {
        for x in x0..x1 {
            let d = w[(y * dims.width + x) as usize];
            if !d.is_finite() || dims.slice_of(d) != k {
                continue;
            }
            if setup.sample_position(x, y, d).distance_squared(v.center) >= v.radius * v.radius {
                continue;
            }
            let other = [d * (1.0 - 1e-5), d * (1.0 + 1e-5)]
                .map(|e| dims.slice_of(e))
                .into_iter()
                .find(|&s| s != k);
            match other {
                Some(s) => {
                    let neighbour = s as usize * dims.tile_count() + t;
                    if sets[neighbour].binary_search(&l).is_err() {
                        return false;
                    }
                }
                None => return false,
            }
        }
    }
    true
}

/// Oracle hits sorted by what made them, so a randomized test can show it exercises the cases
/// light assignment gets wrong (each counts (cell, light) pairs the oracle finds).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Coverage {
    pub cases: u64,
    /// Cases whose frame is not a multiple of the tile size in x or y.
    pub odd_cases: u64,
    pub hits: u64,
    /// Hits of lights that contain the camera.
    pub containing: u64,
    /// Hits of lights centred behind the camera (not containing it) that reach forward.
    pub behind: u64,
    /// Hits of lights centred in front of the camera that cross the near plane (not
    /// containing the camera).
    pub crossing_near: u64,
    /// Hits of lights centred beyond the near plane but outside the frame (not crossing the
    /// near plane).
    pub off_screen: u64,
    /// Hits in tiles cut short by the frame's right or bottom edge.
    pub partial_tiles: u64,
}

impl Coverage {
    pub fn add(
        &mut self,
        setup: &ViewSetup,
        dims: &GridDims,
        lights: &[Light],
        oracle: &[Vec<u32>],
    ) {
        self.cases += 1;
        if dims.width % dims.tile_size != 0 || dims.height % dims.tile_size != 0 {
            self.odd_cases += 1;
        }
        // 0 containing, 1 behind, 2 crossing the near plane, 3 off screen, 4 none of these.
        let kinds: Vec<usize> = lights
            .iter()
            .map(|l| {
                let v = setup.to_view(l);
                let w = -v.center.z;
                if v.center.length() < v.radius {
                    0
                } else if w < 0.0 {
                    1
                } else if (w - setup.near).abs() < v.radius {
                    2
                } else if w > setup.near
                    && ((setup.p00 * v.center.x / w).abs() > 1.0
                        || (setup.p11 * v.center.y / w).abs() > 1.0)
                {
                    3
                } else {
                    4
                }
            })
            .collect();
        for (c, must) in oracle.iter().enumerate() {
            let (x0, y0, x1, y1) = dims.tile_rect(c % dims.tile_count());
            let partial = x1 - x0 < dims.tile_size || y1 - y0 < dims.tile_size;
            for &l in must {
                self.hits += 1;
                match kinds[l as usize] {
                    0 => self.containing += 1,
                    1 => self.behind += 1,
                    2 => self.crossing_near += 1,
                    3 => self.off_screen += 1,
                    _ => {}
                }
                self.partial_tiles += u64::from(partial);
            }
        }
    }

    /// Every count halved: the bound a randomized test keeps against what it measured, so it
    /// fails when most hits of a kind vanish, not when a seed or a tolerance moves a few.
    pub fn halved(&self) -> Coverage {
        Coverage {
            cases: self.cases / 2,
            odd_cases: self.odd_cases / 2,
            hits: self.hits / 2,
            containing: self.containing / 2,
            behind: self.behind / 2,
            crossing_near: self.crossing_near / 2,
            off_screen: self.off_screen / 2,
            partial_tiles: self.partial_tiles / 2,
        }
    }

    /// Assert every count reaches `min`'s.
    pub fn at_least(&self, min: &Coverage, what: &str) {
        let pairs = [
            ("cases", self.cases, min.cases),
            (
                "cases not a multiple of the tile",
                self.odd_cases,
                min.odd_cases,
            ),
            ("oracle hits", self.hits, min.hits),
            ("hits of lights behind the camera", self.behind, min.behind),
            (
                "hits of lights containing the camera",
                self.containing,
                min.containing,
            ),
            (
                "hits of lights crossing the near plane",
                self.crossing_near,
                min.crossing_near,
            ),
            (
                "hits of lights centred off screen",
                self.off_screen,
                min.off_screen,
            ),
            (
                "hits in partial tiles",
                self.partial_tiles,
                min.partial_tiles,
            ),
        ];
        for (name, got, want) in pairs {
            assert!(
                got >= want,
                "{what}: {got} {name}, fewer than {want}: the cases no longer exercise it ({self:?})"
            );
        }
    }
}

/// `s` moved by `d`: static objects, paths, world and circling lights, and the camera.
pub fn moved(s: &lightgrid::scene::Scene, d: glam::Vec3) -> lightgrid::scene::Scene {
    use lightgrid::scene::LightAnchor;
    let mut s = s.clone();
    let t = glam::Mat4::from_translation(d);
    for o in s.objects.iter_mut().filter(|o| o.is_static()) {
        o.local = t * o.local;
    }
    for q in s.paths.iter_mut().flat_map(|p| p.points.iter_mut()) {
        *q += d;
    }
    for l in &mut s.lights {
        if !matches!(l.anchor, LightAnchor::Object(_)) {
            l.light.position += d;
        }
    }
    for k in &mut s.camera_path.keys {
        k.1 += d;
        k.2 += d;
    }
    s.name = format!("{}-moved{:e}", s.name, d.length());
    s
}
