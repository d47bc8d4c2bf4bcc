//! Shadows (`--shadows`): which lights cast them this frame, and the ray-cast form
//! (Forward+ §6's future work: "shadow computation from all the lights in the scene by local
//! short ray casting to the lights").
//!
//! With `--shadows rays` the one light function (`shading/lighting.wgsl`) multiplies a
//! shadow-casting light's terms by the visibility of one ray from the sample to the light
//! (`shading/shadows.wgsl`), so every pipeline shadows alike. The rays walk two hierarchies
//! over the opaque triangles (`bvh::TriangleBvh`): the static objects', built once per scene,
//! and the moving objects', rebuilt every frame. Transparent objects and alpha-tested
//! (cut-out) materials cast no shadow: a ray does not read textures.
//!
//! **Shadow space**: the triangles are stored relative to an anchor (the centre of the static
//! geometry's box), so a scene far from the origin keeps its precision; a sample's
//! camera-relative position reaches it by adding `eye − anchor` (the header's origin).
//!
//! **Which lights cast** (`--shadow-lights N`): the N most important this frame, importance
//! being the light's brightness (the luminance of colour × intensity) times its screen
//! coverage (the square of its bounding sphere's radius over its distance from the eye,
//! capped at 1 when the eye is inside it), 0 for a sphere outside the view frustum; ties go to
//! the lower index. The others light unshadowed, counted as such (`ShadowFrame::unshadowed`).

pub mod bvh;
pub mod maps;

use crate::scene::{Camera, Geometry, Light};
use bvh::{Triangle, TriangleBvh};
use glam::{Vec3, Vec4Swizzles};

/// Vec4s of the header at the start of the shadow buffer (`shadows.wgsl`):
/// `[origin = eye − anchor, bias]`, `[bits(static root), bits(moving root),
/// bits(caster words' first vec4), relative bias]`; a root of [`NO_TREE`] is an empty tree.
pub(crate) const HEADER_VEC4S: u32 = 2;
/// The root of an empty hierarchy.
pub(crate) const NO_TREE: u32 = crate::consts::SHADOW_NO_TREE;

/// The offset of a ray's origin along the surface normal, in world units: `BIAS_REL` × the
/// sample's distance from the eye (what interpolating a position, or rebuilding it from a
/// depth buffer, loses: a few 1e-7 of it) plus `BIAS_EXTENT` × the scene's size (the
/// rounding of f32 positions in shadow space, a few 1e-8 of it). No term grows with the
/// distance from the origin: a scene's f32 vertices minus an eye or an anchor near them are
/// exact (Sterbenz), so a scene 10⁶ units away shadows like one at the origin. Measured: no
/// surface shadows itself on the catalog's scenes, near the origin or 1.4·10⁵ from it
/// (tests/shadows.rs, tests/pipelines.rs). The ray ends at the light itself (a triangle counts
/// strictly before it): a light is exact, and one just behind a wall is behind it.
pub(crate) const BIAS_REL: f32 = 2e-5;
pub(crate) const BIAS_EXTENT: f32 = 1e-6;

/// The triangles that cast shadows in `geometry` (whose index values start at vertex `base`):
/// its opaque runs that are not alpha tested, relative to `anchor`.
pub(crate) fn casting_triangles(geometry: &Geometry, base: u32, anchor: Vec3) -> Vec<Triangle> {
    let mut out = Vec::new();
    let (opaque, _) = geometry.split_draws();
    for d in opaque.iter().filter(|d| !d.alpha_test) {
        let run = &geometry.indices[d.first as usize..(d.first + d.count) as usize];
        for t in run.chunks_exact(3) {
            out.push(std::array::from_fn(|k| {
                Vec3::from(geometry.vertices[(t[k] - base) as usize].position) - anchor
            }));
        }
    }
    out
}

/// What the static part of a scene gives every frame's shadows: the anchor, the biases and
/// the static objects' hierarchy.
#[derive(Clone, Debug)]
pub(crate) struct StaticShadows {
    pub anchor: Vec3,
    pub bias: f32,
    pub bvh: TriangleBvh,
}

impl StaticShadows {
    /// From a scene's `Scene::static_geometry` (the renderer's upload, baked once).
    pub fn new(geometry: &Geometry) -> StaticShadows {
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for v in &geometry.vertices {
            lo = lo.min(Vec3::from(v.position));
            hi = hi.max(Vec3::from(v.position));
        }
        let anchor = if lo.x <= hi.x {
            (lo + hi) * 0.5
        } else {
            Vec3::ZERO
        };
        let extent = if lo.x <= hi.x {
            (hi - lo).max_element()
        } else {
            0.0
        };
        let bias = BIAS_EXTENT * extent.max(1.0);
        let bvh = TriangleBvh::build(casting_triangles(geometry, 0, anchor));
        StaticShadows { anchor, bias, bvh }
    }

