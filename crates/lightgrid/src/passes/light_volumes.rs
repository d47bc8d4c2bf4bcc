//! Light volumes for the classic deferred family (`deferred`, `deferred_stencil`,
//! `light_prepass*`).
//!
//! Each light's bounding sphere is drawn as an instanced low-poly sphere scaled to enclose it;
//! a spot of half-angle up to 45° as a closed cone instead (apex, a ring at the cap's rim, a
//! cylinder to the range: the convex hull of the cone's sector, [`cone_volume`]), which the
//! vertex shader builds from a unit cone mesh and the light.
//! Per frame the CPU sorts the lights into draw classes by where the sphere sits against the
//! near and far planes, so the image is right when the camera is inside a volume or a volume
//! crosses a clip plane:
//! 1. `front`: the sphere is entirely beyond the near plane: front faces, depth test
//!    LessEqual (drops fragments whose surface is in front of the volume).
//! 2. `back`: the sphere reaches the near plane (or contains the camera) but not the far plane:
//!    back faces, depth test GreaterEqual (drops fragments whose surface is behind it).
//! 3. `full`: the sphere reaches both planes: a full-screen triangle, no depth test.
//! 4. `stencil` (only when asked): every light not reaching the far plane, for the two-sided
//!    stencil test (z-fail marking is exact with the camera inside, but needs the back faces
//!    unclipped by the far plane); the others fall back to classes 1 and 3.
//!
//! The volume passes depth-test against a depth-stencil copy of the scene depth
//! ([`volume_depth_format`]), made by a full-screen pass at the start, because they also sample
//! the scene depth to rebuild positions, and a texture cannot be a written stencil attachment
//! and sampled in one pass.
//!
//! MSAA (tiled-deferred-tricks: "edge detection into stencil, then per-sample shading only on
//! these edges and simple per-pixel everywhere else", Crysis 3): the copy is multisampled and
//! written per sample; a full-screen pass sets the stencil's edge bit ([`EDGE_STENCIL`]) on the
//! pixels whose samples show different surfaces (`passes/msaa_edges.wgsl`, the edge-aware
//! kernel's test); then each volume class is drawn twice: [`Shading::PerPixel`] where the bit
//! is clear (one fragment per pixel, shaded at the pixel centre, its colour written to every
//! covered sample) and [`Shading::PerSample`] where it is set (the fragment shader reads
//! `sample_index`, so it runs once per sample and shades the sample where it lies).
//! `deferred_stencil`'s z-fail marks live in the low seven bits ([`COUNT_STENCIL_MASK`]), so
//! they and the edge bit never disturb each other. Without MSAA no edge is marked and only the
//! per-pixel pipelines exist.

use crate::consts::{CONE_VOLUME_MARGIN, CONE_VOLUME_MIN_COS, CONE_VOLUME_SEGMENTS};
use crate::scene::ViewSetup;
use crate::scene::{Light, Mesh};
use glam::Vec3;
use std::ops::Range;

/// Is the light drawn as a cone volume (a spot no wider than 45°)? `vs_volume` decides the
/// same way.
pub fn cone_volume(l: &Light) -> bool {
    l.spot.is_some_and(|s| s.cos_outer >= CONE_VOLUME_MIN_COS)
}

/// The cone volume's extreme points in world space (apex pulled back, the tip ring), as
/// `vs_volume` places them: for the classification's extent.
fn cone_volume_extent(l: &Light, center: Vec3) -> f32 {
    let s = l.spot.expect("cone volumes are spots");
    let (c, r) = (s.cos_outer, l.range);
    let sin = (1.0 - c * c).max(0.0).sqrt();
    let grow = 1.0 + CONE_VOLUME_MARGIN;
    let rho = r * sin / (std::f32::consts::PI / CONE_VOLUME_SEGMENTS as f32).cos() * grow;
    let apex = l.position - s.direction * (CONE_VOLUME_MARGIN * r);
    let tip = l.position + s.direction * (grow * r);
    let along = (tip - center).dot(s.direction);
    let across = ((tip - center).length_squared() - along * along)
        .max(0.0)
        .sqrt();
    let ring = (along * along + (across + rho) * (across + rho)).sqrt();
    apex.distance(center).max(ring) * 1.01
}

