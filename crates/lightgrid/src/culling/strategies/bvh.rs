//! The light hierarchy (tiled-forward-shading §4.4): a BVH over the frame's lights in view
//! space, rebuilt every frame, with BVH_WIDTH (32) children per node so one traversal
//! workgroup tests all children of a node at once (`bvh.wgsl`).
//!
//! Build (CPU, [`build_bvh`]): lights sorted by the Morton code of their view-space centre
//! (quantized to 10 bits per axis within the centres' bounding box), cut into leaves of 32
//! consecutive lights, each level above grouping 32 consecutive nodes. Nodes are stored root
//! first, level by level; each node's box contains its children's (for a leaf: its lights'
//! spheres, padded for round-off), so the traversal never prunes a light the gather test
//! would keep, and the lists it builds equal gather's.

use crate::consts::{BVH_LEAF, BVH_WIDTH};
use crate::culling::grid::{GridDims, LightGrid};
use crate::culling::strategies::gather::{box_margin, cell_frustum, light_margin, CpuFrustum};
use crate::culling::strategies::gpu_assign::{bvh_shader, CellKernels};
use crate::culling::strategies::{AssignFrame, AssignStrategy, StrategyContext, StrategyRun};
use crate::error::Result;
use crate::frame::FrameEncoder;
use crate::gpu::CounterValues;
use crate::gpu::{bind_resources, buffer_layout, grow_storage, storage_buffer, STORAGE_READ};
use crate::scene::Light;
use crate::scene::{ViewLight, ViewSetup};
use glam::Vec3;
use rayon::prelude::*;
use web_time::Instant;

pub use crate::gpu_types::BvhNode;

#[cfg_attr(not(feature = "testing"), allow(dead_code))]
impl BvhNode {
    /// Does the node hold lights (slots of [`LightBvh::order`]) rather than child nodes?
    #[cfg_attr(not(feature = "testing"), allow(dead_code))]
    pub fn is_leaf(&self) -> bool {
        self.count & BVH_LEAF != 0
    }

    /// The node's children: node indices, or for a leaf the slots of [`LightBvh::order`].
    #[cfg_attr(not(feature = "testing"), allow(dead_code))]
    pub fn children(&self) -> std::ops::Range<u32> {
        self.first..self.first + (self.count & !BVH_LEAF)
    }
}

/// The hierarchy: `nodes[0]` is the root; `order[slot]` is the light a leaf slot refers to.
#[derive(Clone, Debug, Default)]
pub struct LightBvh {
    /// The nodes, root first, each level after the one above.
    pub nodes: Vec<BvhNode>,
    /// The light (its index in the scene's light list) of each leaf slot.
    pub order: Vec<u32>,
}

/// Spread the low 10 bits of `v` so that two zero bits follow each.
fn spread_bits(v: u32) -> u32 {
    let mut x = v & 0x3ff;
    x = (x | (x << 16)) & 0x0300_00ff;
    x = (x | (x << 8)) & 0x0300_f00f;
    x = (x | (x << 4)) & 0x030c_30c3;
    (x | (x << 2)) & 0x0924_9249
}

/// 30-bit Morton code of `p` inside the box `[lo, lo + extent]`.
pub fn morton_code(p: Vec3, lo: Vec3, extent: Vec3) -> u32 {
    let q =
        ((p - lo) / extent.max(Vec3::splat(1e-20)) * 1023.0).clamp(Vec3::ZERO, Vec3::splat(1023.0));
    spread_bits(q.x as u32) | (spread_bits(q.y as u32) << 1) | (spread_bits(q.z as u32) << 2)
}

/// Padding added to every light's box: view-space positions computed on the GPU may differ
/// from the CPU's by a few ulps of the distance from the eye.
fn pad(center: Vec3, r: f32) -> f32 {
    r * 1e-4 + center.abs().max_element() * 1e-5 + 1e-5
}

fn union(nodes: &[BvhNode]) -> ([f32; 3], [f32; 3]) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for n in nodes {
        lo = lo.min(Vec3::from(n.lo));
        hi = hi.max(Vec3::from(n.hi));
    }
    (lo.to_array(), hi.to_array())
}

/// The node layout for `lights` lights: per level, bottom-up (leaves first), the index of its
/// first node and its node count. Nodes are stored root first, so the last level listed
/// starts at 0.
pub(crate) fn bvh_levels(lights: usize) -> Vec<(u32, u32)> {
    let mut counts = Vec::new();
    let mut n = lights.div_ceil(BVH_WIDTH as usize);
    while n > 0 {
        counts.push(n as u32);
        if n == 1 {
            break;
        }
        n = n.div_ceil(BVH_WIDTH as usize);
    }
    let mut at = 0u32;
    let mut firsts = vec![0u32; counts.len()];
    for (i, &c) in counts.iter().enumerate().rev() {
        firsts[i] = at;
        at += c;
    }
    firsts.into_iter().zip(counts).collect()
}

