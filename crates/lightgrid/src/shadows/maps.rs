//! Shadow maps (`--shadows maps`): every shadowed light's maps in flight at once, in one
//! **atlas** (tiled-shading §5, Table 1's "Re-use shadow maps" row: the tiled and clustered
//! pipelines shade all lights in one pass, so every shadowed light's map must exist before it).
//!
//! A point light has a cube (six 90° faces), a spot whose half-angle is at most 60° one face
//! around its axis, a wider spot a cube. Every face is a square tile of the atlas, a
//! `Depth32Float` texture whose size is the budget (`--shadow-atlas MiB`: the largest power of
//! two side whose texels fit it, capped by the device). **The tile rule**: with T faces this
//! frame, the tiles are laid in rows of ⌈√T⌉, and a tile's side is the largest power of two
//! that fits `side / ⌈√T⌉`, at most [`MAX_TILE`]: more shadowed lights, smaller maps. A frame
//! whose faces would need tiles under [`MIN_TILE`] texels is refused with the numbers.
//!
//! Depth is reversed (near / w, an infinite far plane), cleared to 0. The light function
//! (`shading/shadows.wgsl`, `shadow_map_visibility`) picks the face by the major axis, moves
//! the sample along its normal by a **slope-scaled normal offset** (one texel's world size at
//! its distance × ([`NORMAL_OFFSET`] + [`SLOPE_OFFSET`] × tan θ, θ the angle between normal
//! and light, tan θ capped at [`MAX_SLOPE`])), and filters with the comparison sampler's
//! bilinear 2×2 PCF, the footprint clamped a texel inside the tile.

use crate::scene::Light;
use glam::{Mat4, Vec3};

/// Smallest and largest tile side in texels.
pub const MIN_TILE: u32 = 16;
pub const MAX_TILE: u32 = 1024;
/// The near plane of a face, as a fraction of the light's range: geometry nearer the light
/// than this casts no shadow.
pub const NEAR_FRACTION: f32 = 1e-4;
/// A spot of half-angle up to this many degrees gets one face; a wider one a cube.
pub const SPOT_ONE_FACE_DEGREES: f32 = 60.0;
/// The slope-scaled normal offset, in texels (module docs).
pub const NORMAL_OFFSET: f32 = 1.0;
pub const SLOPE_OFFSET: f32 = 1.0;
pub const MAX_SLOPE: f32 = 4.0;
/// Largest `--shadow-atlas` in MiB.
pub const MAX_ATLAS_MIB: u32 = 4096;

/// The atlas side for a budget of `mib` MiB: the largest power of two whose square of 4-byte
/// texels fits, at most `max_dimension`.
pub fn atlas_side(mib: u32, max_dimension: u32) -> u32 {
    let texels = (u64::from(mib) << 20) / 4;
    let mut side = 1u32;
    while u64::from(side * 2) * u64::from(side * 2) <= texels && side * 2 <= max_dimension {
        side *= 2;
    }
    side
}

/// Where a frame's faces lie in the atlas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AtlasLayout {
    pub side: u32,
    pub tile: u32,
    pub per_row: u32,
    pub tiles: u32,
}

impl AtlasLayout {
    /// The layout for `tiles` faces in an atlas of `side` texels (module docs: the tile rule).
    pub fn new(side: u32, tiles: u32) -> Result<AtlasLayout, String> {
        let per_row = (f64::from(tiles.max(1))).sqrt().ceil() as u32;
        let fit = side / per_row;
        if fit < MIN_TILE {
            let most = (side / MIN_TILE).pow(2);
            let mib = (u64::from(side) * u64::from(side) * 4) >> 20;
            return Err(format!(
                "the shadow atlas ({side}x{side} texels, {mib} MiB) holds at most {most} shadow-map faces of {MIN_TILE}x{MIN_TILE}; this frame's shadowed lights need {tiles} (a point light 6, a spot 1): raise --shadow-atlas or lower --shadow-lights"
            ));
        }
        let mut tile = MIN_TILE;
        while tile * 2 <= fit && tile * 2 <= MAX_TILE {
            tile *= 2;
        }
        Ok(AtlasLayout {
            side,
            tile,
            per_row: side / tile,
            tiles,
        })
    }

    /// Tile `t`'s top-left texel.
    pub fn origin(&self, t: u32) -> (u32, u32) {
        (
            (t % self.per_row) * self.tile,
            (t / self.per_row) * self.tile,
        )
    }

    /// Bytes of the whole atlas.
    pub fn bytes(side: u32) -> u64 {
        u64::from(side) * u64::from(side) * 4
    }
}

