//! Test (b) of the spot-light culling, measured and not shipped: the post's ray through each
//! tile's centre against a cone thickened on the CPU (tiled-deferred-tricks, Trick 2, with its
//! constants: the apex moved back and the cone lengthened and widened by
//! `0.2 * sqrt(|light centre - eye| + max scale / 2)`). It misses tiles a spot lights
//! (`tests/culling.rs` measures how often), so `--spot-cull cone` ships instead; the benchmark
//! counts what it would cost and miss over an animation ([`ray_test_count`]).

use crate::culling::bounds::cell_bounds::cell_bounds_cpu;
use crate::culling::grid::GridDims;
use crate::culling::oracle::oracle_tile_lights;
use crate::culling::strategies::assign_cpu::{assign_cpu, DepthRange};
use crate::error::Result;
use crate::scene::Light;
use crate::scene::ViewSetup;
use glam::Vec3;

/// What test (b) would have listed for one frame's depth-bounded tile grid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct RayTestCount {
    /// Samples × lights listed: spots the ray test accepts, point lights as `assign_cpu` lists
    /// them.
    pub lighting_computations: u64,
    /// (tile, spot) pairs where the spot reaches a sample of the tile (the oracle).
    pub lit_pairs: u64,
    /// Of those, the ones the ray test rejected: light it would have lost.
    pub missed_pairs: u64,
}

/// Does the segment `o + t d`, t in [t0, t1], meet the solid finite cone (apex `a`, unit axis
/// `axis`, length `len`, base radius `base`)? The cone is convex: an end inside, or a crossing
/// of the lateral surface or of the base disc.
fn segment_meets_cone(
    o: Vec3,
    d: Vec3,
    t: (f32, f32),
    a: Vec3,
    axis: Vec3,
    len: f32,
    base: f32,
) -> bool {
    let k = base / len;
    let inside = |p: Vec3| {
        let h = (p - a).dot(axis);
        let perp = ((p - a).length_squared() - h * h).max(0.0).sqrt();
        (0.0..=len).contains(&h) && perp <= k * h
    };
    if inside(o + d * t.0) || inside(o + d * t.1) {
        return true;
    }
    let v0 = o - a;
    let (h0, hd) = (v0.dot(axis), d.dot(axis));
    // |v|² - (1 + k²) h² = 0 along the segment.
    let qa = d.length_squared() - (1.0 + k * k) * hd * hd;
    let qb = 2.0 * (v0.dot(d) - (1.0 + k * k) * h0 * hd);
    let qc = v0.length_squared() - (1.0 + k * k) * h0 * h0;
    let mut roots = Vec::new();
    if qa.abs() < 1e-12 {
        if qb.abs() > 1e-12 {
            roots.push(-qc / qb);
        }
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            roots.push((-qb - disc.sqrt()) / (2.0 * qa));
            roots.push((-qb + disc.sqrt()) / (2.0 * qa));
        }
    }
    let lateral = roots
        .iter()
        .any(|&r| (t.0..=t.1).contains(&r) && (0.0..=len).contains(&(h0 + r * hd)));
    let cap = hd.abs() > 1e-12 && {
        let r = (len - h0) / hd;
        let p = v0 + d * r;
        (t.0..=t.1).contains(&r) && (p.length_squared() - len * len).max(0.0).sqrt() <= base
    };
    lateral || cap
}

/// A spot's cone thickened as the post does (view space): apex, unit axis, length, base
/// radius.
struct ThickCone {
    apex: Vec3,
    axis: Vec3,
    len: f32,
    base: f32,
}

impl ThickCone {
    /// The post's cone for a spot narrower than a half-space; None for other lights (they
    /// are culled as `assign_cpu` culls them).
    fn of(setup: &ViewSetup, light: &Light) -> Option<ThickCone> {
        let spot = light.spot.filter(|s| s.cos_outer > 0.02)?;
        let v = setup.to_view(light);
        let axis = setup.view.transform_vector3(spot.direction);
        let half = spot.cos_outer.clamp(-1.0, 1.0).acos();
        let base = light.range * half.sin();
        let max_scale = (base * std::f32::consts::PI).max(light.range);
        let centre = v.apex + axis * (light.range * 0.5);
        let off = 0.2 * (centre.length() + max_scale * 0.5).sqrt();
        Some(ThickCone {
            apex: v.apex - axis * off,
            axis,
            len: light.range + 2.0 * off,
            base: base * std::f32::consts::PI + off,
        })
    }

    /// Does the ray `d` from the eye, over view distances `w`, meet it?
    fn hit_by(&self, d: Vec3, w: (f32, f32)) -> bool {
        segment_meets_cone(Vec3::ZERO, d, w, self.apex, self.axis, self.len, self.base)
    }
}

/// Test (b) on one frame: a depth-bounded tile grid (`tile_size`) from `depth` ([0, 1],
/// 1 = no geometry), spots narrower than a half-space kept by the ray test, everything else
/// as `assign_cpu` keeps it; what that lists and what it misses against the oracle.
pub fn ray_test_count(
    setup: &ViewSetup,
    tile_size: u32,
    lights: &[Light],
    depth: &[f32],
) -> Result<RayTestCount> {
    let dims = GridDims::new(setup.width, setup.height, tile_size)?;
    let view_distance = setup.view_distances(depth);
    let bounds = cell_bounds_cpu(setup, &dims, depth);
    let oracle = oracle_tile_lights(setup, &dims, lights, &view_distance);
    let grid = assign_cpu(setup, &dims, lights, DepthRange::Cells(&bounds));
    let cones: Vec<Option<ThickCone>> = lights.iter().map(|l| ThickCone::of(setup, l)).collect();
    let mut count = RayTestCount::default();
    for t in 0..dims.tile_count() {
        let [w0, w1] = bounds[t];
        if w0 > w1 {
            continue;
        }
        let (x0, y0, x1, y1) = dims.tile_rect(t);
        let samples = (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .filter(|&(x, y)| view_distance[(y * setup.width + x) as usize].is_finite())
            .count() as u64;
        let cx = (x0 + x1) as f32 * 0.5 / setup.width as f32 * 2.0 - 1.0;
        let cy = 1.0 - (y0 + y1) as f32 * 0.5 / setup.height as f32 * 2.0;
        let ray = Vec3::new(
            (cx + setup.p20) / setup.p00,
            (cy + setup.p21) / setup.p11,
            -1.0,
        );
        // Lights without a thickened cone: as the CPU grid lists them.
        let others = grid
            .cell(t)
            .iter()
            .filter(|&&l| cones[l as usize].is_none());
        let mut kept = others.count() as u64;
        let lit = &oracle[t];
        for (l, cone) in cones.iter().enumerate() {
            let Some(cone) = cone else { continue };
            let hit = cone.hit_by(ray, (w0, w1));
            kept += u64::from(hit);
            if lit.contains(&(l as u32)) {
                count.lit_pairs += 1;
                count.missed_pairs += u64::from(!hit);
            }
        }
        count.lighting_computations += samples * kept;
    }
    Ok(count)
}
