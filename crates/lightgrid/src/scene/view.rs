//! What light assignment needs to know about the camera: view transform, projection scale,
//! near/far, frame size; and the conversions between pixels, depth and view space.
//!
//! View space is right-handed with the camera looking down -z; "view distance" `w = -z`.
//! The GPU works in camera-relative space (world minus the eye, world-aligned): `view` maps
//! it to view space and carries no translation, and [`ViewSetup::relative`] takes a world
//! point there the way the renderer's upload and vertex stage do, so the CPU twins see the
//! same numbers as the kernels however far from the origin the scene lies.

use super::{Camera, Light};
use crate::consts::CONE_SLACK;
use glam::{Mat4, Vec3};

/// What spot lights are culled by (`--spot-cull`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SpotCull {
    /// The tightest sphere around the cone's sector (the baseline, test (a) of the issue).
    Sphere,
    /// The sphere, then the cone itself against each cell's bounding sphere: conservative by
    /// construction (`ViewLight::may_reach_sphere`).
    #[default]
    Cone,
}

/// One frame's camera as light assignment sees it: view rotation, projection scale, depth
/// range and frame size in pixels.
#[derive(Clone, Copy, Debug)]
pub struct ViewSetup {
    /// Camera-relative space to view space: a rotation (`Camera::rotation`).
    pub view: Mat4,
    /// The camera's world position: camera-relative space's origin.
    pub eye: Vec3,
    /// `proj[0][0]` and `proj[1][1]`: x_ndc = p00 * x / w, y_ndc = p11 * y / w.
    pub p00: f32,
    /// `proj[1][1]`: the vertical projection scale, 1 / tan(fov_y / 2).
    pub p11: f32,
    /// `proj[2][0]` and `proj[2][1]`: an off-centre projection's shift (TAA jitter, a VR eye,
    /// an off-axis display; 0 for a symmetric one): x_ndc = p00 * x / w - p20,
    /// y_ndc = p11 * y / w - p21.
    pub p20: f32,
    /// `proj[2][1]`: see [`Self::p20`].
    pub p21: f32,
    /// Near-plane view distance (the camera's `near`), in scene units.
    pub near: f32,
    /// Far-plane view distance (the camera's `far`), in scene units.
    pub far: f32,
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// What spot lights are culled by; `to_view` hands it to each light.
    pub spot_cull: SpotCull,
}

/// A light in view space: the sphere culling starts from (the light's bounding sphere), and
/// what it exactly reaches.
#[derive(Clone, Copy, Debug)]
pub struct ViewLight {
    /// Bounding sphere: everything the light reaches is inside it.
    pub center: Vec3,
    /// Radius of the bounding sphere, in scene units.
    pub radius: f32,
    /// The light's position in view space (a spot's cone apex).
    pub apex: Vec3,
    /// The light's range: it reaches nothing at or beyond this distance from `apex`.
    pub range: f32,
    /// A spot's unit axis and outer cosine.
    pub cone: Option<(Vec3, f32)>,
    /// Cull by the cone as well as the sphere (`SpotCull::Cone`).
    pub cull_by_cone: bool,
}

/// Is the offset `d` from a light inside its `range` and, for a spot, its outer cone
/// (unit axis, outer cosine)? The light function's factors are positive exactly there.
pub(super) fn reaches(d: Vec3, range: f32, cone: Option<(Vec3, f32)>) -> bool {
    let dist_sq = d.length_squared();
    if dist_sq >= range * range {
        return false;
    }
    match cone {
        None => true,
        Some((axis, cos_outer)) => d.dot(axis) > cos_outer * dist_sq.sqrt(),
    }
}

impl ViewLight {
    /// Does the light reach view-space point `p` (the light function's factors are positive
    /// exactly there: inside the range and the outer cone)?
    pub fn reaches(&self, p: Vec3) -> bool {
        reaches(p - self.apex, self.range, self.cone)
    }