/// The volume passes' depth-stencil format: a float depth copy of the scene depth, so the
/// volume tests keep reversed-Z's precision (`crate::depth`): with a 24-bit unorm copy a
/// znear of 10⁻⁶ leaves everything beyond ~10 units within a few steps of 0. Adapters
/// without `DEPTH32FLOAT_STENCIL8` (rare: every Vulkan, Metal and DX12 GPU in wgpu's tests
/// has it, as has lavapipe) fall back to `Depth24PlusStencil8`.
pub(crate) fn volume_depth_format(device: &wgpu::Device) -> wgpu::TextureFormat {
    if device
        .features()
        .contains(wgpu::Features::DEPTH32FLOAT_STENCIL8)
    {
        wgpu::TextureFormat::Depth32FloatStencil8
    } else {
        wgpu::TextureFormat::Depth24PlusStencil8
    }
}

/// The stencil bit marking an MSAA edge pixel: its samples are shaded one by one.
pub(crate) const EDGE_STENCIL: u32 = 0x80;
/// The stencil bits of the z-fail volume marks (`VolumeDraw::StencilMark`): below the edge bit.
pub(crate) const COUNT_STENCIL_MASK: u32 = 0x7f;

/// How the fragments of a volume (or full-screen) draw are shaded with MSAA.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shading {
    /// Pixels whose edge bit is clear (every pixel without MSAA): one fragment per pixel.
    PerPixel,
    /// Pixels whose edge bit is set: the fragment entry reads `sample_index`, so it runs per
    /// sample (MSAA only).
    PerSample,
}

impl Shading {
    /// The pipelines of a frame with `samples` samples per pixel.
    pub fn of(samples: u32) -> &'static [Shading] {
        if samples > 1 {
            &[Shading::PerPixel, Shading::PerSample]
        } else {
            &[Shading::PerPixel]
        }
    }

    /// The stencil reference of a draw testing the edge bit.
    pub fn edge_bit(self) -> u32 {
        match self {
            Shading::PerPixel => 0,
            Shading::PerSample => EDGE_STENCIL,
        }
    }
}

/// The stencil reference a draw of `draw` with `shading` tests against (the pipelines'
/// masks select the bits: see [`LightVolumes::pipeline`]).
fn stencil_reference(draw: VolumeDraw, shading: Shading) -> u32 {
    match draw {
        VolumeDraw::StencilMark => 0,
        // Inside the volume: the z-fail count's low bit (below).
        VolumeDraw::StencilLight => shading.edge_bit() | 1,
        _ => shading.edge_bit(),
    }
}

/// Shading draws: the reference's edge bit equals the sample's.
fn edge_test() -> wgpu::StencilFaceState {
    wgpu::StencilFaceState {
        compare: wgpu::CompareFunction::Equal,
        fail_op: wgpu::StencilOperation::Keep,
        depth_fail_op: wgpu::StencilOperation::Keep,
        pass_op: wgpu::StencilOperation::Keep,
    }
}

/// Bytes per pixel of the volume depth-stencil target in the memory model: 32-bit float
/// depth + 8-bit stencil (`volume_depth_format`).
pub const VOLUME_DEPTH_BYTES: u32 = 5;
pub(crate) const VOLUME_WGSL: &str = include_str!("light_volume.wgsl");

const RINGS: u32 = 8;
const SEGMENTS: u32 = 16;
/// The sphere mesh's faces lie inside the unit sphere; scaling by this moves every face out
/// of it. Adjacent vertices are at most π/8 apart, so each face's circumscribed cap has an
/// angular radius well under π/6, and 1/cos(π/6) ≈ 1.155 < 1.16 keeps faces outside.
const ENCLOSING_SCALE: f32 = 1.16;
/// Relative margin for the plane tests of the classification.
const PLANE_SLACK: f32 = 1e-3;

/// Light indices per draw class.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct VolumeClasses {
    /// Volumes entirely beyond the near plane: front faces, depth test LessEqual.
    pub front: Vec<u32>,
    /// Volumes reaching the near plane but not the far one: back faces, GreaterEqual.
    pub back: Vec<u32>,
    /// Volumes reaching both planes: a full-screen triangle, no depth test.
    pub full: Vec<u32>,
    /// Stencil-tested lights (only when asked): every volume not reaching the far plane,
    /// marked by two-sided z-fail stencil then lit; empty otherwise.
    pub stencil: Vec<u32>,
    /// Per class (front, back, full, stencil), where its cone volumes start.
    pub cones_from: [u32; 4],
}

/// The first one-at-a-time class slot of [`LightVolumes`].
pub const SHADOWED: usize = 4;

