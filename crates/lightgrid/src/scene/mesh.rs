//! Indexed triangle meshes with normals and UVs, and the primitives the catalog builds from.

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

/// The axis-aligned bounds (min, max) of `points`; `None` for no points.
pub(crate) fn bounds_of(points: impl IntoIterator<Item = Vec3>) -> Option<(Vec3, Vec3)> {
    points.into_iter().fold(None, |b, p| match b {
        None => Some((p, p)),
        Some((lo, hi)) => Some((lo.min(p), hi.max(p))),
    })
}

/// An indexed triangle mesh (counter-clockwise front faces).
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Vertex positions in the mesh's own (object) space.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals in object space, one per position.
    pub normals: Vec<Vec3>,
    /// Texture coordinate set 0, one per position (UV (0, 0) is a texture's first texel).
    pub uvs: Vec<Vec2>,
    /// Three vertex indices per triangle, counter-clockwise seen from the front.
    pub indices: Vec<u32>,
    /// Per vertex, or empty: tangents (xyz, and the bitangent's sign in w) for normal
    /// textures, from the file or generated (MikkTSpace).
    pub tangents: Vec<Vec4>,
    /// Per vertex, or empty (white): colours multiplying the base colour (glTF's `COLOR_0`).
    pub colors: Vec<Vec4>,
    /// Per vertex, or empty (set 0 stands in): texture coordinate set 1.
    pub uvs1: Vec<Vec2>,
}

impl Mesh {
    /// Number of triangles (a third of the indices).
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Centre of the axis-aligned bounds (the origin for an empty mesh).
    pub fn centre(&self) -> Vec3 {
        bounds_of(self.positions.iter().copied()).map_or(Vec3::ZERO, |(lo, hi)| (lo + hi) * 0.5)
    }

    /// Reverse every triangle's winding (front faces become back faces).
    pub fn flip_winding(&mut self) {
        for t in self.indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
    }

    /// Append `other` transformed by `m`.
    pub fn append(&mut self, other: &Mesh, m: Mat4) {
        let base = self.positions.len() as u32;
        let nm = Mat3::from_mat4(m).inverse().transpose();
        self.positions
            .extend(other.positions.iter().map(|p| m.transform_point3(*p)));
        self.normals
            .extend(other.normals.iter().map(|n| (nm * *n).normalize_or_zero()));
        self.uvs.extend_from_slice(&other.uvs);
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }

    fn quad(&mut self, corner: Vec3, u: Vec3, v: Vec3, uv_scale: Vec2) {
        let n = u.cross(v).normalize();
        let base = self.positions.len() as u32;
        for (a, b) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            self.positions.push(corner + u * a + v * b);
            self.normals.push(n);
            self.uvs.push(Vec2::new(a, b) * uv_scale);
        }
        self.indices
            .extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
    }

    /// An axis-aligned box from `min` to `max`, faces pointing out.
    pub fn cuboid(min: Vec3, max: Vec3) -> Mesh {
        Self::box_faces(min, max, true)
    }

    /// A box standing on something: [`Mesh::cuboid`] without the bottom face, which would be
    /// coplanar with the ground and fight it for depth (and resolve differently under the
    /// depth tests Less and LessEqual).
    pub fn block(min: Vec3, max: Vec3) -> Mesh {
        Self::box_faces(min, max, false)
    }

    fn box_faces(min: Vec3, max: Vec3, bottom: bool) -> Mesh {
        let mut m = Mesh::default();
        let d = max - min;
        let (x, y, z) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
        m.quad(min, y, x, Vec2::new(d.y, d.x)); // -z
        m.quad(min + z, x, y, Vec2::new(d.x, d.y)); // +z
        m.quad(min, z, y, Vec2::new(d.z, d.y)); // -x
        m.quad(min + x, y, z, Vec2::new(d.y, d.z)); // +x
        if bottom {
            m.quad(min, x, z, Vec2::new(d.x, d.z)); // -y
        }
        m.quad(min + y, z, x, Vec2::new(d.z, d.x)); // +y
        m
    }

    /// A horizontal quad at height `y`, facing up.
    pub fn ground(min_x: f32, min_z: f32, max_x: f32, max_z: f32, y: f32) -> Mesh {
        let mut m = Mesh::default();
        let (w, d) = (max_x - min_x, max_z - min_z);
        m.quad(
            Vec3::new(min_x, y, min_z),
            Vec3::Z * d,
            Vec3::X * w,
            Vec2::new(d, w),
        );
        m
    }

    /// A UV sphere of radius `r` at the origin.
    pub fn sphere(r: f32, rings: u32, segments: u32) -> Mesh {
        let mut m = Mesh::default();
        for i in 0..=rings {
            let v = i as f32 / rings as f32;
            let theta = v * std::f32::consts::PI;
            for j in 0..=segments {
                let u = j as f32 / segments as f32;
                let phi = u * std::f32::consts::TAU;
                let n = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                m.positions.push(n * r);
                m.normals.push(n);
                m.uvs.push(Vec2::new(u, v));
            }
        }
        let row = segments + 1;
        for i in 0..rings {
            for j in 0..segments {
                let a = i * row + j;
                let b = a + row;
                m.indices.extend_from_slice(&[a, a + 1, b, a + 1, b + 1, b]);
            }
        }
        m
    }

    /// A vertical cylinder of radius `r` from y=0 to y=`h`, with caps.
    pub fn cylinder(r: f32, h: f32, segments: u32) -> Mesh {
        let mut m = Mesh::default();
        for j in 0..=segments {
            let u = j as f32 / segments as f32;
            let phi = u * std::f32::consts::TAU;
            let n = Vec3::new(phi.cos(), 0.0, phi.sin());
            for y in [0.0, h] {
                m.positions.push(n * r + Vec3::Y * y);
                m.normals.push(n);
                m.uvs.push(Vec2::new(u, y / h));
            }
        }
        for j in 0..segments {
            let a = j * 2;
            m.indices
                .extend_from_slice(&[a, a + 1, a + 2, a + 1, a + 3, a + 2]);
        }
        for (y, n) in [(0.0, -Vec3::Y), (h, Vec3::Y)] {
            let center = m.positions.len() as u32;
            m.positions.push(Vec3::Y * y);
            m.normals.push(n);
            m.uvs.push(Vec2::splat(0.5));
            for j in 0..=segments {
                let phi = j as f32 / segments as f32 * std::f32::consts::TAU;
                m.positions.push(Vec3::new(phi.cos() * r, y, phi.sin() * r));
                m.normals.push(n);
                m.uvs.push(Vec2::new(phi.cos(), phi.sin()) * 0.5 + 0.5);
            }
            for j in 0..segments {
                let (a, b) = (center + 1 + j, center + 2 + j);
                if n.y > 0.0 {
                    m.indices.extend_from_slice(&[center, b, a]);
                } else {
                    m.indices.extend_from_slice(&[center, a, b]);
                }
            }
        }
        m
    }
}