/// The faces a light's map has: 1 for a narrow spot, 6 otherwise.
pub fn faces(light: &Light) -> u32 {
    match light.spot {
        Some(s) if s.cos_outer >= SPOT_ONE_FACE_DEGREES.to_radians().cos() => 1,
        _ => 6,
    }
}

/// The cube's faces: the axis each looks along and its up vector, in the order the shader
/// numbers them by major axis (+x, −x, +y, −y, +z, −z).
const CUBE: [(Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::NEG_Y),
    (Vec3::NEG_X, Vec3::NEG_Y),
    (Vec3::Y, Vec3::Z),
    (Vec3::NEG_Y, Vec3::NEG_Z),
    (Vec3::Z, Vec3::NEG_Y),
    (Vec3::NEG_Z, Vec3::NEG_Y),
];

/// A right-handed view from `eye` looking along `dir`.
fn look_to(eye: Vec3, dir: Vec3, up: Vec3) -> Mat4 {
    let f = dir.normalize();
    let s = f.cross(up).normalize();
    let u = s.cross(f);
    Mat4::from_cols(
        glam::Vec4::new(s.x, u.x, -f.x, 0.0),
        glam::Vec4::new(s.y, u.y, -f.y, 0.0),
        glam::Vec4::new(s.z, u.z, -f.z, 0.0),
        glam::Vec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
    )
}

/// A square reversed-Z perspective with an infinite far plane: depth = `near` / w.
fn reversed_infinite(fov: f32, near: f32) -> Mat4 {
    let h = 1.0 / (fov * 0.5).tan();
    Mat4::from_cols(
        glam::Vec4::new(h, 0.0, 0.0, 0.0),
        glam::Vec4::new(0.0, h, 0.0, 0.0),
        glam::Vec4::new(0.0, 0.0, 0.0, -1.0),
        glam::Vec4::new(0.0, 0.0, near, 0.0),
    )
}

/// The view-projection of each of the light's faces, for camera-relative positions (`light`
/// camera-relative): clip = M · p, depth near / w.
pub fn face_matrices(light: &Light) -> Vec<Mat4> {
    let near = light.range * NEAR_FRACTION;
    let eye = light.position;
    if faces(light) == 1 {
        let spot = light.spot.expect("one face: a spot");
        let d = spot.direction.normalize();
        let up = if d.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
        // The cone, widened by two texels' worth so the PCF footprint stays inside.
        let half = spot.cos_outer.clamp(-1.0, 1.0).acos() * 1.05;
        let proj = reversed_infinite(2.0 * half, near);
        return vec![proj * look_to(eye, d, up)];
    }
    let proj = reversed_infinite(std::f32::consts::FRAC_PI_2, near);
    CUBE.iter()
        .map(|&(dir, up)| proj * look_to(eye, dir, up))
        .collect()
}

/// The face of a cube a direction from the light falls on (the shader's rule).
pub fn cube_face(v: Vec3) -> u32 {
    let a = v.abs();
    if a.x >= a.y && a.x >= a.z {
        u32::from(v.x <= 0.0)
    } else if a.y >= a.z {
        2 + u32::from(v.y <= 0.0)
    } else {
        4 + u32::from(v.z <= 0.0)
    }
}

/// One frame's maps: which tile each shadowed light starts at, and every tile's matrix.
#[derive(Clone, Debug)]
pub struct MapFrame {
    pub layout: AtlasLayout,
    /// Per light: 0 for none, else (first tile × 2 + cube) + 1 (`shadows.wgsl`).
    pub slots: Vec<u32>,
    pub matrices: Vec<Mat4>,
}

impl MapFrame {
    /// `lights` camera-relative; `casters` from [`super::casters`].
    pub fn new(lights: &[Light], casters: &[bool], side: u32) -> Result<MapFrame, String> {
        let mut slots = vec![0; lights.len()];
        let mut matrices = Vec::new();
        for (i, l) in lights.iter().enumerate().filter(|&(i, _)| casters[i]) {
            let first = matrices.len() as u32;
            let m = face_matrices(l);
            slots[i] = first * 2 + u32::from(m.len() == 6) + 1;
            matrices.extend(m);
        }
        let layout = AtlasLayout::new(side, matrices.len() as u32)?;
        Ok(MapFrame {
            layout,
            slots,
            matrices,
        })
    }

