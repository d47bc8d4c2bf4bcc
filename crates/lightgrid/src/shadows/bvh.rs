//! A bounding-volume hierarchy over triangles for shadow rays (Forward+ §6's "local short ray
//! casting to the lights"): built on the CPU, flattened into the layout `shading/shadows.wgsl`
//! walks, and walked on the CPU by the same rules (`TriangleBvh::occluded`).
//!
//! The build splits each node's triangles at the median centroid along the longest axis of
//! their centroids' box, down to `LEAF_TRIANGLES`: a balanced tree, so its depth is
//! ⌈log2(n / 4)⌉ + 1 and the shaders' fixed stack (`SHADOW_STACK_DEPTH`) holds any scene a
//! buffer can (2^31 triangles need 30 levels). A median split costs O(n log n) and keeps the
//! per-frame rebuild of the moving objects cheap; the surface-area heuristic would trace
//! faster and build slower (not measured here).
//!
//! `SHADOW_STACK_DEPTH`: crate::consts::SHADOW_STACK_DEPTH

use glam::Vec3;

/// Most triangles in a leaf.
pub(crate) const LEAF_TRIANGLES: usize = crate::consts::SHADOW_LEAF_TRIANGLES as usize;

/// A triangle's three corners.
pub type Triangle = [Vec3; 3];

/// One node: its box, and either two children (`count` 0: the left child follows the node,
/// `next` is the right child) or `count` triangles from `next`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Node {
    pub min: Vec3,
    pub max: Vec3,
    pub next: u32,
    pub count: u32,
}

/// The hierarchy: nodes depth first (the root at 0), triangles in leaf order.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct TriangleBvh {
    pub nodes: Vec<Node>,
    pub triangles: Vec<Triangle>,
}

/// Vec4s per node and per triangle in the GPU layout.
pub(crate) const NODE_VEC4S: u32 = 2;
pub(crate) const TRIANGLE_VEC4S: u32 = 3;

impl TriangleBvh {
    pub fn build(mut triangles: Vec<Triangle>) -> TriangleBvh {
        let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF_TRIANGLES + 1);
        if !triangles.is_empty() {
            let mut centroids: Vec<(Vec3, u32)> = triangles
                .iter()
                .enumerate()
                .map(|(i, t)| ((t[0] + t[1] + t[2]) / 3.0, i as u32))
                .collect();
            let n = centroids.len();
            build_node(&triangles, &mut centroids, 0, n, &mut nodes);
            let order: Vec<Triangle> = centroids
                .iter()
                .map(|&(_, i)| triangles[i as usize])
                .collect();
            triangles = order;
        }
        TriangleBvh { nodes, triangles }
    }

    /// Deepest level (the root is 1; 0 when empty).
    pub fn depth(&self) -> u32 {
        fn walk(nodes: &[Node], i: usize) -> u32 {
            let n = nodes[i];
            if n.count > 0 {
                1
            } else {
                1 + walk(nodes, i + 1).max(walk(nodes, n.next as usize))
            }
        }
        if self.nodes.is_empty() {
            0
        } else {
            walk(&self.nodes, 0)
        }
    }

    /// GPU size in vec4s.
    pub fn vec4s(&self) -> u32 {
        self.nodes.len() as u32 * NODE_VEC4S + self.triangles.len() as u32 * TRIANGLE_VEC4S
    }

    /// Append the GPU layout (`shadows.wgsl`) with the first node at vec4 `base` of the
    /// buffer: per node `[min, bits(right child's vec4 index or first triangle's)]`,
    /// `[max, bits(triangle count, 0 for two children)]`; per triangle `[v0]`, `[v1 − v0]`,
    /// `[v2 − v0]` (the edges Möller–Trumbore reads).
    pub fn write_gpu(&self, base: u32, out: &mut Vec<[f32; 4]>) {
        let tri_base = base + self.nodes.len() as u32 * NODE_VEC4S;
        for n in &self.nodes {
            let next = if n.count > 0 {
                tri_base + n.next * TRIANGLE_VEC4S
            } else {
                base + n.next * NODE_VEC4S
            };
            out.push([n.min.x, n.min.y, n.min.z, f32::from_bits(next)]);
            out.push([n.max.x, n.max.y, n.max.z, f32::from_bits(n.count)]);
        }
        for t in &self.triangles {
            let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
            out.push([t[0].x, t[0].y, t[0].z, 0.0]);
            out.push([e1.x, e1.y, e1.z, 0.0]);
            out.push([e2.x, e2.y, e2.z, 0.0]);
        }
    }

    /// Does a triangle cross the segment `origin + t·dir`, 0 < t < `t_max`? As the shader walks
    /// it: boxes by slabs, triangles by Möller–Trumbore, either side of a triangle.
    #[cfg(test)]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let inv = dir.recip();
        let mut stack = Vec::with_capacity(32);
        stack.push(0usize);
        while let Some(i) = stack.pop() {
            let n = self.nodes[i];
            if !box_hit(n.min, n.max, origin, inv, t_max) {
                continue;
            }
            if n.count == 0 {
                stack.push(n.next as usize);
                stack.push(i + 1);
                continue;
            }
            let first = n.next as usize;
            for t in &self.triangles[first..first + n.count as usize] {
                if triangle_hit(t[0], t[1] - t[0], t[2] - t[0], origin, dir, t_max) {
                    return true;
                }
            }
        }
        false
    }
}