    /// May the light reach anything inside the view-space sphere (c, r)? The bounding sphere
    /// is tested by the caller (against a frustum, a rectangle, a box); this adds the cone,
    /// when culling by it. Never false for a sphere the light reaches into: for a cone of
    /// half-angle θ ≤ 90°, `cos θ · |v⊥| - v∥ · sin θ` (v = c - apex, split along and across
    /// the axis) is |v| sin(α - θ), α the angle between v and the axis: the distance from c to
    /// the cone's boundary line when α - θ ≤ 90°, and less than the distance to the cone (the
    /// apex, |v|) beyond; inside the cone it is negative. So "more than r" means the sphere
    /// misses the cone. Points the cone lights also lie in front of the apex (v∥ ≥ 0) and
    /// within the range. Wider cones are left to the sphere.
    pub fn may_reach_sphere(&self, c: Vec3, r: f32) -> bool {
        self.cone_margin(c, r) >= 0.0
    }

    /// The box (view space) a spot culled by its cone is bounded by: the cone sector's box,
    /// within its bounding sphere's. Along each axis e the sector reaches from the apex to
    /// the cap's rim circle (centre r cos θ along the axis, radius r sin θ: the extent
    /// r (a cos θ ± sin θ √(1 - a²)) for a = axis · e), and to the full range r where e lies
    /// inside the cone (±a ≥ cos θ). None for point lights, wider cones and sphere culling.
    /// `reach_box` in `tile_frustum.wgsl` is its GPU twin.
    pub fn reach_box(&self) -> Option<(Vec3, Vec3)> {
        let (axis, cos) = self
            .cone
            .filter(|&(_, cos)| self.cull_by_cone && cos > 0.0)?;
        let (mut lo, mut hi) = (
            self.center - Vec3::splat(self.radius),
            self.center + Vec3::splat(self.radius),
        );
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let r = self.range;
        for i in 0..3 {
            let a = axis[i];
            let spread = sin * (1.0 - a * a).max(0.0).sqrt();
            let top = if a >= cos { r } else { r * (cos * a + spread) };
            let bottom = if -a >= cos {
                -r
            } else {
                r * (cos * a - spread)
            };
            hi[i] = hi[i].min(self.apex[i] + top.max(0.0));
            lo[i] = lo[i].max(self.apex[i] + bottom.min(0.0));
        }
        Some((lo, hi))
    }

    /// How far the cone reaches into the sphere (c, r), as [`Self::may_reach_sphere`]
    /// decides (≥ 0: it may reach it; infinite when not culling by a cone). `cone_margin` in
    /// `tile_frustum.wgsl` is its GPU twin.
    pub fn cone_margin(&self, c: Vec3, r: f32) -> f32 {
        let Some((axis, cos)) = self.cone.filter(|_| self.cull_by_cone) else {
            return f32::INFINITY;
        };
        // Round-off slack for the cell sphere (the GPU twin uses the same).
        let r = r * (1.0 + CONE_SLACK) + CONE_SLACK;
        let v = c - self.apex;
        let m = self.range + r - v.length();
        if cos <= 0.0 {
            return m;
        }
        let along = v.dot(axis);
        // The distance from the axis as the length of v's perpendicular part: computing it as
        // sqrt(|v|² - along²) cancels catastrophically for a far cell near the axis (an error
        // of ~0.3 at 800 units, larger than a small light's slack).
        let across = (v - axis * along).length();
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        m.min(along + r).min(r - (cos * across - along * sin))
    }
}