impl VolumeClasses {
    /// Split the classes: the lights `casts` says cast re-used shadow maps (drawn one at a
    /// time after their maps), and the rest; each list keeps its order (spheres, then cones).
    pub fn split(self, casts: impl Fn(usize) -> bool, lights: &[Light]) -> (Self, Self) {
        let part = |list: Vec<u32>| -> (Vec<u32>, Vec<u32>) {
            list.into_iter().partition(|&i| !casts(i as usize))
        };
        let (front, sf) = part(self.front);
        let (back, sb) = part(self.back);
        let (full, sfl) = part(self.full);
        let (stencil, ss) = part(self.stencil);
        let with_cones = |front: Vec<u32>, back: Vec<u32>, full: Vec<u32>, stencil: Vec<u32>| {
            let cones_from = [&front, &back, &full, &stencil]
                .map(|list| list.partition_point(|&i| !cone_volume(&lights[i as usize])) as u32);
            VolumeClasses {
                front,
                back,
                full,
                stencil,
                cones_from,
            }
        };
        (
            with_cones(front, back, full, stencil),
            with_cones(sf, sb, sfl, ss),
        )
    }
}

/// Sort the lights into draw classes (see the module docs). Lights that cannot reach any
/// sample (entirely behind the near plane or beyond the far plane) are left out.
pub fn classify_lights(setup: &ViewSetup, lights: &[Light], stencil: bool) -> VolumeClasses {
    let mut c = VolumeClasses::default();
    for (i, l) in lights.iter().enumerate() {
        let v = setup.to_view(l);
        let w = -v.center.z;
        let r = if cone_volume(l) {
            let l = l.relative_to(setup.eye);
            cone_volume_extent(&l, l.bounding_sphere().0)
        } else {
            v.radius * ENCLOSING_SCALE
        };
        if w + v.radius < setup.near || w - v.radius > setup.far {
            continue;
        }
        let near = w - r <= setup.near * (1.0 + PLANE_SLACK);
        let far = w + r >= setup.far * (1.0 - PLANE_SLACK);
        let i = i as u32;
        match (near, far) {
            (_, false) if stencil => c.stencil.push(i),
            (false, _) => c.front.push(i),
            (true, false) => c.back.push(i),
            (true, true) => c.full.push(i),
        }
    }
    // Sphere volumes first, then cone volumes, in each class (drawn with their own mesh).
    for list in [&mut c.front, &mut c.back, &mut c.full, &mut c.stencil] {
        list.sort_by_key(|&i| cone_volume(&lights[i as usize]));
    }
    c.cones_from = [&c.front, &c.back, &c.full, &c.stencil]
        .map(|list| list.partition_point(|&i| !cone_volume(&lights[i as usize])) as u32);
    c
}

/// The unit cone mesh `vs_volume` shapes per spot: xy on the unit circle (scaled to enclose
/// it), z the part: 0 the apex, 1 the ring at the cap's rim, 2 the ring at the range (and its
/// centre). Triangles wound like the sphere's (front faces outward).
fn unit_cone(outward_ccw: bool) -> (Vec<[f32; 3]>, Vec<u32>) {
    let n = CONE_VOLUME_SEGMENTS;
    let mut v = vec![[0.0, 0.0, 0.0]];
    for z in [1.0, 2.0] {
        for k in 0..n {
            let a = k as f32 / n as f32 * std::f32::consts::TAU;
            v.push([a.cos(), a.sin(), z]);
        }
    }
    v.push([0.0, 0.0, 2.0]);
    let ring = |z: u32, k: u32| 1 + (z - 1) * n + k % n;
    let tip = 1 + 2 * n;
    let mut tris = Vec::new();
    for k in 0..n {
        tris.push([0, ring(1, k), ring(1, k + 1)]);
        tris.push([ring(1, k), ring(2, k), ring(2, k + 1)]);
        tris.push([ring(1, k), ring(2, k + 1), ring(1, k + 1)]);
        tris.push([tip, ring(2, k + 1), ring(2, k)]);
    }
    // Orient every triangle against an interior point of the (convex) code-space shape.
    let p = |i: u32| Vec3::from(v[i as usize]);
    let inside = Vec3::new(0.0, 0.0, 1.2);
    let mut indices = Vec::new();
    for [a, b, c] in tris {
        let normal = (p(b) - p(a)).cross(p(c) - p(a));
        let out = normal.dot((p(a) + p(b) + p(c)) / 3.0 - inside) > 0.0;
        if out == outward_ccw {
            indices.extend_from_slice(&[a, b, c]);
        } else {
            indices.extend_from_slice(&[a, c, b]);
        }
    }
    (v, indices)
}

/// Which light volumes a draw covers, and how they are rasterized.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum VolumeDraw {
    Front,
    Back,
    Full,
    /// Two-sided z-fail stencil marking, no colour.
    StencilMark,
    /// Back faces where the stencil is set; clears it.
    StencilLight,
}