    /// The shadow buffer for `--shadows maps` (`shadows.wgsl`): the header
    /// `[bits(side), bits(tile), bits(per row), bits(slots' first vec4)]`,
    /// `[bits(matrices' first vec4), 0, 0, 0]`, the slots (4 per vec4), then 4 vec4s (the
    /// columns) per tile.
    pub fn gpu_data(&self) -> Vec<[f32; 4]> {
        let slots_at = super::HEADER_VEC4S;
        let matrices_at = slots_at + self.slots.len().div_ceil(4) as u32;
        let bits = |v: u32| f32::from_bits(v);
        let mut out = vec![
            [
                bits(self.layout.side),
                bits(self.layout.tile),
                bits(self.layout.per_row),
                bits(slots_at),
            ],
            [bits(matrices_at), 0.0, 0.0, 0.0],
        ];
        for chunk in self.slots.chunks(4) {
            let mut v = [0u32; 4];
            v[..chunk.len()].copy_from_slice(chunk);
            out.push(v.map(bits));
        }
        for m in &self.matrices {
            out.extend(m.to_cols_array_2d());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Spot;

    #[test]
    fn more_faces_get_smaller_tiles_and_too_many_are_refused() {
        let side = atlas_side(64, 16384);
        assert_eq!(side, 4096);
        assert_eq!(AtlasLayout::new(side, 6).unwrap().tile, MAX_TILE);
        let many = AtlasLayout::new(side, 6 * 924).unwrap();
        assert_eq!(many.tile, 32);
        assert!(many.per_row * many.per_row >= many.tiles);
        let e = AtlasLayout::new(atlas_side(1, 16384), 6 * 1000).unwrap_err();
        assert!(e.contains("raise --shadow-atlas"), "{e}");
        assert_eq!(atlas_side(1, 16384), 512);
        assert_eq!(atlas_side(4096, 8192), 8192);
    }

    #[test]
    fn tiles_never_overlap_and_stay_in_the_atlas() {
        for tiles in [1, 5, 6, 7, 100, 5544] {
            let l = AtlasLayout::new(4096, tiles).unwrap();
            let mut seen = std::collections::HashSet::new();
            for t in 0..tiles {
                let (x, y) = l.origin(t);
                assert!(
                    x + l.tile <= l.side && y + l.tile <= l.side,
                    "{tiles}: tile {t}"
                );
                assert!(seen.insert((x, y)), "{tiles}: tile {t} overlaps");
            }
        }
    }

    #[test]
    fn each_face_sees_its_own_major_axis_in_front_of_the_light() {
        let light = Light::point(Vec3::new(1.0, 2.0, 3.0), Vec3::ONE, 1.0, 10.0);
        let m = face_matrices(&light);
        assert_eq!(m.len(), 6);
        for v in [
            Vec3::new(3.0, 0.5, -1.0),
            Vec3::new(-2.0, 1.0, 1.5),
            Vec3::new(0.2, 4.0, 1.0),
            Vec3::new(0.2, -4.0, 1.0),
            Vec3::new(1.0, 1.0, 2.0),
            Vec3::new(-1.0, 0.5, -3.0),
        ] {
            let f = cube_face(v) as usize;
            let c = m[f] * (light.position + v).extend(1.0);
            let ndc = c.truncate() / c.w;
            assert!(
                c.w > 0.0 && ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0,
                "{v}: {ndc}"
            );
            // Reversed depth: near / w, in (0, 1].
            assert!(ndc.z > 0.0 && ndc.z <= 1.0, "{v}: {ndc}");
        }
        let spot = Light {
            spot: Some(Spot::new(Vec3::NEG_Y, 0.3, 0.5)),
            ..light
        };
        assert_eq!(faces(&spot), 1);
        let wide = Light {
            spot: Some(Spot::new(Vec3::NEG_Y, 1.0, 1.2)),
            ..light
        };
        assert_eq!(faces(&wide), 6);
    }

    #[test]
    fn the_gpu_data_points_each_shadowed_light_at_its_tiles() {
        let lights = [
            Light::point(Vec3::ZERO, Vec3::ONE, 1.0, 5.0),
            Light::point(Vec3::ONE, Vec3::ONE, 1.0, 5.0),
            Light {
                spot: Some(Spot::new(Vec3::NEG_Y, 0.3, 0.5)),
                ..Light::point(Vec3::Y, Vec3::ONE, 1.0, 5.0)
            },
        ];
        let f = MapFrame::new(&lights, &[true, false, true], 1024).unwrap();
        assert_eq!(f.slots, vec![1 + 1, 0, 6 * 2 + 1]);
        assert_eq!(f.matrices.len(), 7);
        let data = f.gpu_data();
        assert_eq!(data.len(), 2 + 1 + 7 * 4);
        assert_eq!(data[0][3].to_bits(), 2);
        assert_eq!(data[1][0].to_bits(), 3);
        assert_eq!(data[2][2].to_bits(), 13);
    }
}