    /// The static hierarchy, for the buffer at [`HEADER_VEC4S`].
    pub fn gpu_data(&self) -> Vec<[f32; 4]> {
        let mut out = Vec::with_capacity(self.bvh.vec4s() as usize);
        self.bvh.write_gpu(HEADER_VEC4S, &mut out);
        out
    }

    /// Where each frame's part of the buffer starts (after the static hierarchy).
    pub fn frame_start(&self) -> u32 {
        HEADER_VEC4S + self.bvh.vec4s()
    }
}

/// One frame's shadow data: the moving objects' hierarchy and which lights cast.
#[derive(Clone, Debug)]
pub(crate) struct ShadowFrame {
    pub moving: TriangleBvh,
    /// Per light: does it cast shadows this frame?
    pub casters: Vec<bool>,
    /// `eye − anchor`: a camera-relative position plus this is in shadow space.
    pub origin: Vec3,
}

impl ShadowFrame {
    /// `frame_geometry` is the frame's moving geometry with index values from vertex `base`.
    pub fn new(
        statics: &StaticShadows,
        frame_geometry: &Geometry,
        base: u32,
        camera: &Camera,
        aspect: f32,
        lights: &[Light],
        shadow_lights: Option<u32>,
    ) -> ShadowFrame {
        let moving = TriangleBvh::build(casting_triangles(frame_geometry, base, statics.anchor));
        ShadowFrame {
            moving,
            casters: casters(lights, camera, aspect, shadow_lights),
            origin: camera.eye - statics.anchor,
        }
    }

    /// Lights lit without shadows this frame.
    pub fn unshadowed(&self) -> usize {
        self.casters.iter().filter(|&&c| !c).count()
    }

    /// The whole buffer (`shadows.wgsl`'s layout): the header, the static hierarchy at
    /// [`HEADER_VEC4S`] ([`StaticShadows::gpu_data`]), then what changes between frames of one
    /// scene ([`Self::frame_data`], at [`StaticShadows::frame_start`]).
    #[cfg(test)]
    pub fn gpu_data(&self, statics: &StaticShadows) -> Vec<[f32; 4]> {
        let mut out = self.header(statics).to_vec();
        out.extend(statics.gpu_data());
        out.extend(self.frame_data(statics));
        out
    }

    /// The header: `[origin, bias]`, `[bits(static root), bits(moving root), bits(casters'
    /// first vec4), relative bias]`.
    pub fn header(&self, statics: &StaticShadows) -> [[f32; 4]; 2] {
        let static_root = HEADER_VEC4S;
        let moving_root = statics.frame_start();
        let casters_at = moving_root + self.moving.vec4s();
        let root = |b: &TriangleBvh, at: u32| if b.nodes.is_empty() { NO_TREE } else { at };
        [
            [self.origin.x, self.origin.y, self.origin.z, statics.bias],
            [
                f32::from_bits(root(&statics.bvh, static_root)),
                f32::from_bits(root(&self.moving, moving_root)),
                f32::from_bits(casters_at),
                BIAS_REL,
            ],
        ]
    }

    /// The moving objects' hierarchy, then the casters' bits (128 lights per vec4).
    pub fn frame_data(&self, statics: &StaticShadows) -> Vec<[f32; 4]> {
        let mut out =
            Vec::with_capacity(self.moving.vec4s() as usize + self.casters.len() / 128 + 1);
        self.moving.write_gpu(statics.frame_start(), &mut out);
        for chunk in self.casters.chunks(128) {
            let mut words = [0u32; 4];
            for (i, &c) in chunk.iter().enumerate() {
                words[i / 32] |= u32::from(c) << (i % 32);
            }
            out.push(words.map(f32::from_bits));
        }
        out
    }
}

/// The shadow ray from a camera-relative surface point to a camera-relative light position,
/// as `shadows.wgsl` makes it: origin in shadow space, pushed off the surface along its normal,
/// and the vector to the light (the segment is `o + t·d`, 0 < t < 1).
pub fn ray(from: Vec3, normal: Vec3, to: Vec3, origin: Vec3, bias: f32) -> (Vec3, Vec3) {
    let b = bias + BIAS_REL * from.length();
    let o = from + normal * b + origin;
    (o, to + origin - o)
}