/// What a volume pipeline shades with.
pub(crate) struct VolumePipelineDesc<'a> {
    pub label: &'a str,
    pub module: &'a wgpu::ShaderModule,
    pub fragment_entry: &'a str,
    pub layouts: &'a [Option<&'a wgpu::BindGroupLayout>],
    pub color_targets: &'a [Option<wgpu::ColorTargetState>],
    pub draw: VolumeDraw,
    /// Per pixel or (MSAA edge pixels) per sample; `StencilMark` writes no colour and is
    /// drawn once, its pipeline `PerPixel`.
    pub shading: Shading,
}

/// A full-screen draw of a volume pass (after the depth copy).
pub(crate) struct FullscreenVolumeDesc<'a> {
    pub label: &'a str,
    pub module: &'a wgpu::ShaderModule,
    pub fragment_entry: &'a str,
    pub layouts: &'a [Option<&'a wgpu::BindGroupLayout>],
    pub color_targets: &'a [Option<wgpu::ColorTargetState>],
    pub kind: Fullscreen,
}

/// What a full-screen volume-pass draw does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Fullscreen {
    /// Shades the pixels (or edge samples) of `Shading`.
    Shade(Shading),
    /// Sets [`EDGE_STENCIL`] on every sample of the pixels its fragment does not discard; no
    /// colour.
    MarkEdges,
}

/// Additive blending (exit radiance, irradiance and counts accumulate over lights).
pub fn additive(format: wgpu::TextureFormat) -> wgpu::ColorTargetState {
    let add = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    wgpu::ColorTargetState {
        format,
        blend: Some(wgpu::BlendState {
            color: add,
            alpha: add,
        }),
        write_mask: wgpu::ColorWrites::ALL,
    }
}

/// The sphere mesh, per-frame instance lists and the depth-stencil copy.
pub(crate) struct LightVolumes {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    /// The sphere's and the unit cone's index ranges in `indices`, and the cone's first vertex.
    sphere: Range<u32>,
    cone: Range<u32>,
    cone_base: i32,
    instances: wgpu::Buffer,
    /// Per class slot (front, back, full, stencil), then per class slot of the lights drawn
    /// one at a time after their re-used shadow maps ([`SHADOWED`] + class).
    ranges: [Range<u32>; 8],
    cones_from: [u32; 8],
    /// The lights drawn one at a time: (class slot, instance, light index).
    shadowed: Vec<(usize, u32, u32)>,
    pub depth: wgpu::TextureView,
    /// [`volume_depth_format`] on this device.
    pub depth_format: wgpu::TextureFormat,
    /// Samples per pixel of the depth-stencil copy (the frame's).
    pub samples: u32,
    copy_layout: wgpu::BindGroupLayout,
}

/// Colour targets kept in the pass but not written (stencil-only and copy draws).
fn no_color(targets: &[Option<wgpu::ColorTargetState>]) -> Vec<Option<wgpu::ColorTargetState>> {
    targets
        .iter()
        .map(|t| {
            t.clone().map(|t| wgpu::ColorTargetState {
                blend: None,
                write_mask: wgpu::ColorWrites::empty(),
                ..t
            })
        })
        .collect()
}

