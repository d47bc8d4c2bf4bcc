//! The scene catalog: procedural scenes, deterministic from a seed.
//!
//! The robots street follows tiled-shading §8 (the BART Robots scene with two light
//! distributions); `scattered` follows the Forward+ demo (forward-plus §5, 3072 lights at
//! 1280×720); `random-top` / `random-fps` follow tiled-forward-shading Fig. 4.6 (1024 random
//! lights, top-down and first-person); `stress` takes any light count for scaling runs.

use super::{
    CameraPath, Light, LightAnchor, Material, MaterialShader, Mesh, Motion, Object, Path, Rng,
    Scene, SceneLight, Spot,
};
use crate::error::{Error, Result};
use glam::{Mat4, Vec3};

/// Width of the robots scene's main street (tiled-shading §8).
pub const MAIN_STREET_WIDTH: f32 = 29.1;
/// Robots walking the street (the BART Robots scene has 11).
pub(crate) const ROBOT_COUNT: usize = 11;
/// `robots-many`: static lights spread evenly along the robots' paths.
pub(crate) const ROBOTS_MANY_LIGHTS: usize = 924;
pub(crate) const ROBOTS_MANY_RANGE: f32 = 12.5;
/// `robots-few`: one light per robot.
pub(crate) const ROBOTS_FEW_RANGE: f32 = 40.0;
/// Frames of the robots camera path (the paper shows frames 0 to 259).
pub(crate) const ROBOTS_FRAMES: u32 = 260;
pub(crate) const SCATTERED_LIGHTS: usize = 3072;
pub(crate) const RANDOM_LIGHTS: usize = 1024;
/// `stress` without `--lights`.
pub(crate) const STRESS_DEFAULT_LIGHTS: u32 = 10_000;
/// Largest `--lights` accepted by `stress`.
pub const STRESS_MAX_LIGHTS: u32 = 1_000_000;

/// What the user can vary when building a catalog scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneParams {
    /// Seed of the scene's random placement of lights, objects and colours (`--seed`).
    pub seed: u64,
    /// Light count; only scenes with `variable_lights` accept it.
    pub lights: Option<u32>,
    /// Fraction of the lights (0 to 1) turned into spot lights with seeded random directions
    /// and cones (`--spot-fraction`).
    pub spot_fraction: f32,
    /// Two headlights (spots) on every robot (`--headlights`, robots scenes only).
    pub headlights: bool,
    /// The scene's transparent objects (`--transparency on|off`), where it has any.
    pub transparency: bool,
    /// The materials' own shaders (`--material-shaders on|off`); off makes every material
    /// standard Blinn-Phong (tiled-forward-shading §4.7 measures the difference).
    pub material_shaders: bool,
}

impl Default for SceneParams {
    fn default() -> Self {
        SceneParams {
            seed: 1,
            lights: None,
            spot_fraction: 0.0,
            headlights: false,
            transparency: true,
            material_shaders: true,
        }
    }
}

/// Outer half-angles of the spots `--spot-fraction` makes, in degrees (street lamps to wide
/// floods); the inner cone is 50% to 90% of the outer.
pub(crate) const SPOT_OUTER_DEGREES: (f32, f32) = (15.0, 75.0);

/// A saturated random colour (random hue), as lights in the papers' scenes.
pub(crate) fn random_light_color(rng: &mut Rng) -> Vec3 {
    let h = rng.unit() * 6.0;
    let s = rng.range(0.45, 0.85);
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    let rgb = match h as u32 {
        0 => Vec3::new(1.0, x, 0.0),
        1 => Vec3::new(x, 1.0, 0.0),
        2 => Vec3::new(0.0, 1.0, x),
        3 => Vec3::new(0.0, x, 1.0),
        4 => Vec3::new(x, 0.0, 1.0),
        _ => Vec3::new(1.0, 0.0, x),
    };
    Vec3::ONE.lerp(rgb, s)
}

/// Turn `fraction` of the scene's lights into spots: each light is chosen with that
/// probability from its own seeded stream, so the choice and the cones do not depend on the
/// light count. Directions are uniform on the sphere.
pub(crate) fn make_spots(scene: &mut Scene, seed: u64, fraction: f32) {
    if fraction <= 0.0 {
        return;
    }
    let mut rng = Rng::new(seed ^ 0x5907_11a4_c0de_0001);
    for l in &mut scene.lights {
        let (pick, z, phi, outer, inner) = (
            rng.unit(),
            rng.range(-1.0, 1.0),
            rng.range(0.0, std::f32::consts::TAU),
            rng.range(SPOT_OUTER_DEGREES.0, SPOT_OUTER_DEGREES.1),
            rng.range(0.5, 0.9),
        );
        // Lights that are spots already (headlights) keep their cones.
        if pick >= fraction || l.light.spot.is_some() {
            continue;
        }
        let xy = (1.0 - z * z).max(0.0).sqrt();
        let direction = Vec3::new(xy * phi.cos(), z, xy * phi.sin());
        let outer = outer.to_radians();
        l.light.spot = Some(Spot::new(direction, outer * inner, outer));
    }
}

