//! Shadow maps (`--shadows maps`), in the two ways tiled-shading §5 contrasts (Table 1, row
//! "Re-use shadow maps": deferred yes, tiled deferred and tiled forward no, "because all lights
//! are in flight simultaneously"):
//!
//! - **All in flight** (forward, the tiled and clustered pipelines, and every pipeline's
//!   transparent pass): every shadowed light's faces are rendered into one **atlas** before
//!   shading. A point light has a cube (six 90° faces), a spot whose half-angle is at most 60°
//!   one face around its axis, a wider spot a cube; each face is a square tile.
//! - **Re-used** (the classic deferred family: `deferred`, `deferred_stencil`, `deferred_mono`,
//!   `light_prepass`, `light_prepass_mono`, which shade one light volume at a time): one cube's
//!   six tiles, rendered again just before each shadowed light's volume.
//!
//! **The tile rule**: the budget `--shadow-atlas MiB` is a square of 4-byte texels, its side
//! the largest power of two that fits (capped by the device). With T faces this frame, the
//! tiles are laid in rows of ⌈√T⌉, and a tile's side is the largest power of two that fits
//! `side / ⌈√T⌉`, at most `--shadow-map-size` (and `MAX_TILE`): more shadowed lights,
//! smaller maps. The atlas texture is as large as its rows of tiles need (so at one map size
//! its memory grows with the shadowed lights, up to the budget); the re-used maps are six
//! tiles of the same size, so both forms shade the same image. A frame whose faces would need
//! tiles under `MIN_TILE` texels is refused with the numbers.
//!
//! Depth is reversed (near / w, an infinite far plane), cleared to 0. The light function
//! (`shading/shadows.wgsl`, `shadow_map_visibility`) picks the face by the major axis, moves
//! the sample along its normal by a **slope-scaled normal offset** (one texel's world size at
//! its distance × (`SHADOW_NORMAL_OFFSET` + `SHADOW_SLOPE_OFFSET` × tan θ, θ the angle
//! between normal and light, tan θ capped at `SHADOW_MAX_SLOPE`)), and filters with the comparison sampler's
//! bilinear 2×2 PCF, the footprint clamped a texel inside the tile.

use crate::scene::Light;
use glam::{Mat4, Vec3};

/// Smallest and largest tile side in texels.
pub(crate) const MIN_TILE: u32 = 16;
pub(crate) const MAX_TILE: u32 = 1024;
/// The near plane of a face, as a fraction of the light's range: geometry nearer the light
/// than this casts no shadow.
pub(crate) const NEAR_FRACTION: f32 = 1e-4;
/// A spot of half-angle up to this many degrees gets one face; a wider one a cube.
pub(crate) const SPOT_ONE_FACE_DEGREES: f32 = 60.0;
/// The atlas pass's label in a frame's pass timings (the bench's summary reads it).
pub const PASS_LABEL: &str = "shadow maps";
/// Largest `--shadow-atlas` in MiB.
pub(crate) const MAX_ATLAS_MIB: u32 = 4096;

/// The atlas side for a budget of `mib` MiB: the largest power of two whose square of 4-byte
/// texels fits, at most `max_dimension`.
pub(crate) fn atlas_side(mib: u32, max_dimension: u32) -> u32 {
    let texels = (u64::from(mib) << 20) / 4;
    let mut side = 1u32;
    while u64::from(side * 2) * u64::from(side * 2) <= texels && side * 2 <= max_dimension {
        side *= 2;
    }
    side
}

/// Where a frame's faces lie in the shadow texture, and how large it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct AtlasLayout {
    /// The texture's size in texels: all in flight, ⌈√T⌉ tiles a row and as many rows as
    /// the faces fill; re-used, one cube's six tiles (3 x 2).
    pub width: u32,
    pub height: u32,
    pub tile: u32,
    pub per_row: u32,
    /// Faces this frame (all in flight), or 6 (re-used).
    pub tiles: u32,
}