impl ViewSetup {
    /// The setup for `camera` rendering a `width` × `height` pixel frame, culling spots by
    /// [`SpotCull`]'s default.
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let proj = camera.proj(width as f32 / height as f32);
        ViewSetup {
            view: camera.rotation(),
            eye: camera.eye,
            p00: proj.x_axis.x,
            p11: proj.y_axis.y,
            p20: proj.z_axis.x,
            p21: proj.z_axis.y,
            near: camera.near,
            far: camera.far,
            width,
            height,
            spot_cull: SpotCull::default(),
        }
    }

    /// A world point in camera-relative space, computed as the GPU computes it (an f32
    /// difference, exact for points near the eye however large their coordinates).
    pub fn relative(&self, world: Vec3) -> Vec3 {
        world - self.eye
    }

    /// A world point in view space.
    pub fn view_point(&self, world: Vec3) -> Vec3 {
        self.view.transform_point3(self.relative(world))
    }

    /// A view-space point in the world ([`Self::view_point`]'s inverse).
    pub fn world_point(&self, view: Vec3) -> Vec3 {
        self.view.transpose().transform_point3(view) + self.eye
    }

    /// A light in view space, its bounding sphere computed camera-relative as the GPU's
    /// (`Light::relative_to`).
    pub fn to_view(&self, l: &Light) -> ViewLight {
        let l = &l.relative_to(self.eye);
        let (center, radius) = l.bounding_sphere();
        ViewLight {
            center: self.view.transform_point3(center),
            radius,
            apex: self.view.transform_point3(l.position),
            range: l.range,
            cone: l.spot.map(|s| {
                let axis = self
                    .view
                    .transform_vector3(s.direction)
                    .normalize_or(s.direction);
                (axis, s.cos_outer)
            }),
            cull_by_cone: self.spot_cull == SpotCull::Cone,
        }
    }

    /// The bounding sphere (view space) of the frustum piece over pixel rectangle
    /// `[x0, x1) x [y0, y1)` between view distances `w_min` and `w_max`: the centre of its
    /// eight corners and the farthest corner. `tile_frustum.wgsl` computes the same.
    pub fn cell_sphere(
        &self,
        (x0, y0, x1, y1): (u32, u32, u32, u32),
        w_min: f32,
        w_max: f32,
    ) -> (Vec3, f32) {
        let ndc_x = |x: u32| x as f32 / self.width as f32 * 2.0 - 1.0 + self.p20;
        let ndc_y = |y: u32| 1.0 - y as f32 / self.height as f32 * 2.0 + self.p21;
        let mut corners = [Vec3::ZERO; 8];
        let mut i = 0;
        for w in [w_min, w_max] {
            for nx in [ndc_x(x0), ndc_x(x1)] {
                for ny in [ndc_y(y0), ndc_y(y1)] {
                    corners[i] = Vec3::new(nx / self.p00 * w, ny / self.p11 * w, -w);
                    i += 1;
                }
            }
        }
        let center = corners.iter().copied().sum::<Vec3>() / 8.0;
        let radius = corners
            .iter()
            .map(|p| p.distance(center))
            .fold(0.0f32, f32::max);
        (center, radius)
    }

    /// The view distance of every sample of a depth buffer (reversed-Z, `crate::depth`;
    /// infinite where it holds no geometry).
    pub fn view_distances(&self, depth: &[f32]) -> Vec<f32> {
        depth.iter().map(|&d| self.view_distance(d)).collect()
    }

    /// View distance of a depth-buffer value (the projection's inverse; infinite for the
    /// background).
    pub fn view_distance(&self, depth: f32) -> f32 {
        crate::depth::view_distance(depth, self.near, self.far)
    }

    /// The depth-buffer value the projection gives view distance `w`.
    pub fn depth_of(&self, w: f32) -> f32 {
        crate::depth::depth_of(w, self.near, self.far)
    }

    /// View-space position of the sample at the centre of pixel (x, y) at view distance `w`.
    pub fn sample_position(&self, x: u32, y: u32, w: f32) -> Vec3 {
        let ndc_x = (x as f32 + 0.5) / self.width as f32 * 2.0 - 1.0 + self.p20;
        let ndc_y = 1.0 - (y as f32 + 0.5) / self.height as f32 * 2.0 + self.p21;
        Vec3::new(ndc_x / self.p00 * w, ndc_y / self.p11 * w, -w)
    }
}