/// One catalog row.
pub struct SceneInfo {
    /// The name the scene is chosen by (`robots-many`, `stress`, ...).
    pub name: &'static str,
    /// One line on what the scene holds, as `lightgrid list` prints it.
    pub description: &'static str,
    /// Accepts `--lights N`.
    pub variable_lights: bool,
    /// Has walking robots, which `--headlights` gives two spot lights each.
    pub robots: bool,
    build: fn(&SceneParams) -> Scene,
    /// Adds the scene's transparent objects (`--transparency on`), from their own seeded
    /// stream so the rest of the scene does not change.
    glass: Option<fn(&mut Scene, u64)>,
}

impl SceneInfo {
    /// Has transparent objects (`--transparency` applies).
    pub fn transparency(&self) -> bool {
        self.glass.is_some()
    }
}

/// Every scene, in the order `lightgrid list` prints them.
pub const SCENES: &[SceneInfo] = &[
    SceneInfo {
        name: "robots-many",
        description:
            "city street, 11 car-painted walking robots, 924 static lights (range 12.5) along their paths; glass panes and bubbles",
        variable_lights: false,
        robots: true,
        build: robots_many,
        glass: Some(street_glass),
    },
    SceneInfo {
        name: "robots-few",
        description: "the same street (and glass) with one light (range 40) carried by each of the 11 robots",
        variable_lights: false,
        robots: true,
        build: robots_few,
        glass: Some(street_glass),
    },
    SceneInfo {
        name: "scattered",
        description:
            "3072 lights scattered through a volume of rim-lit pillars and blocks (Forward+ demo), 1280x720",
        variable_lights: false,
        robots: false,
        build: scattered,
        glass: None,
    },
    SceneInfo {
        name: "random-top",
        description: "1024 randomly placed lights over a block field with translucent blocks, seen top-down",
        variable_lights: false,
        robots: false,
        build: random_top,
        glass: Some(field_glass),
    },
    SceneInfo {
        name: "random-fps",
        description: "the same 1024 lights and field, seen first-person",
        variable_lights: false,
        robots: false,
        build: random_fps,
        glass: Some(field_glass),
    },
    SceneInfo {
        name: "stress",
        description:
            "any light count (--lights N, up to 1,000,000; default 10,000) over a large block field",
        variable_lights: true,
        robots: false,
        build: stress,
        glass: None,
    },
];

/// Comma-separated scene names, for error messages and help.
fn scene_names() -> String {
    scenes_where(|_| true)
}

/// Look up a scene by name.
pub fn find(name: &str) -> Result<&'static SceneInfo> {
    SCENES
        .iter()
        .find(|s| s.name == name)
        .ok_or_else(|| Error::Unknown {
            what: "scene",
            name: name.to_string(),
            valid: scene_names(),
        })
}