/// Build the node for `centroids[lo..hi]`, reordering them; returns its index.
fn build_node(
    triangles: &[Triangle],
    centroids: &mut [(Vec3, u32)],
    lo: usize,
    hi: usize,
    nodes: &mut Vec<Node>,
) -> usize {
    let (mut min, mut max) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let (mut cmin, mut cmax) = (min, max);
    for &(c, i) in &centroids[lo..hi] {
        for v in triangles[i as usize] {
            min = min.min(v);
            max = max.max(v);
        }
        cmin = cmin.min(c);
        cmax = cmax.max(c);
    }
    let index = nodes.len();
    nodes.push(Node {
        min,
        max,
        next: lo as u32,
        count: (hi - lo) as u32,
    });
    if hi - lo <= LEAF_TRIANGLES {
        return index;
    }
    let extent = cmax - cmin;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = (lo + hi) / 2;
    centroids[lo..hi].select_nth_unstable_by(mid - lo, |a, b| {
        a.0[axis].total_cmp(&b.0[axis]).then(a.1.cmp(&b.1))
    });
    build_node(triangles, centroids, lo, mid, nodes);
    let right = build_node(triangles, centroids, mid, hi, nodes);
    nodes[index].next = right as u32;
    nodes[index].count = 0;
    index
}

/// Does the segment `origin + t·dir`, 0 ≤ t ≤ `t_max`, meet the box? (`inv` = 1 / dir; the
/// IEEE infinities of an axis-parallel ray do the right thing.)
#[cfg(test)]
pub(crate) fn box_hit(min: Vec3, max: Vec3, origin: Vec3, inv: Vec3, t_max: f32) -> bool {
    let t0 = (min - origin) * inv;
    let t1 = (max - origin) * inv;
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element().min(t_max);
    near <= far
}