/// Which lights cast shadows this frame (module docs: the `n` most important).
pub fn casters(lights: &[Light], camera: &Camera, aspect: f32, n: Option<u32>) -> Vec<bool> {
    let Some(n) = n else {
        return vec![true; lights.len()];
    };
    let view = camera.rotation();
    let proj = camera.proj(aspect);
    let (px, py) = (proj.x_axis.x, proj.y_axis.y);
    let inside = |c: Vec3, r: f32| {
        let v = (view * (c - camera.eye).extend(1.0)).xyz();
        let w = -v.z;
        w + r >= camera.near
            && w - r <= camera.far
            && (px * v.x.abs() - w) / (px * px + 1.0).sqrt() <= r
            && (py * v.y.abs() - w) / (py * py + 1.0).sqrt() <= r
    };
    let mut ranked: Vec<(f32, usize)> = lights
        .iter()
        .enumerate()
        .map(|(i, l)| (importance(l, camera.eye, &inside), i))
        .collect();
    ranked.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut out = vec![false; lights.len()];
    for &(_, i) in ranked.iter().take(n as usize) {
        out[i] = true;
    }
    out
}

fn importance(l: &Light, eye: Vec3, inside: &dyn Fn(Vec3, f32) -> bool) -> f32 {
    let (c, r) = l.bounding_sphere();
    if !inside(c, r) {
        return 0.0;
    }
    let d2 = c.distance_squared(eye);
    let coverage = if d2 <= r * r { 1.0 } else { r * r / d2 };
    let brightness = (l.color * l.intensity).dot(Vec3::new(0.2126, 0.7152, 0.0722));
    coverage * brightness.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn light(position: Vec3, intensity: f32, range: f32) -> Light {
        Light {
            position,
            color: Vec3::ONE,
            intensity,
            range,
            spot: None,
        }
    }

    fn camera() -> Camera {
        Camera {
            eye: Vec3::ZERO,
            target: -Vec3::Z,
            up: Vec3::Y,
            fov_y: 1.0,
            near: 0.1,
            far: 100.0,
        }
    }

    #[test]
    fn the_brightest_nearest_lights_in_view_cast_and_those_behind_do_not() {
        let lights = [
            light(Vec3::new(0.0, 0.0, -10.0), 1.0, 2.0),  // in view
            light(Vec3::new(0.0, 0.0, 10.0), 100.0, 2.0), // behind: importance 0
            light(Vec3::new(0.0, 0.0, -40.0), 1.0, 2.0),  // in view, farther
            light(Vec3::new(1.0, 0.0, -10.0), 5.0, 2.0),  // in view, brighter
        ];
        let c = casters(&lights, &camera(), 1.0, Some(2));
        assert_eq!(c, vec![true, false, false, true]);
        assert_eq!(casters(&lights, &camera(), 1.0, None), vec![true; 4]);
        assert_eq!(casters(&lights, &camera(), 1.0, Some(9)), vec![true; 4]);
        // The eye inside a light's sphere: full coverage.
        let around = [
            light(Vec3::ZERO, 1.0, 5.0),
            light(Vec3::new(0.0, 0.0, -3.0), 1.5, 1.0),
        ];
        assert_eq!(casters(&around, &camera(), 1.0, Some(1)), vec![true, false]);
    }

    #[test]
    fn the_ray_starts_off_the_surface_and_ends_at_the_light() {
        let (o, d) = ray(
            Vec3::new(0.0, 0.0, -10.0),
            Vec3::Z,
            Vec3::new(0.0, 0.0, -5.0),
            Vec3::new(100.0, 0.0, 0.0),
            0.01,
        );
        let b = 0.01 + BIAS_REL * 10.0;
        assert!((o - Vec3::new(100.0, 0.0, -10.0 + b)).length() < 1e-5);
        assert!((o + d - Vec3::new(100.0, 0.0, -5.0)).length() < 1e-5);
    }

    #[test]
    fn the_gpu_header_points_at_both_trees_and_the_casters() {
        let quad = |z: f32| -> Vec<Triangle> {
            vec![[
                Vec3::new(0.0, 0.0, z),
                Vec3::new(1.0, 0.0, z),
                Vec3::new(0.0, 1.0, z),
            ]]
        };
        let statics = StaticShadows {
            anchor: Vec3::ONE,
            bias: 0.001,
            bvh: TriangleBvh::build(quad(0.0)),
        };
        let mut casters = vec![false; 200];
        casters[3] = true;
        casters[130] = true;
        let frame = ShadowFrame {
            moving: TriangleBvh::default(),
            casters,
            origin: Vec3::new(1.0, 2.0, 3.0),
        };
        let data = frame.gpu_data(&statics);
        assert_eq!(data[1][0].to_bits(), HEADER_VEC4S);
        assert_eq!(data[1][1].to_bits(), NO_TREE);
        let at = data[1][2].to_bits() as usize;
        assert_eq!(at, (HEADER_VEC4S + statics.bvh.vec4s()) as usize);
        assert_eq!(data[at][0].to_bits(), 1 << 3);
        assert_eq!(data[at + 1][0].to_bits(), 1 << 2);
        assert_eq!(data.len(), at + 2);
        assert_eq!(frame.unshadowed(), 198);
    }
}