/// Comma-separated names of the scenes an option applies to.
fn scenes_where(applies: fn(&SceneInfo) -> bool) -> String {
    SCENES
        .iter()
        .filter(|s| applies(s))
        .map(|s| s.name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// Check a scene's parameters without building it: `--lights` only for scenes that take a
/// light count, and within 1 to [`STRESS_MAX_LIGHTS`].
pub fn check_params(name: &str, params: &SceneParams) -> Result<&'static SceneInfo> {
    let info = find(name)?;
    match params.lights {
        Some(_) if !info.variable_lights => Err(Error::invalid(
            "--lights",
            format!(
                "scene {name} has a fixed light count; --lights applies to: {}",
                scenes_where(|s| s.variable_lights)
            ),
        )),
        Some(n) if n == 0 || n > STRESS_MAX_LIGHTS => Err(Error::invalid(
            "--lights",
            format!("{n} is out of range 1 to {STRESS_MAX_LIGHTS}"),
        )),
        _ if params.headlights && !info.robots => Err(Error::invalid(
            "--headlights",
            format!(
                "scene {name} has no robots; --headlights applies to: {}",
                scenes_where(|s| s.robots)
            ),
        )),
        _ if !params.transparency && !info.transparency() => Err(Error::invalid(
            "--transparency",
            format!(
                "scene {name} has no transparent objects; --transparency applies to: {}",
                scenes_where(SceneInfo::transparency)
            ),
        )),
        _ => check_spot_fraction(params.spot_fraction).map(|()| info),
    }
}

/// `--spot-fraction` is a fraction, for catalog scenes and files alike.
pub(crate) fn check_spot_fraction(fraction: f32) -> Result<()> {
    if (0.0..=1.0).contains(&fraction) {
        Ok(())
    } else {
        Err(Error::invalid(
            "--spot-fraction",
            format!("{fraction} is out of range 0 to 1"),
        ))
    }
}

/// Build a catalog scene by name.
pub fn build(name: &str, params: &SceneParams) -> Result<Scene> {
    let info = check_params(name, params)?;
    let mut scene = (info.build)(params);
    if let (true, Some(glass)) = (params.transparency, info.glass) {
        glass(&mut scene, params.seed);
    }
    make_spots(&mut scene, params.seed, params.spot_fraction);
    if !params.material_shaders {
        for m in &mut scene.materials {
            m.shader = MaterialShader::Standard;
        }
    }
    scene.validate()?;
    Ok(scene)
}

/// Scene under construction.
struct Builder {
    scene: Scene,
    rng: Rng,
}

impl Builder {
    fn new(name: &str, seed: u64, camera_path: CameraPath, default_size: (u32, u32)) -> Self {
        Builder {
            scene: Scene {
                name: name.to_string(),
                meshes: Vec::new(),
                materials: Vec::new(),
                objects: Vec::new(),
                paths: Vec::new(),
                lights: Vec::new(),
                textures: Vec::new(),
                camera_path,
                default_size,
                lighting: Default::default(),
                derived_ranges: Vec::new(),
                tracks: Vec::new(),
            },
            rng: Rng::new(seed),
        }
    }

    fn material(&mut self, m: Material) -> usize {
        self.scene.materials.push(m);
        self.scene.materials.len() - 1
    }

    fn object(&mut self, mesh: Mesh, material: usize, motion: Motion) -> usize {
        self.scene.meshes.push(mesh);
        self.scene.objects.push(Object {
            mesh: self.scene.meshes.len() - 1,
            material,
            local: Mat4::IDENTITY,
            motion,
        });
        self.scene.objects.len() - 1
    }

    fn light(&mut self, light: Light, anchor: LightAnchor) {
        self.scene.lights.push(SceneLight { light, anchor });
    }

    fn light_color(&mut self) -> Vec3 {
        random_light_color(&mut self.rng)
    }

    /// Boxes standing on the ground at random heights, in a grid of `cells` over the square
    /// [-half, half]², each leaving a `gap` to the cell edge. Returns the merged mesh.
    fn block_field(&mut self, half: f32, cells: u32, gap: f32, height: (f32, f32)) -> Mesh {
        let mut mesh = Mesh::default();
        let cell = 2.0 * half / cells as f32;
        for i in 0..cells {
            for j in 0..cells {
                if self.rng.unit() < 0.25 {
                    continue;
                }
                let x0 = -half + i as f32 * cell + gap;
                let z0 = -half + j as f32 * cell + gap;
                let w = (cell - 2.0 * gap) * self.rng.range(0.4, 1.0);
                let d = (cell - 2.0 * gap) * self.rng.range(0.4, 1.0);
                let h = self.rng.range(height.0, height.1);
                mesh.append(
                    &Mesh::block(Vec3::new(x0, 0.0, z0), Vec3::new(x0 + w, h, z0 + d)),
                    Mat4::IDENTITY,
                );
            }
        }
        mesh
    }
}

// ---------------------------------------------------------------- robots street

/// Street layout: the main street runs along z; two cross streets run along x.
const STREET_HALF_LENGTH: f32 = 160.0;
const CROSS_STREETS_Z: [f32; 2] = [-70.0, 70.0];
const CROSS_STREET_WIDTH: f32 = 20.0;
const SIDEWALK: f32 = 3.5;

/// The robots' walking loops: five lanes up and down the main street, five along the cross
/// streets and one around a block.
fn robot_paths() -> Vec<Path> {
    let lane = |a: Vec3, b: Vec3, side: Vec3| Path {
        points: vec![a - side, b - side, b + side, a + side],
    };
    let mut paths = Vec::new();
    for x in [-9.0, -4.5, 0.0, 4.5, 9.0] {
        paths.push(lane(
            Vec3::new(x, 0.0, -150.0),
            Vec3::new(x, 0.0, 150.0),
            Vec3::X * 1.5,
        ));
    }
    for (z, dz) in [
        (-70.0, -3.0),
        (-70.0, 3.0),
        (70.0, -4.0),
        (70.0, 0.0),
        (70.0, 4.0),
    ] {
        paths.push(lane(
            Vec3::new(-150.0, 0.0, z + dz),
            Vec3::new(150.0, 0.0, z + dz),
            Vec3::Z * 1.2,
        ));
    }
    paths.push(Path {
        points: vec![
            Vec3::new(-6.0, 0.0, -70.0),
            Vec3::new(-6.0, 0.0, 70.0),
            Vec3::new(-140.0, 0.0, 70.0),
            Vec3::new(-140.0, 0.0, -70.0),
        ],
    });
    debug_assert_eq!(paths.len(), ROBOT_COUNT);
    paths
}

/// Is the point (x, z) on a street or sidewalk (where no building may stand)?
fn in_street(x0: f32, x1: f32, z0: f32, z1: f32) -> bool {
    let main = MAIN_STREET_WIDTH * 0.5 + SIDEWALK;
    let overlaps_main = x1 > -main && x0 < main;
    let cross = CROSS_STREET_WIDTH * 0.5 + SIDEWALK;
    let overlaps_cross = CROSS_STREETS_Z
        .iter()
        .any(|&c| z1 > c - cross && z0 < c + cross);
    overlaps_main || overlaps_cross
}

/// The asphalt, and the sidewalks along both sides of the main street and the cross
/// streets.
fn street(b: &mut Builder, asphalt: usize, pavement: usize) {
    let extent = STREET_HALF_LENGTH + 40.0;
    b.object(
        Mesh::ground(-extent, -extent, extent, extent, 0.0),
        asphalt,
        Motion::Static,
    );

    // Sidewalks along both sides of the main street and the cross streets.
    let mut walks = Mesh::default();
    let m = MAIN_STREET_WIDTH * 0.5;
    for side in [-1.0f32, 1.0] {
        let (x0, x1) = if side < 0.0 {
            (-m - SIDEWALK, -m)
        } else {
            (m, m + SIDEWALK)
        };
        walks.append(
            &Mesh::block(
                Vec3::new(x0, 0.0, -STREET_HALF_LENGTH),
                Vec3::new(x1, 0.2, STREET_HALF_LENGTH),
            ),
            Mat4::IDENTITY,
        );
    }
    for c in CROSS_STREETS_Z {
        let h = CROSS_STREET_WIDTH * 0.5;
        for (z0, z1) in [(c - h - SIDEWALK, c - h), (c + h, c + h + SIDEWALK)] {
            walks.append(
                &Mesh::block(
                    Vec3::new(-STREET_HALF_LENGTH, 0.0, z0),
                    Vec3::new(STREET_HALF_LENGTH, 0.2, z1),
                ),
                Mat4::IDENTITY,
            );
        }
    }
    b.object(walks, pavement, Motion::Static);
}

/// Buildings: rows of boxes along every block's street fronts, two rows deep, each block of
/// one of the `facades` materials (drawn from the scene's stream).
fn buildings(b: &mut Builder, facades: Vec<usize>) {
    let mut buildings: Vec<Mesh> = vec![Mesh::default(); facades.len()];
    let inner = MAIN_STREET_WIDTH * 0.5 + SIDEWALK + 0.5;
    for side in [-1.0f32, 1.0] {
        for row in 0..2 {
            let mut z = -STREET_HALF_LENGTH;
            while z < STREET_HALF_LENGTH {
                let width = b.rng.range(9.0, 22.0);
                let depth = b.rng.range(14.0, 26.0);
                let height = b.rng.range(10.0, 55.0) * if row == 0 { 1.0 } else { 1.4 };
                let near = inner + row as f32 * 30.0;
                let (x0, x1) = if side > 0.0 {
                    (near, near + depth)
                } else {
                    (-near - depth, -near)
                };
                let (z0, z1) = (z, (z + width).min(STREET_HALF_LENGTH));
                // Fronts facing the main street stop at the cross streets.
                if !in_street(x0, x1, z0, z1) {
                    let f = b.rng.below(facades.len() as u32) as usize;
                    buildings[f].append(
                        &Mesh::block(Vec3::new(x0, 0.0, z0), Vec3::new(x1, height, z1)),
                        Mat4::IDENTITY,
                    );
                }
                z += width + b.rng.range(0.5, 3.0);
            }
        }
    }
    for (mesh, f) in buildings.into_iter().zip(facades) {
        b.object(mesh, f, Motion::Static);
    }
}

/// A robot (a 2x scale humanoid made of boxes, facing +z in object space) and its eyes.
fn robot_meshes() -> (Mesh, Mesh) {
    let mut body = Mesh::default();
    let parts = [
        (Vec3::new(-1.8, 0.0, -0.7), Vec3::new(-0.4, 4.4, 0.7)), // left leg
        (Vec3::new(0.4, 0.0, -0.7), Vec3::new(1.8, 4.4, 0.7)),   // right leg
        (Vec3::new(-2.2, 4.4, -1.2), Vec3::new(2.2, 9.2, 1.2)),  // torso
        (Vec3::new(-3.2, 5.0, -0.6), Vec3::new(-2.3, 9.0, 0.6)), // left arm
        (Vec3::new(2.3, 5.0, -0.6), Vec3::new(3.2, 9.0, 0.6)),   // right arm
        (Vec3::new(-1.2, 9.4, -1.0), Vec3::new(1.2, 11.4, 1.0)), // head
    ];
    for (lo, hi) in parts {
        body.append(&Mesh::block(lo, hi), Mat4::IDENTITY);
    }
    let mut eye_mesh = Mesh::default();
    for x in [-0.7, 0.3] {
        eye_mesh.append(
            &Mesh::cuboid(Vec3::new(x, 10.4, 1.02), Vec3::new(x + 0.4, 10.8, 1.15)),
            Mat4::IDENTITY,
        );
    }
    (body, eye_mesh)
}

/// The street, its buildings and the 11 robots. Returns the builder and the object index of
/// each robot's body (lights of `robots-few` ride on it).
fn robots_street(name: &str, seed: u64) -> (Builder, Vec<usize>) {
    let camera = CameraPath {
        keys: vec![
            (0, Vec3::new(0.0, 70.0, -185.0), Vec3::new(0.0, 0.0, -60.0)),
            (50, Vec3::new(6.0, 30.0, -140.0), Vec3::new(0.0, 4.0, -50.0)),
            (100, Vec3::new(-8.0, 7.0, -75.0), Vec3::new(6.0, 4.0, 10.0)),
            (150, Vec3::new(4.0, 6.0, -10.0), Vec3::new(-10.0, 5.0, 60.0)),
            (200, Vec3::new(-5.0, 9.0, 55.0), Vec3::new(-80.0, 4.0, 75.0)),
            (259, Vec3::new(30.0, 45.0, 130.0), Vec3::new(0.0, 0.0, 0.0)),
        ],
        ups: Vec::new(),
        fov_y: 60f32.to_radians(),
        near: 0.5,
        far: 800.0,
    };
    let mut b = Builder::new(name, seed, camera, (640, 360));
    let asphalt = b.material(Material::plain(Vec3::splat(0.30), 0.15, 16.0));
    let pavement = b.material(Material::plain(Vec3::new(0.55, 0.53, 0.50), 0.1, 8.0));
    let facades: Vec<usize> = [
        Vec3::new(0.70, 0.62, 0.52),
        Vec3::new(0.55, 0.58, 0.64),
        Vec3::new(0.72, 0.70, 0.68),
        Vec3::new(0.60, 0.45, 0.40),
    ]
    .into_iter()
    .map(|c| b.material(Material::plain(c, 0.25, 24.0)))
    .collect();
    // The robots wear two-colour car paint (tiled-forward-shading §4.7's per-material
    // shaders): steel blue turning plum at grazing angles.
    let metal = b.material(Material {
        shader: MaterialShader::CarPaint {
            flip: Vec3::new(0.55, 0.12, 0.40),
            power: 2.0,
        },
        ..Material::plain(Vec3::new(0.45, 0.50, 0.58), 0.9, 64.0)
    });
    let eyes = b.material(Material {
        emissive: Vec3::new(1.5, 0.2, 0.1),
        ..Material::plain(Vec3::new(0.2, 0.05, 0.05), 0.5, 32.0)
    });

    street(&mut b, asphalt, pavement);
    buildings(&mut b, facades);

    let (body, eye_mesh) = robot_meshes();
    b.scene.paths = robot_paths();
    let mut robots = Vec::new();
    for p in 0..ROBOT_COUNT {
        let len = b.scene.paths[p].length();
        let motion = Motion::Walk {
            path: p,
            speed: b.rng.range(0.6, 1.0),
            start: b.rng.range(0.0, len),
        };
        robots.push(b.object(body.clone(), metal, motion.clone()));
        b.object(eye_mesh.clone(), eyes, motion);
    }
    (b, robots)
}

/// Headlights: two spots on each robot's head, beside its eyes, looking ahead and a little
/// down (robots face +z in object space); they turn with the robot.
fn headlights(b: &mut Builder, robots: &[usize]) {
    for &body in robots {
        for x in [-0.6f32, 0.6] {
            let light = Light {
                position: Vec3::new(x, 10.6, 1.3),
                color: Vec3::new(1.0, 0.92, 0.75),
                intensity: 2.0,
                range: HEADLIGHT_RANGE,
                spot: Some(Spot::new(
                    Vec3::new(0.0, -0.3, 1.0),
                    12f32.to_radians(),
                    22f32.to_radians(),
                )),
            };
            b.light(light, LightAnchor::Object(body));
        }
    }
}

/// Add a static transparent object.
fn add_glass(scene: &mut Scene, mesh: Mesh, material: usize) {
    scene.meshes.push(mesh);
    scene.objects.push(Object {
        mesh: scene.meshes.len() - 1,
        material,
        local: Mat4::IDENTITY,
        motion: Motion::Static,
    });
}

fn add_material(scene: &mut Scene, m: Material) -> usize {
    scene.materials.push(m);
    scene.materials.len() - 1
}

/// The street's glass (tiled-shading §4's transparent objects among many lights): panes
/// standing on both sidewalks, some along the street and some across it, and bubbles
/// floating over the street, one of them around the camera's key at frame 150, so the
/// animation flies through a transparent object.
fn street_glass(scene: &mut Scene, seed: u64) {
    let mut rng = Rng::new(seed ^ 0x61a5_55e5_0000_0001);
    let pane = add_material(scene, Material::glass(Vec3::new(0.55, 0.78, 0.85), 0.35));
    let bubble = add_material(scene, Material::glass(Vec3::new(0.85, 0.7, 0.95), 0.3));
    let m = MAIN_STREET_WIDTH * 0.5;
    let clear_of_crossings = |z: f32| {
        CROSS_STREETS_Z
            .iter()
            .all(|c| (z - c).abs() > CROSS_STREET_WIDTH * 0.5 + 6.0)
    };
    for side in [-1.0f32, 1.0] {
        let x = side * (m + SIDEWALK * 0.5);
        let mut z = -STREET_HALF_LENGTH + 12.0;
        let mut across = side > 0.0;
        while z < STREET_HALF_LENGTH - 12.0 {
            if clear_of_crossings(z) {
                let (lo, hi) = if across {
                    (
                        Vec3::new(x - SIDEWALK * 0.45, 0.2, z - 0.08),
                        Vec3::new(x + SIDEWALK * 0.45, 3.0, z + 0.08),
                    )
                } else {
                    (
                        Vec3::new(x - 0.08, 0.2, z - 3.5),
                        Vec3::new(x + 0.08, 3.0, z + 3.5),
                    )
                };
                add_glass(scene, Mesh::cuboid(lo, hi), pane);
                across = !across;
            }
            z += rng.range(18.0, 30.0);
        }
    }
    let sphere = |scene: &mut Scene, centre: Vec3, r: f32| {
        let mut mesh = Mesh::default();
        mesh.append(&Mesh::sphere(r, 12, 24), Mat4::from_translation(centre));
        add_glass(scene, mesh, bubble);
    };
    let mut z = -STREET_HALF_LENGTH + 8.0;
    while z < STREET_HALF_LENGTH - 8.0 {
        // Among the lights (1 to 6 units up), so they are lit from around them.
        let r = rng.range(1.0, 2.4);
        let centre = Vec3::new(rng.range(-m + 3.0, m - 3.0), r + rng.range(0.3, 3.5), z);
        sphere(scene, centre, r);
        z += rng.range(9.0, 16.0);
    }
    // Around the camera at frame 150 ((4, 6, -10) in `robots_street`).
    sphere(scene, Vec3::new(4.5, 6.5, -9.0), 3.5);
}

/// Translucent blocks and spheres among the random lights (tiled-forward-shading Fig. 4.6's
/// field, with transparent geometry as in §4.5).
fn field_glass(scene: &mut Scene, seed: u64) {
    let mut rng = Rng::new(seed ^ 0x61a5_55e5_0000_0002);
    let tints = [
        Vec3::new(0.6, 0.85, 0.7),
        Vec3::new(0.85, 0.75, 0.55),
        Vec3::new(0.6, 0.7, 0.95),
    ];
    let materials: Vec<usize> = tints
        .iter()
        .enumerate()
        .map(|(i, &t)| add_material(scene, Material::glass(t, 0.3 + 0.1 * i as f32)))
        .collect();
    for i in 0..48 {
        let centre = Vec3::new(
            rng.range(-75.0, 75.0),
            rng.range(2.0, 8.0),
            rng.range(-75.0, 75.0),
        );
        let size = rng.range(1.5, 3.5);
        let material = materials[i % materials.len()];
        let mesh = if i % 2 == 0 {
            Mesh::cuboid(centre - Vec3::splat(size), centre + Vec3::splat(size))
        } else {
            let mut m = Mesh::default();
            m.append(&Mesh::sphere(size, 10, 20), Mat4::from_translation(centre));
            m
        };
        add_glass(scene, mesh, material);
    }
}

/// Reach of a robot's headlight.
pub(crate) const HEADLIGHT_RANGE: f32 = 35.0;

fn robots_many(p: &SceneParams) -> Scene {
    let (mut b, robots) = robots_street("robots-many", p.seed);
    if p.headlights {
        headlights(&mut b, &robots);
    }
    let per_path = ROBOTS_MANY_LIGHTS / ROBOT_COUNT;
    for path in 0..ROBOT_COUNT {
        let len = b.scene.paths[path].length();
        for k in 0..per_path {
            let (pos, dir) = b.scene.paths[path].sample((k as f32 + 0.5) * len / per_path as f32);
            let sideways = dir.cross(Vec3::Y) * b.rng.range(-5.0, 5.0);
            let light = Light {
                position: pos + sideways + Vec3::Y * b.rng.range(1.0, 6.0),
                color: b.light_color(),
                intensity: 0.35,
                range: ROBOTS_MANY_RANGE,
                spot: None,
            };
            b.light(light, LightAnchor::World);
        }
    }
    b.scene
}

fn robots_few(p: &SceneParams) -> Scene {
    let (mut b, robots) = robots_street("robots-few", p.seed);
    if p.headlights {
        headlights(&mut b, &robots);
    }
    for body in robots {
        let light = Light {
            position: Vec3::new(0.0, 14.0, 0.0),
            color: b.light_color(),
            intensity: 1.2,
            range: ROBOTS_FEW_RANGE,
            spot: None,
        };
        b.light(light, LightAnchor::Object(body));
    }
    b.scene
}

// ---------------------------------------------------------------- scattered (Forward+ demo)

fn scattered(p: &SceneParams) -> Scene {
    let mut keys = Vec::new();
    for k in 0..=6u32 {
        let a = k as f32 / 6.0 * std::f32::consts::PI;
        keys.push((
            k * 20,
            Vec3::new(
                a.cos() * 110.0,
                28.0 + 8.0 * (a * 2.0).sin(),
                a.sin() * 110.0,
            ),
            Vec3::new(0.0, 8.0, 0.0),
        ));
    }
    let camera = CameraPath {
        keys,
        ups: Vec::new(),
        fov_y: 60f32.to_radians(),
        near: 0.5,
        far: 600.0,
    };
    let mut b = Builder::new("scattered", p.seed, camera, (1280, 720));
    let floor = b.material(Material::plain(Vec3::splat(0.55), 0.2, 16.0));
    // The pillars are rim-lit (tiled-forward-shading §4.7's per-material shaders).
    let rim = b.material(Material {
        shader: MaterialShader::Rim {
            color: Vec3::new(0.35, 0.55, 1.0),
            power: 3.0,
        },
        ..Material::plain(Vec3::new(0.66, 0.62, 0.56), 0.4, 32.0)
    });
    let shiny = b.material(Material::plain(Vec3::new(0.35, 0.40, 0.50), 0.9, 96.0));
    b.object(
        Mesh::ground(-100.0, -100.0, 100.0, 100.0, 0.0),
        floor,
        Motion::Static,
    );
    let mut pillars = Mesh::default();
    for i in 0..6 {
        for j in 0..6 {
            let pos = Vec3::new(-75.0 + i as f32 * 30.0, 0.0, -75.0 + j as f32 * 30.0);
            pillars.append(&Mesh::cylinder(2.0, 30.0, 24), Mat4::from_translation(pos));
        }
    }
    b.object(pillars, rim, Motion::Static);
    let mut blocks = Mesh::default();
    for _ in 0..60 {
        let c = Vec3::new(b.rng.range(-90.0, 90.0), 0.0, b.rng.range(-90.0, 90.0));
        let s = Vec3::new(
            b.rng.range(2.0, 8.0),
            b.rng.range(1.0, 10.0),
            b.rng.range(2.0, 8.0),
        );
        blocks.append(
            &Mesh::block(c - s * Vec3::new(1.0, 0.0, 1.0), c + s),
            Mat4::IDENTITY,
        );
    }
    for _ in 0..20 {
        let c = Vec3::new(
            b.rng.range(-90.0, 90.0),
            b.rng.range(3.0, 25.0),
            b.rng.range(-90.0, 90.0),
        );
        blocks.append(
            &Mesh::sphere(b.rng.range(1.5, 4.0), 12, 24),
            Mat4::from_translation(c),
        );
    }
    b.object(blocks, shiny, Motion::Static);
    // The demo's lights move (forward-plus §5): each circles an axis of its own, from its
    // place at frame 0, with radii and speeds from a stream of their own (so the rest of the
    // scene, and frame 0, are as before).
    let mut motion = Rng::new(p.seed ^ 0x5ca7_7e2e_d11f_0a75);
    for _ in 0..SCATTERED_LIGHTS {
        let light = Light {
            position: Vec3::new(
                b.rng.range(-100.0, 100.0),
                b.rng.range(0.5, 35.0),
                b.rng.range(-100.0, 100.0),
            ),
            color: b.light_color(),
            intensity: 0.6,
            range: 10.0,
            spot: None,
        };
        let anchor = LightAnchor::Circle {
            radius: motion.range(2.0, 8.0),
            frames_per_turn: motion.range(60.0, 240.0),
            phase: motion.range(0.0, std::f32::consts::TAU),
        };
        b.light(light, anchor);
    }
    b.scene
}

// ---------------------------------------------------------------- random lights (Fig. 4.6)

fn random_field(name: &str, seed: u64, camera: CameraPath) -> Scene {
    let mut b = Builder::new(name, seed, camera, (640, 360));
    let ground = b.material(Material::plain(Vec3::new(0.45, 0.50, 0.42), 0.1, 8.0));
    let block = b.material(Material::plain(Vec3::new(0.70, 0.66, 0.60), 0.3, 32.0));
    b.object(
        Mesh::ground(-100.0, -100.0, 100.0, 100.0, 0.0),
        ground,
        Motion::Static,
    );
    let field = b.block_field(80.0, 12, 2.5, (1.0, 9.0));
    b.object(field, block, Motion::Static);
    for _ in 0..RANDOM_LIGHTS {
        let light = Light {
            position: Vec3::new(
                b.rng.range(-80.0, 80.0),
                b.rng.range(0.5, 6.0),
                b.rng.range(-80.0, 80.0),
            ),
            color: b.light_color(),
            intensity: 0.9,
            range: 9.0,
            spot: None,
        };
        b.light(light, LightAnchor::World);
    }
    b.scene
}

fn random_top(p: &SceneParams) -> Scene {
    let camera = CameraPath {
        keys: vec![
            (0, Vec3::new(-20.0, 150.0, 10.0), Vec3::new(-20.0, 0.0, 0.0)),
            (119, Vec3::new(20.0, 150.0, 10.0), Vec3::new(20.0, 0.0, 0.0)),
        ],
        ups: Vec::new(),
        fov_y: 60f32.to_radians(),
        near: 1.0,
        far: 400.0,
    };
    random_field("random-top", p.seed, camera)
}

fn random_fps(p: &SceneParams) -> Scene {
    let camera = CameraPath {
        keys: vec![
            (0, Vec3::new(-75.0, 2.5, -72.0), Vec3::new(0.0, 2.0, 0.0)),
            (
                119,
                Vec3::new(-45.0, 2.5, -40.0),
                Vec3::new(30.0, 2.0, 30.0),
            ),
        ],
        ups: Vec::new(),
        fov_y: 60f32.to_radians(),
        near: 0.3,
        far: 400.0,
    };
    random_field("random-fps", p.seed, camera)
}

// ---------------------------------------------------------------- stress

fn stress(p: &SceneParams) -> Scene {
    let n = p.lights.unwrap_or(STRESS_DEFAULT_LIGHTS);
    let camera = CameraPath {
        keys: vec![
            (0, Vec3::new(0.0, 110.0, 230.0), Vec3::new(0.0, 0.0, 20.0)),
            (119, Vec3::new(160.0, 90.0, 160.0), Vec3::new(0.0, 0.0, 0.0)),
        ],
        ups: Vec::new(),
        fov_y: 60f32.to_radians(),
        near: 1.0,
        far: 1000.0,
    };
    let mut b = Builder::new("stress", p.seed, camera, (640, 360));
    let ground = b.material(Material::plain(Vec3::splat(0.5), 0.2, 16.0));
    let block = b.material(Material::plain(Vec3::new(0.62, 0.64, 0.70), 0.4, 32.0));
    let half = 200.0;
    b.object(
        Mesh::ground(-half, -half, half, half, 0.0),
        ground,
        Motion::Static,
    );
    let field = b.block_field(half, 20, 3.0, (2.0, 20.0));
    b.object(field, block, Motion::Static);
    // Keep the number of lights reaching a ground point roughly constant (about 12) as the
    // count grows: coverage = n * pi * r^2 / area.
    let range = (25.0 * (1000.0 / n as f32).sqrt()).clamp(0.4, 40.0);
    let intensity = 0.35;
    for _ in 0..n {
        let light = Light {
            position: Vec3::new(
                b.rng.range(-half, half),
                b.rng.range(0.2, 0.2 + range.min(12.0)),
                b.rng.range(-half, half),
            ),
            color: b.light_color(),
            intensity,
            range,
            spot: None,
        };
        b.light(light, LightAnchor::World);
    }
    b.scene
}