impl AtlasLayout {
    /// All in flight: the layout for `tiles` faces in a budget of `side`² texels with tiles
    /// of at most `max_tile` (module docs: the tile rule).
    pub fn new(side: u32, max_tile: u32, tiles: u32) -> Result<AtlasLayout, String> {
        let per_row = (f64::from(tiles.max(1))).sqrt().ceil() as u32;
        let fit = (side / per_row).min(max_tile.min(MAX_TILE));
        if fit < MIN_TILE {
            let most = (side / MIN_TILE).pow(2);
            let mib = Self::bytes_of(side, side) >> 20;
            return Err(format!(
                "the shadow atlas ({side}x{side} texels, {mib} MiB) holds at most {most} shadow-map faces of {MIN_TILE}x{MIN_TILE}; this frame's shadowed lights need {tiles} (a point light 6, a spot 1): raise --shadow-atlas or lower --shadow-lights"
            ));
        }
        let mut tile = MIN_TILE;
        while tile * 2 <= fit {
            tile *= 2;
        }
        let rows = tiles.max(1).div_ceil(per_row);
        Ok(AtlasLayout {
            width: per_row * tile,
            height: rows * tile,
            tile,
            per_row,
            tiles,
        })
    }

    /// Re-used (the classic deferred family): one light's six faces at this layout's tile
    /// size, rendered again before each shadowed light is shaded.
    pub fn reused(&self) -> AtlasLayout {
        AtlasLayout {
            width: 3 * self.tile,
            height: 2 * self.tile,
            tile: self.tile,
            per_row: 3,
            tiles: 6,
        }
    }

    /// Tile `t`'s top-left texel.
    pub fn origin(&self, t: u32) -> (u32, u32) {
        (
            (t % self.per_row) * self.tile,
            (t / self.per_row) * self.tile,
        )
    }

    /// Bytes of the texture.
    #[cfg(test)]
    pub fn bytes(&self) -> u64 {
        Self::bytes_of(self.width, self.height)
    }

