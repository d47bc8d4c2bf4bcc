//! CPU rasterization of world-space triangles into the fragments a GPU would shade (pixel
//! centres inside the triangle, clipped at the near and far planes, in front of the opaque
//! view distance at the pixel). The analysis counts the ideal of the transparent objects'
//! fragments with it, and the tests hand its fragments to the oracle. Edges follow a top-left
//! rule, so a pixel centre on an edge shared by two triangles belongs to one of them; it may
//! differ from the GPU's choice only for centres exactly on an edge.

use super::ViewSetup;
use glam::{Vec2, Vec3};

/// A fragment: pixel (x, y) and its view distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fragment {
    /// Pixel column, from the left.
    pub x: u32,
    /// Pixel row, from the top.
    pub y: u32,
    /// View distance (view-space -z) of the fragment at the pixel centre, in scene units.
    pub w: f32,
}

/// The fragments of `triangles` (world space) in front of `opaque_w` (view distance per
/// pixel, row-major, infinite where there is no opaque sample).
pub fn rasterize(setup: &ViewSetup, triangles: &[[Vec3; 3]], opaque_w: &[f32]) -> Vec<Fragment> {
    let mut out = Vec::new();
    for t in triangles {
        let view = t.map(|p| setup.view_point(p));
        let clipped = clip_near(&view, setup.near);
        for i in 1..clipped.len().saturating_sub(1) {
            raster_triangle(
                setup,
                [clipped[0], clipped[i], clipped[i + 1]],
                opaque_w,
                &mut out,
            );
        }
    }
    out
}

/// The polygon of a view-space triangle in front of the near plane (view distance -z ≥ near).
fn clip_near(t: &[Vec3; 3], near: f32) -> Vec<Vec3> {
    let inside = |p: Vec3| -p.z >= near;
    let mut out = Vec::with_capacity(4);
    for i in 0..3 {
        let (a, b) = (t[i], t[(i + 1) % 3]);
        if inside(a) {
            out.push(a);
        }
        if inside(a) != inside(b) {
            let s = (-near - a.z) / (b.z - a.z);
            out.push(a + (b - a) * s);
        }
    }
    out
}

fn raster_triangle(setup: &ViewSetup, t: [Vec3; 3], opaque_w: &[f32], out: &mut Vec<Fragment>) {
    let (wf, hf) = (setup.width as f32, setup.height as f32);
    // Screen position (pixels, y down) and 1/w, which is affine in screen space.
    let screen = t.map(|p| {
        let w = -p.z;
        let ndc = Vec2::new(
            setup.p00 * p.x / w - setup.p20,
            setup.p11 * p.y / w - setup.p21,
        );
        (
            Vec2::new((ndc.x * 0.5 + 0.5) * wf, (0.5 - ndc.y * 0.5) * hf),
            1.0 / w,
        )
    });
    let [(a, ia), (b, ib), (c, ic)] = screen;
    let area = (b - a).perp_dot(c - a);
    if area.abs() < 1e-12 || !area.is_finite() {
        return;
    }
    // Orient counter-clockwise in this y-down frame so inside means all edge functions ≥ 0.
    let (b, ib, c, ic) = if area < 0.0 {
        (c, ic, b, ib)
    } else {
        (b, ib, c, ic)
    };
    let area = area.abs();
    let lo = a.min(b).min(c).max(Vec2::ZERO);
    let hi = a.max(b).max(c).min(Vec2::new(wf, hf));
    if lo.x >= hi.x || lo.y >= hi.y {
        return;
    }
    // Top-left rule: a centre exactly on an edge counts for one of the edge's two triangles.
    let owns = |e: Vec2| e.y < 0.0 || (e.y == 0.0 && e.x > 0.0);
    let edges = [(b, c), (c, a), (a, b)];
    // Pixels whose centre x + 0.5 lies in [lo, hi].
    let centres = |lo: f32, hi: f32, n: u32| {
        let first = (lo - 0.5).ceil().max(0.0) as u32;
        let end = ((hi - 0.5).floor() + 1.0).clamp(0.0, n as f32) as u32;
        first..end.max(first)
    };
    for y in centres(lo.y, hi.y, setup.height) {
        for x in centres(lo.x, hi.x, setup.width) {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let mut weights = [0.0f32; 3];
            let mut inside = true;
            for (k, (e0, e1)) in edges.iter().enumerate() {
                let e = *e1 - *e0;
                let f = e.perp_dot(p - *e0);
                if f < 0.0 || (f == 0.0 && !owns(e)) {
                    inside = false;
                    break;
                }
                weights[k] = f / area;
            }
            if !inside {
                continue;
            }
            let inv_w = weights[0] * ia + weights[1] * ib + weights[2] * ic;
            let w = 1.0 / inv_w;
            let opaque = opaque_w[(y * setup.width + x) as usize];
            if w >= setup.near && w <= setup.far && w < opaque {
                out.push(Fragment { x, y, w });
            }
        }
    }
}