fn instance_buffer(device: &wgpu::Device, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("light volume instances"),
        size: size.max(16),
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The stencil state of a volume class: the stencil-shadow-style marking (back faces
/// behind the scene incremented, front faces decremented), the light draw over what was
/// marked (clearing it), or for the others the MSAA edge bit's test (`edge_test`).
fn volume_stencil(draw: VolumeDraw) -> wgpu::StencilState {
    use wgpu::{CompareFunction as C, StencilFaceState, StencilOperation as Op};
    let both = |face: StencilFaceState, read_mask: u32, write_mask: u32| wgpu::StencilState {
        front: face,
        back: face,
        read_mask,
        write_mask,
    };

    match draw {
        VolumeDraw::StencilMark => wgpu::StencilState {
            front: StencilFaceState {
                compare: C::Always,
                fail_op: Op::Keep,
                depth_fail_op: Op::DecrementWrap,
                pass_op: Op::Keep,
            },
            back: StencilFaceState {
                compare: C::Always,
                fail_op: Op::Keep,
                depth_fail_op: Op::IncrementWrap,
                pass_op: Op::Keep,
            },
            read_mask: COUNT_STENCIL_MASK,
            write_mask: COUNT_STENCIL_MASK,
        },
        VolumeDraw::StencilLight => both(
            StencilFaceState {
                compare: C::Equal,
                fail_op: Op::Keep,
                depth_fail_op: Op::Keep,
                pass_op: Op::Zero,
            },
            EDGE_STENCIL | 1,
            COUNT_STENCIL_MASK,
        ),
        _ => both(edge_test(), EDGE_STENCIL, 0),
    }
}

impl LightVolumes {
    /// Volumes for a `width` x `height` frame of `samples` samples per pixel.
    pub fn new(device: &wgpu::Device, width: u32, height: u32, samples: u32) -> Self {
        use wgpu::util::DeviceExt;
        let sphere = Mesh::sphere(ENCLOSING_SCALE, RINGS, SEGMENTS);
        let mut positions: Vec<[f32; 3]> = sphere.positions.iter().map(|p| p.to_array()).collect();
        // The cone is wound like the sphere: look at a triangle away from the poles.
        let t = (RINGS / 2 * SEGMENTS * 6) as usize;
        let tri = &sphere.indices[t..t + 3];
        let p = |i: u32| sphere.positions[i as usize];
        let outward_ccw = (p(tri[1]) - p(tri[0]))
            .cross(p(tri[2]) - p(tri[0]))
            .dot(p(tri[0]))
            > 0.0;
        let (cone_positions, cone_indices) = unit_cone(outward_ccw);
        let cone_base = positions.len() as i32;
        positions.extend_from_slice(&cone_positions);
        let mut all_indices = sphere.indices.clone();
        all_indices.extend_from_slice(&cone_indices);
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("light volume meshes"),
            contents: bytemuck::cast_slice(&positions),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("light volume mesh indices"),
            contents: bytemuck::cast_slice(&all_indices),
            usage: wgpu::BufferUsages::INDEX,
        });
        let sphere_count = sphere.indices.len() as u32;
        let depth_format = volume_depth_format(device);
        let depth = super::multisampled_texture(
            device,
            "light volume depth-stencil",
            depth_format,
            (width, height),
            samples,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());
        let copy_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth copy source"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: samples > 1,
                },
                count: None,
            }],
        });
        LightVolumes {
            vertices,
            indices,
            sphere: 0..sphere_count,
            cone: sphere_count..all_indices.len() as u32,
            cone_base,
            instances: instance_buffer(device, 1 << 14),
            ranges: Default::default(),
            cones_from: [0; 8],
            shadowed: Vec::new(),
            depth,
            depth_format,
            samples,
            copy_layout,
        }
    }

    /// Upload this frame's classes: `c` drawn together, `shadowed` one light at a time
    /// ([`Self::shadowed`], [`Self::draw_one`]) after each one's re-used shadow maps.
    pub fn upload_split(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        c: &VolumeClasses,
        shadowed: &VolumeClasses,
    ) {
        let mut all = Vec::new();
        let mut start = 0u32;
        self.shadowed.clear();
        for (slot, list) in [&c.front, &c.back, &c.full, &c.stencil]
            .into_iter()
            .chain([
                &shadowed.front,
                &shadowed.back,
                &shadowed.full,
                &shadowed.stencil,
            ])
            .enumerate()
        {
            all.extend_from_slice(list);
            self.ranges[slot] = start..start + list.len() as u32;
            if slot >= SHADOWED {
                self.shadowed.extend(
                    list.iter()
                        .enumerate()
                        .map(|(k, &light)| (slot, self.ranges[slot].start + k as u32, light)),
                );
            }
            start += list.len() as u32;
        }
        self.cones_from[..4].copy_from_slice(&c.cones_from);
        self.cones_from[4..].copy_from_slice(&shadowed.cones_from);
        let bytes: &[u8] = bytemuck::cast_slice(&all);
        if bytes.len() as u64 > self.instances.size() {
            self.instances = instance_buffer(device, (bytes.len() as u64).next_power_of_two());
        }
        if !bytes.is_empty() {
            queue.write_buffer(&self.instances, 0, bytes);
        }
    }

    pub fn stencil_count(&self) -> u32 {
        self.ranges[3].len() as u32
    }

    /// The lights drawn one at a time this frame, in order: (class slot, instance, light),
    /// for [`Self::draw_one`].
    pub fn shadowed(&self) -> Vec<(usize, u32, u32)> {
        self.shadowed.clone()
    }

    /// The class a one-at-a-time slot holds, and the draws it takes: `Front`, `Back` or `Full`
    /// with the class's pipeline, or for the stencil class `StencilMark` then `StencilLight`.
    pub fn shadowed_class(slot: usize) -> VolumeDraw {
        match slot - SHADOWED {
            0 => VolumeDraw::Front,
            1 => VolumeDraw::Back,
            2 => VolumeDraw::Full,
            _ => VolumeDraw::StencilLight,
        }
    }

    /// Draw instance `i` of one-at-a-time slot `slot` as `draw` with the bound pipeline, made
    /// for `shading`.
    pub fn draw_one(
        &self,
        pass: &mut wgpu::RenderPass,
        (slot, i): (usize, u32),
        draw: VolumeDraw,
        shading: Shading,
    ) {
        self.bind(pass);
        pass.set_stencil_reference(stencil_reference(draw, shading));
        if draw == VolumeDraw::Full {
            pass.draw(0..3, i..i + 1);
        } else {
            self.draw_instances(pass, slot, i..i + 1);
        }
    }

    /// A pipeline for one kind of volume draw (see [`VolumeDraw`]).
    ///
    /// Stencil (drawn with `stencil_reference`): shading draws pass where the edge bit is
    /// what `shading` wants; `StencilMark` counts z-fails in the low seven bits (wrapping
    /// within them: the write mask keeps the edge bit); `StencilLight` passes where the count's
    /// low bit and the edge bit match the reference, and clears the count. A convex closed
    /// volume not clipped by the far plane leaves a count of 0 or 1 (a back face behind the
    /// surface adds one, a front face behind it takes one, and the front face lies before
    /// the back face on every ray), so the low bit is "inside".
    pub fn pipeline(&self, device: &wgpu::Device, d: &VolumePipelineDesc) -> wgpu::RenderPipeline {
        use wgpu::{CompareFunction as C, Face};
        assert!(
            d.shading == Shading::PerPixel || self.samples > 1,
            "per-sample volume pipelines need MSAA"
        );
        // Reversed-Z (`crate::depth`): a front face in front of the scene surface, a back
        // face behind it.
        let (cull, compare, vertex_entry) = match d.draw {
            VolumeDraw::Front => (Some(Face::Back), crate::depth::NEARER_OR_EQUAL, "vs_volume"),
            VolumeDraw::Back => (
                Some(Face::Front),
                crate::depth::FARTHER_OR_EQUAL,
                "vs_volume",
            ),
            VolumeDraw::Full => (None, C::Always, "vs_volume_fullscreen"),
            VolumeDraw::StencilMark => (None, crate::depth::NEARER_OR_EQUAL, "vs_volume"),
            VolumeDraw::StencilLight => (Some(Face::Front), C::Always, "vs_volume"),
        };
        let stencil = volume_stencil(d.draw);
        let targets = if d.draw == VolumeDraw::StencilMark {
            no_color(d.color_targets)
        } else {
            d.color_targets.to_vec()
        };
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(d.label),
            bind_group_layouts: d.layouts,
            immediate_size: 0,
        });
        const POSITION: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![0 => Float32x3];
        const LIGHT: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![1 => Uint32];
        let constants = self.constants();
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(d.label),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: d.module,
                entry_point: Some(vertex_entry),
                compilation_options: Default::default(),
                buffers: &[
                    Some(wgpu::VertexBufferLayout {
                        array_stride: 12,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &POSITION,
                    }),
                    Some(wgpu::VertexBufferLayout {
                        array_stride: 4,
                        step_mode: wgpu::VertexStepMode::Instance,
                        attributes: &LIGHT,
                    }),
                ],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: cull,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: self.depth_format,
                depth_write_enabled: Some(false),
                depth_compare: Some(compare),
                stencil,
                bias: Default::default(),
            }),
            multisample: self.multisample(),
            fragment: Some(wgpu::FragmentState {
                module: d.module,
                entry_point: Some(d.fragment_entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    ..Default::default()
                },
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    /// A full-screen draw after the depth copy (no depth test): shading the pixels or edge
    /// samples of its `Shading`, or marking the edges (see [`Fullscreen`]).
    pub fn fullscreen_pipeline(
        &self,
        device: &wgpu::Device,
        d: &FullscreenVolumeDesc,
    ) -> wgpu::RenderPipeline {
        use wgpu::{CompareFunction as C, StencilFaceState, StencilOperation as Op};
        let (face, read_mask, write_mask) = match d.kind {
            Fullscreen::Shade(_) => (edge_test(), EDGE_STENCIL, 0),
            Fullscreen::MarkEdges => (
                StencilFaceState {
                    compare: C::Always,
                    fail_op: Op::Keep,
                    depth_fail_op: Op::Keep,
                    pass_op: Op::Replace,
                },
                EDGE_STENCIL,
                EDGE_STENCIL,
            ),
        };
        let targets = match d.kind {
            Fullscreen::Shade(_) => d.color_targets.to_vec(),
            Fullscreen::MarkEdges => no_color(d.color_targets),
        };
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(d.label),
            bind_group_layouts: d.layouts,
            immediate_size: 0,
        });
        let constants = self.constants();
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(d.label),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: d.module,
                entry_point: Some("vs_fullscreen_volume"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: self.depth_format,
                depth_write_enabled: Some(false),
                depth_compare: Some(C::Always),
                stencil: wgpu::StencilState {
                    front: face,
                    back: face,
                    read_mask,
                    write_mask,
                },
                bias: Default::default(),
            }),
            multisample: self.multisample(),
            fragment: Some(wgpu::FragmentState {
                module: d.module,
                entry_point: Some(d.fragment_entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    ..Default::default()
                },
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    fn multisample(&self) -> wgpu::MultisampleState {
        wgpu::MultisampleState {
            count: self.samples,
            ..Default::default()
        }
    }

    /// With MSAA, lighting fragments count into the per-pixel counts after the frame counters (`lit_out.wgsl`).
    fn constants(&self) -> Vec<(&'static str, f64)> {
        if self.samples > 1 {
            vec![(crate::shader::overrides::MULTISAMPLED, 1.0)]
        } else {
            Vec::new()
        }
    }

    /// The full-screen pipeline that copies the scene depth into [`Self::depth`], sample by
    /// sample with MSAA; the colour targets must be the pass's (nothing is written to them).
    pub fn copy_pipeline(
        &self,
        device: &wgpu::Device,
        module: &wgpu::ShaderModule,
        scene_layout: &wgpu::BindGroupLayout,
        color_targets: &[Option<wgpu::ColorTargetState>],
    ) -> wgpu::RenderPipeline {
        let targets = no_color(color_targets);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("depth copy"),
            bind_group_layouts: &[Some(scene_layout), Some(&self.copy_layout)],
            immediate_size: 0,
        });
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("depth copy"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_copy_depth"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: self.depth_format,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: self.multisample(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some("fs_copy_depth"),
                compilation_options: Default::default(),
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    pub fn copy_bind_group(
        &self,
        device: &wgpu::Device,
        scene_depth: &wgpu::TextureView,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("depth copy source"),
            layout: &self.copy_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(scene_depth),
            }],
        })
    }

    /// The first draw of a volume pass: copy the scene depth into [`Self::depth`] with the
    /// pass's `copy_pipeline` and the source from `copy_bind_group`; binds group 0.
    pub fn draw_depth_copy(
        &self,
        pass: &mut wgpu::RenderPass,
        scene_bind_group: &wgpu::BindGroup,
        pipeline: &wgpu::RenderPipeline,
        source: &wgpu::BindGroup,
    ) {
        pass.set_bind_group(0, scene_bind_group, &[]);
        pass.set_pipeline(pipeline);
        pass.set_bind_group(1, source, &[]);
        pass.draw(0..3, 0..1);
    }

    /// Depth-stencil attachment for a volume pass: cleared, then filled by the copy draw.
    pub fn attachment(&self) -> wgpu::RenderPassDepthStencilAttachment<'_> {
        self.attachment_with(
            wgpu::LoadOp::Clear(crate::depth::CLEAR),
            wgpu::LoadOp::Clear(0),
        )
    }

    /// As [`Self::attachment`], the copy and its edge bits kept for a later pass (the light
    /// pre-pass's shading pass, [`Self::loaded_attachment`]).
    pub fn kept_attachment(&self) -> wgpu::RenderPassDepthStencilAttachment<'_> {
        let mut a = self.attachment();
        for store in [
            &mut a.depth_ops.as_mut().expect("depth").store,
            &mut a.stencil_ops.as_mut().expect("stencil").store,
        ] {
            *store = wgpu::StoreOp::Store;
        }
        a
    }

    /// The copy as an earlier pass left it, kept for the next (the passes between re-used
    /// shadow maps).
    pub fn reloaded_attachment(&self) -> wgpu::RenderPassDepthStencilAttachment<'_> {
        let mut a = self.loaded_attachment();
        for store in [
            &mut a.depth_ops.as_mut().expect("depth").store,
            &mut a.stencil_ops.as_mut().expect("stencil").store,
        ] {
            *store = wgpu::StoreOp::Store;
        }
        a
    }

    /// The copy as a [`Self::kept_attachment`] pass left it, read-only.
    pub fn loaded_attachment(&self) -> wgpu::RenderPassDepthStencilAttachment<'_> {
        self.attachment_with(wgpu::LoadOp::Load, wgpu::LoadOp::Load)
    }

    fn attachment_with(
        &self,
        depth: wgpu::LoadOp<f32>,
        stencil: wgpu::LoadOp<u32>,
    ) -> wgpu::RenderPassDepthStencilAttachment<'_> {
        wgpu::RenderPassDepthStencilAttachment {
            view: &self.depth,
            depth_ops: Some(wgpu::Operations {
                load: depth,
                store: wgpu::StoreOp::Discard,
            }),
            stencil_ops: Some(wgpu::Operations {
                load: stencil,
                store: wgpu::StoreOp::Discard,
            }),
        }
    }

    /// The depth-stencil state of a geometry pass over the copy (the light pre-pass's
    /// shading pass): the scene's surface test ([`crate::depth::SURFACE`]: the copy holds
    /// the scene depth, bit for bit in [`volume_depth_format`]'s float format), no writes,
    /// and the edge bit equal to the reference's (a draw's [`Shading::edge_bit`]).
    pub fn surface_test(&self) -> wgpu::DepthStencilState {
        wgpu::DepthStencilState {
            format: self.depth_format,
            depth_write_enabled: Some(false),
            depth_compare: Some(crate::depth::SURFACE),
            stencil: wgpu::StencilState {
                front: edge_test(),
                back: edge_test(),
                read_mask: EDGE_STENCIL,
                write_mask: 0,
            },
            bias: Default::default(),
        }
    }

    fn bind(&self, pass: &mut wgpu::RenderPass) {
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_vertex_buffer(1, self.instances.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
    }

    /// Draw the instances `i` of class `slot`: its sphere volumes with the sphere mesh, its cone
    /// volumes with the cone mesh.
    fn draw_instances(&self, pass: &mut wgpu::RenderPass, slot: usize, i: Range<u32>) {
        let split = (self.ranges[slot].start + self.cones_from[slot]).clamp(i.start, i.end);
        if i.start < split {
            pass.draw_indexed(self.sphere.clone(), 0, i.start..split);
        }
        if split < i.end {
            pass.draw_indexed(self.cone.clone(), self.cone_base, split..i.end);
        }
    }

    /// Mark the MSAA edge pixels in the stencil with `pipeline` (a [`Fullscreen::MarkEdges`]
    /// pipeline; its bind groups set).
    pub fn mark_edges(&self, pass: &mut wgpu::RenderPass, pipeline: &wgpu::RenderPipeline) {
        pass.set_pipeline(pipeline);
        pass.set_stencil_reference(EDGE_STENCIL);
        pass.draw(0..3, 0..1);
    }

    /// A full-screen shading draw of the pixels or edge samples of `shading` with `pipeline`
    /// (a [`Fullscreen::Shade`] pipeline; its bind groups set).
    pub fn draw_fullscreen(
        &self,
        pass: &mut wgpu::RenderPass,
        pipeline: &wgpu::RenderPipeline,
        shading: Shading,
    ) {
        pass.set_pipeline(pipeline);
        pass.set_stencil_reference(shading.edge_bit());
        pass.draw(0..3, 0..1);
    }

    /// Draw every light of class `Front`, `Back` or `Full` with the bound pipeline, made for
    /// `shading`.
    pub fn draw(&self, pass: &mut wgpu::RenderPass, draw: VolumeDraw, shading: Shading) {
        self.bind(pass);
        pass.set_stencil_reference(stencil_reference(draw, shading));
        match draw {
            VolumeDraw::Front => self.draw_instances(pass, 0, self.ranges[0].clone()),
            VolumeDraw::Back => self.draw_instances(pass, 1, self.ranges[1].clone()),
            VolumeDraw::Full => pass.draw(0..3, self.ranges[2].clone()),
            _ => panic!("stencil lights are drawn one at a time with draw_stencil_light"),
        }
    }

    /// Draw the `k`-th light of the stencil class with the bound pipeline: its marks
    /// (`StencilMark`) or its light (`StencilLight`, made for `shading`).
    pub fn draw_stencil_light(
        &self,
        pass: &mut wgpu::RenderPass,
        k: u32,
        draw: VolumeDraw,
        shading: Shading,
    ) {
        self.bind(pass);
        pass.set_stencil_reference(stencil_reference(draw, shading));
        let i = self.ranges[3].start + k;
        self.draw_instances(pass, 3, i..i + 1);
    }
}