/// Build the hierarchy over `lights` as seen by `setup`'s camera.
pub fn build_bvh(setup: &ViewSetup, lights: &[Light]) -> LightBvh {
    if lights.is_empty() {
        return LightBvh::default();
    }
    // Each light in view space: its bounding sphere (a spot's cone sector) and reach box.
    let views: Vec<ViewLight> = lights.par_iter().map(|l| setup.to_view(l)).collect();
    let centers: Vec<Vec3> = views.iter().map(|v| v.center).collect();
    let (lo, hi) = centers.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &c| (lo.min(c), hi.max(c)),
    );
    let mut keys: Vec<u64> = centers
        .par_iter()
        .enumerate()
        .map(|(i, &c)| (u64::from(morton_code(c, lo, hi - lo)) << 32) | i as u64)
        .collect();
    keys.par_sort_unstable();
    let order: Vec<u32> = keys.iter().map(|&k| k as u32).collect();
    let width = BVH_WIDTH as usize;
    // Levels bottom-up; children indices are fixed once the top-down layout is known.
    let leaves: Vec<BvhNode> = order
        .par_chunks(width)
        .enumerate()
        .map(|(j, chunk)| {
            let mut lo = Vec3::splat(f32::INFINITY);
            let mut hi = Vec3::splat(f32::NEG_INFINITY);
            for &l in chunk {
                // The light's sphere box, or a spot's sector box (`ViewLight::reach_box`),
                // padded.
                let v = &views[l as usize];
                let (c, r) = (v.center, v.radius);
                let (box_lo, box_hi) = v
                    .reach_box()
                    .unwrap_or((c - Vec3::splat(r), c + Vec3::splat(r)));
                let e = Vec3::splat(r * 1e-4 + pad(c, r));
                lo = lo.min(box_lo - e);
                hi = hi.max(box_hi + e);
            }
            BvhNode {
                lo: lo.to_array(),
                first: (j * width) as u32,
                hi: hi.to_array(),
                count: chunk.len() as u32 | BVH_LEAF,
            }
        })
        .collect();
    let mut levels = vec![leaves];
    while levels.last().expect("at least the leaves").len() > 1 {
        let below = levels.last().expect("non-empty");
        let level: Vec<BvhNode> = below
            .chunks(width)
            .enumerate()
            .map(|(j, chunk)| {
                let (lo, hi) = union(chunk);
                BvhNode {
                    lo,
                    first: (j * width) as u32, // index within the level below, fixed below
                    hi,
                    count: chunk.len() as u32,
                }
            })
            .collect();
        levels.push(level);
    }
    // Root first: level k's nodes follow those of every level above it.
    let mut nodes = Vec::with_capacity(levels.iter().map(Vec::len).sum());
    let offsets: Vec<u32> = bvh_levels(lights.len()).iter().map(|l| l.0).collect();
    debug_assert_eq!(offsets.len(), levels.len());
    for (i, level) in levels.iter().enumerate().rev() {
        for n in level {
            let mut n = *n;
            if i > 0 {
                n.first += offsets[i - 1];
            }
            nodes.push(n);
        }
    }
    LightBvh { nodes, order }
}

/// `box_in_cell` of tile_frustum.wgsl: does the node's view-space box reach into the frustum?
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
fn box_in_cell(f: &CpuFrustum, n: &BvhNode) -> bool {
    box_margin(f, Vec3::from(n.lo), Vec3::from(n.hi)) >= 0.0
}

/// CPU twin of the GPU traversal (`bvh.wgsl`): per cell, walk `bvh` pruning boxes outside the
/// cell's frustum and keep the leaves' lights that pass the gather test. Lists in light
/// order. Equal to [`crate::culling::strategies::gather::assign_gather_cpu`] whenever the boxes are conservative, which is
/// what the tests check.
#[cfg_attr(not(feature = "testing"), allow(dead_code))]
pub fn traverse_bvh_cpu(
    setup: &ViewSetup,
    dims: &GridDims,
    lights: &[Light],
    cell_bounds: &[[f32; 2]],
    culls: Option<&[crate::culling::bounds::cell_box::CellCull]>,
    bvh: &LightBvh,
) -> LightGrid {
    let views: Vec<_> = lights.iter().map(|l| setup.to_view(l)).collect();
    let lists: Vec<Vec<u32>> = (0..dims.cell_count())
        .into_par_iter()
        .map(|c| {
            let f = cell_frustum(setup, dims, c, cell_bounds, culls);
            let mut out = Vec::new();
            let mut stack = Vec::new();
            if bvh.nodes.first().is_some_and(|root| box_in_cell(&f, root)) {
                stack.push(0u32);
            }
            while let Some(i) = stack.pop() {
                let node = &bvh.nodes[i as usize];
                for child in node.children() {
                    if node.is_leaf() {
                        let l = bvh.order[child as usize];
                        if light_margin(&f, &views[l as usize]) >= 0.0 {
                            out.push(l);
                        }
                    } else if box_in_cell(&f, &bvh.nodes[child as usize]) {
                        stack.push(child);
                    }
                }
            }
            out.sort_unstable();
            out
        })
        .collect();
    LightGrid::from_lists(*dims, &lists)
}