/// Möller–Trumbore: does the segment cross the triangle `v0, v0 + e1, v0 + e2` at
/// 0 < t < `t_max`?
#[cfg(test)]
pub(crate) fn triangle_hit(
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
    origin: Vec3,
    dir: Vec3,
    t_max: f32,
) -> bool {
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return false;
    }
    let inv = 1.0 / det;
    let s = origin - v0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let t = e2.dot(q) * inv;
    t > 0.0 && t < t_max
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(z: f32, half: f32) -> Vec<Triangle> {
        let a = Vec3::new(-half, -half, z);
        let b = Vec3::new(half, -half, z);
        let c = Vec3::new(half, half, z);
        let d = Vec3::new(-half, half, z);
        vec![[a, b, c], [a, c, d]]
    }

    fn grid(n: usize) -> Vec<Triangle> {
        let mut out = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let o = Vec3::new(i as f32, j as f32, (i * 7 + j * 3) as f32 % 5.0);
                out.push([o, o + Vec3::X * 0.9, o + Vec3::Y * 0.9]);
            }
        }
        out
    }

    fn brute(tris: &[Triangle], o: Vec3, d: Vec3, t_max: f32) -> bool {
        tris.iter()
            .any(|t| triangle_hit(t[0], t[1] - t[0], t[2] - t[0], o, d, t_max))
    }

    #[test]
    fn a_segment_through_a_quad_is_blocked_and_one_stopping_short_is_not() {
        let bvh = TriangleBvh::build(quad(1.0, 1.0));
        let o = Vec3::new(0.2, 0.3, 0.0);
        assert!(bvh.occluded(o, Vec3::Z * 2.0, 1.0));
        // The segment ends at z = 0.9, before the quad.
        assert!(!bvh.occluded(o, Vec3::Z * 0.9, 1.0));
        // Beside the quad.
        assert!(!bvh.occluded(Vec3::new(1.5, 0.0, 0.0), Vec3::Z * 2.0, 1.0));
        // From the other side too.
        assert!(bvh.occluded(Vec3::new(0.0, 0.0, 2.0), -Vec3::Z * 2.0, 1.0));
    }

    #[test]
    fn the_tree_agrees_with_every_triangle_tested() {
        let tris = grid(24);
        let bvh = TriangleBvh::build(tris.clone());
        assert_eq!(bvh.triangles.len(), tris.len());
        assert!(bvh.depth() <= 10, "balanced: depth {}", bvh.depth());
        let mut s = 12345u32;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            s as f32 / u32::MAX as f32
        };
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..4000 {
            let o = Vec3::new(rnd() * 26.0 - 1.0, rnd() * 26.0 - 1.0, rnd() * 8.0 - 2.0);
            let e = Vec3::new(rnd() * 26.0 - 1.0, rnd() * 26.0 - 1.0, rnd() * 8.0 - 2.0);
            let want = brute(&tris, o, e - o, 1.0);
            assert_eq!(bvh.occluded(o, e - o, 1.0), want, "{o} → {e}");
            if want {
                hits += 1
            } else {
                misses += 1
            }
        }
        assert!(hits > 100 && misses > 100, "{hits} hits, {misses} misses");
    }

    #[test]
    fn every_node_box_holds_its_triangles_and_the_gpu_layout_has_every_vec4() {
        let bvh = TriangleBvh::build(grid(9));
        fn check(b: &TriangleBvh, i: usize) -> (Vec3, Vec3) {
            let n = b.nodes[i];
            let (lo, hi) = if n.count > 0 {
                let ts = &b.triangles[n.next as usize..(n.next + n.count) as usize];
                let vs = ts.iter().flatten();
                (
                    vs.clone().fold(Vec3::INFINITY, |a, &v| a.min(v)),
                    vs.fold(Vec3::NEG_INFINITY, |a, &v| a.max(v)),
                )
            } else {
                let (a0, a1) = check(b, i + 1);
                let (b0, b1) = check(b, n.next as usize);
                (a0.min(b0), a1.max(b1))
            };
            assert!(n.min.cmple(lo).all() && n.max.cmpge(hi).all());
            (lo, hi)
        }
        check(&bvh, 0);
        let mut out = vec![[0.0; 4]; 5];
        bvh.write_gpu(5, &mut out);
        assert_eq!(out.len() as u32, 5 + bvh.vec4s());
        assert_eq!(TriangleBvh::build(Vec::new()).depth(), 0);
        assert!(!TriangleBvh::build(Vec::new()).occluded(Vec3::ZERO, Vec3::ONE, 1.0));
    }
}