    fn bytes_of(w: u32, h: u32) -> u64 {
        u64::from(w) * u64::from(h) * 4
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
pub(crate) fn face_matrices(light: &Light) -> Vec<Mat4> {
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
#[cfg(test)]
pub(crate) fn cube_face(v: Vec3) -> u32 {
    let a = v.abs();
    if a.x >= a.y && a.x >= a.z {
        u32::from(v.x <= 0.0)
    } else if a.y >= a.z {
        2 + u32::from(v.y <= 0.0)
    } else {
        4 + u32::from(v.z <= 0.0)
    }
}

/// One frame's maps: each shadowed light's first face, every face's matrix, and where the
/// faces lie (all in flight, or one light's at a time: `reused`).
#[derive(Clone, Debug)]
pub(crate) struct MapFrame {
    /// The atlas of every face (the grid pipelines', and the transparent pass's).
    pub atlas: AtlasLayout,
    /// The layout the shaders read: the atlas, or its [`AtlasLayout::reused`] six tiles.
    pub layout: AtlasLayout,
    pub reused: bool,
    /// Per light: 0 for none, else (first face × 2 + cube) + 1 (`shadows.wgsl`).
    pub slots: Vec<u32>,
    pub matrices: Vec<Mat4>,
}

impl MapFrame {
    /// `lights` camera-relative; `casters` from [`super::casters`]; an atlas budget of
    /// `side`² texels and tiles of at most `max_tile`.
    pub fn new(
        lights: &[Light],
        casters: &[bool],
        side: u32,
        max_tile: u32,
        reused: bool,
    ) -> Result<MapFrame, String> {
        let mut slots = vec![0; lights.len()];
        let mut matrices = Vec::new();
        for (i, l) in lights.iter().enumerate().filter(|&(i, _)| casters[i]) {
            let first = matrices.len() as u32;
            let m = face_matrices(l);
            slots[i] = first * 2 + u32::from(m.len() == 6) + 1;
            matrices.extend(m);
        }
        let atlas = AtlasLayout::new(side, max_tile, matrices.len() as u32)?;
        Ok(MapFrame {
            atlas,
            layout: if reused { atlas.reused() } else { atlas },
            reused,
            slots,
            matrices,
        })
    }

    /// Light `i`'s faces (first face, count), if it casts.
    pub fn faces_of(&self, i: usize) -> Option<(u32, u32)> {
        let s = *self.slots.get(i)?;
        (s != 0).then(|| ((s - 1) >> 1, if (s - 1) & 1 == 1 { 6 } else { 1 }))
    }

    /// The texture both forms fit in: the re-used tiles, and the atlas too when `atlas_too`
    /// (a re-using pipeline's frame with transparent objects, whose forward-shaded pass needs
    /// every map in flight).
    pub fn texture_size(&self, atlas_too: bool) -> (u32, u32) {
        let l = &self.layout;
        if atlas_too || !self.reused {
            (
                l.width.max(self.atlas.width),
                l.height.max(self.atlas.height),
            )
        } else {
            (l.width, l.height)
        }
    }

    /// The shadow buffer for `--shadows maps` (`shadows.wgsl`) and a texture of `size`: the
    /// header `[bits(width), bits(tile), bits(atlas's tiles per row), bits(slots' first
    /// vec4)]`, `[bits(matrices' first vec4), bits(height), 0, 0]`, the slots (4 per vec4),
    /// then 4 vec4s (the columns) per face. Which tile a face lies in (its own in the atlas, or
    /// its cube face's when re-used: 3 a row) is the shader's constant (`SHADOWS_MAPS` or
    /// `SHADOWS_MAPS_REUSED`).
    pub fn gpu_data(&self, (width, height): (u32, u32)) -> Vec<[f32; 4]> {
        let slots_at = super::HEADER_VEC4S;
        let matrices_at = slots_at + self.slots.len().div_ceil(4) as u32;
        let bits = |v: u32| f32::from_bits(v);
        let mut out = vec![
            [
                bits(width),
                bits(self.atlas.tile),
                bits(self.atlas.per_row),
                bits(slots_at),
            ],
            [bits(matrices_at), bits(height), 0.0, 0.0],
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
        let one = AtlasLayout::new(side, MAX_TILE, 6).unwrap();
        assert_eq!(
            (one.tile, one.width, one.height),
            (MAX_TILE, 3 * MAX_TILE, 2 * MAX_TILE)
        );
        assert_eq!(one.reused(), one);
        let many = AtlasLayout::new(side, MAX_TILE, 6 * 924).unwrap();
        assert_eq!(many.tile, 32);
        assert!(many.per_row * (many.height / many.tile) >= many.tiles);
        assert!(many.width <= side && many.height <= side);
        // A cap on the tile keeps the resolution and grows the texture with the faces.
        let capped = AtlasLayout::new(atlas_side(1024, 16384), 64, 6 * 924).unwrap();
        assert_eq!(capped.tile, 64);
        assert!(capped.bytes() > 64 * capped.reused().bytes());
        let e = AtlasLayout::new(atlas_side(1, 16384), MAX_TILE, 6 * 1000).unwrap_err();
        assert!(e.contains("raise --shadow-atlas"), "{e}");
        assert_eq!(atlas_side(1, 16384), 512);
        assert_eq!(atlas_side(4096, 8192), 8192);
    }

    #[test]
    fn tiles_never_overlap_and_stay_in_the_atlas() {
        for tiles in [1, 5, 6, 7, 100, 5544] {
            let l = AtlasLayout::new(4096, MAX_TILE, tiles).unwrap();
            let mut seen = std::collections::HashSet::new();
            for t in 0..tiles {
                let (x, y) = l.origin(t);
                assert!(
                    x + l.tile <= l.width && y + l.tile <= l.height,
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
        let f = MapFrame::new(&lights, &[true, false, true], 1024, MAX_TILE, false).unwrap();
        assert_eq!(f.slots, vec![1 + 1, 0, 6 * 2 + 1]);
        assert_eq!(f.faces_of(0), Some((0, 6)));
        assert_eq!(f.faces_of(1), None);
        assert_eq!(f.faces_of(2), Some((6, 1)));
        assert_eq!(f.matrices.len(), 7);
        let data = f.gpu_data(f.texture_size(false));
        assert_eq!(data.len(), 2 + 1 + 7 * 4);
        assert_eq!(data[0][3].to_bits(), 2);
        assert_eq!(data[1][0].to_bits(), 3);
        assert_eq!(data[2][2].to_bits(), 13);
        let r = MapFrame::new(&lights, &[true, false, true], 1024, MAX_TILE, true).unwrap();
        assert_eq!(r.layout, r.atlas.reused());
        assert_eq!(r.layout.tiles, 6);
    }
}