/// The hierarchy's GPU buffer (group 2 of the traversal kernels, `bvh.wgsl`): the order
/// (the leaf slots' lights) padded to a multiple of 4 entries, then the nodes. One binding
/// keeps the walk within WebGPU's default 8 storage buffers per stage.
pub struct BvhBuffers {
    pub layout: wgpu::BindGroupLayout,
    data: wgpu::Buffer,
}

/// Bytes the order of `lights` lights takes at the start of [`BvhBuffers`]' buffer.
fn order_bytes(lights: usize) -> u64 {
    lights.div_ceil(4) as u64 * 16
}

impl BvhBuffers {
    pub fn new(device: &wgpu::Device) -> Self {
        BvhBuffers {
            layout: buffer_layout(device, "light bvh (group 2)", &[STORAGE_READ]),
            data: storage_buffer(device, "bvh", 1 << 12),
        }
    }

    /// Make room for `lights` lights' order and `nodes` nodes; returns where the nodes start.
    fn fit(&mut self, device: &wgpu::Device, lights: usize, nodes: usize) -> u64 {
        let at = order_bytes(lights);
        let bytes = at + (nodes * std::mem::size_of::<BvhNode>()) as u64;
        grow_storage(device, &mut self.data, "bvh", bytes);
        at
    }

    fn bind(&self, device: &wgpu::Device) -> wgpu::BindGroup {
        bind_resources(
            device,
            "light bvh",
            &self.layout,
            &[self.data.as_entire_binding()],
        )
    }

    /// Upload a hierarchy and bind it.
    pub fn upload(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        bvh: &LightBvh,
    ) -> wgpu::BindGroup {
        let at = self.fit(device, bvh.order.len(), bvh.nodes.len());
        if !bvh.nodes.is_empty() {
            queue.write_buffer(&self.data, 0, bytemuck::cast_slice(&bvh.order));
            queue.write_buffer(&self.data, at, bytemuck::cast_slice(&bvh.nodes));
        }
        self.bind(device)
    }

    /// Record the copies of a hierarchy built on the GPU (`nodes` nodes in `node_buffer`,
    /// the order of `lights` lights in `order`) and bind it.
    pub fn copy(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        lights: usize,
        (node_buffer, nodes): (&wgpu::Buffer, usize),
        order: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let at = self.fit(device, lights, nodes);
        if nodes > 0 {
            encoder.copy_buffer_to_buffer(order, 0, &self.data, 0, lights as u64 * 4);
            let node_bytes = (nodes * std::mem::size_of::<BvhNode>()) as u64;
            encoder.copy_buffer_to_buffer(node_buffer, 0, &self.data, at, node_bytes);
        }
        self.bind(device)
    }
}

/// `--assign bvh`: the hierarchy built on the CPU every frame from the lights alone (no wait
/// for the GPU), uploaded, and walked by one workgroup per occupied cell (`bvh.wgsl`).
struct CpuBvhStrategy {
    kernels: CellKernels,
    buffers: BvhBuffers,
}

pub(super) fn create_strategy(ctx: &StrategyContext) -> Box<dyn AssignStrategy> {
    let buffers = BvhBuffers::new(ctx.device);
    Box::new(CpuBvhStrategy {
        kernels: CellKernels::new(ctx, "bvh", &bvh_shader(), &[&buffers.layout]),
        buffers,
    })
}

impl AssignStrategy for CpuBvhStrategy {
    fn encode(&mut self, a: AssignFrame, enc: &mut FrameEncoder) -> Result<StrategyRun> {
        let start = Instant::now();
        let bvh = build_bvh(&a.f.setup, a.f.lights);
        let cpu_ms = start.elapsed().as_secs_f64() * 1e3;
        let group = self.buffers.upload(a.f.device, a.f.queue, &bvh);
        self.kernels.encode(a, enc, &[&group]);
        Ok(StrategyRun {
            cpu_ms,
            ..Default::default()
        })
    }

    fn observe(&mut self, device: &wgpu::Device, values: &CounterValues) -> Result<()> {
        self.kernels.observe(device, values)
    }

    fn grid_entries(&self, values: &CounterValues) -> u32 {
        values.index_needed()
    }
}
