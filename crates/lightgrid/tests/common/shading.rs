//! The CPU shading reference `forward` is checked against (`tests/shading_reference.rs`) and
//! that gates re-blessing the golden images (`tests/reference.rs`): a ray caster and the light
//! function written here from the papers' formulas and the shaders' documented contract, not
//! generated from the WGSL.

use glam::{DVec3, Vec2, Vec3, Vec4};
use lightgrid::consts::{
    EXPOSURE, MATERIAL_SHADER_CAR_PAINT, MATERIAL_SHADER_RIM, POINT_LIGHT_COS, SCENE_AMBIENT,
    TEXTURE_SLOT_BASE, TEXTURE_SLOT_EMISSIVE, TEXTURE_SLOT_METAL_ROUGH, TEXTURE_SLOT_NORMAL,
    TEXTURE_SLOT_OCCLUSION, WRAP_CLAMP, WRAP_MIRROR,
};
use lightgrid::scene::{Brdf, Light, LightUnits, Material, Scene, Spot, SpotCone};
use lightgrid::{RenderSettings, Renderer};

/// The light model a `forward` variant implements.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Model {
    /// `forward`: diffuse and specular per light.
    Full,
    /// `forward_mono`: the light pre-pass's compromise, the specular summed as luminance and
    /// given the diffuse irradiance's colour (deferred-shading-vs-deferred-lighting).
    Mono,
    /// `forward_mono_albedo`: the specular albedo reduced to its luminance in every channel.
    MonoAlbedo,
}

impl Model {
    pub fn pipeline(self) -> &'static str {
        match self {
            Model::Full => "forward",
            Model::Mono => "forward_mono",
            Model::MonoAlbedo => "forward_mono_albedo",
        }
    }
}

/// A triangle of the frame, camera-relative (the renderer's space), in drawing order.
struct Triangle {
    p: [DVec3; 3],
    n: [Vec3; 3],
    material: usize,
    transparent: bool,
    /// Texture coordinate sets 0 and 1, vertex colour and tangent (xyz, bitangent sign) per
    /// corner, as the vertex buffer holds them.
    uv: [[Vec2; 3]; 2],
    color: [Vec4; 3],
    tangent: [Vec4; 3],
}

/// A material as one sample reads it: glTF's rules applied to its textures and vertex colour
/// (the base colour multiplies the diffuse, ambient and alpha; metallic-roughness re-derives
/// diffuse, F0 and the exponent; the normal texture bends the normal in the tangent frame;
/// occlusion darkens the ambient term; the emissive texture multiplies the emissive colour).
struct Sampled {
    diffuse: Vec3,
    specular: Vec3,
    shininess: f32,
    emissive: Vec3,
    ambient: Vec3,
    alpha: f32,
    /// The shading normal, facing the ray's side.
    normal: Vec3,
    /// Every texel value read (linear), to find samples near a texture's edge.
    texels: Vec<Vec4>,
}

/// A ray's meeting with a triangle: distance along the ray and the barycentric weights.
#[derive(Clone, Copy)]
pub struct Hit {
    pub t: f64,
    triangle: usize,
    w: [f64; 3],
}

fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// The frame as the reference sees it: triangles, lights and the camera, all camera-relative.
pub struct Frame<'s> {
    scene: &'s Scene,
    triangles: Vec<Triangle>,
    lights: Vec<Light>,
    /// Camera basis: right, up, forward (world orientation).
    basis: [DVec3; 3],
    tan_half_fov: f64,
    near: f64,
    size: (u32, u32),
    /// The BRDF shaded with, and what each light's colour × intensity is multiplied by.
    brdf: Brdf,
    light_scale: f32,
    /// `--shadows rays` with every light casting: a light reaches a surface point only where
    /// the segment between them crosses no opaque triangle (transparent and alpha-tested ones
    /// cast none, as `lightgrid::shadows` says).
    pub shadows: bool,
}

impl<'s> Frame<'s> {
    /// The frame as `forward` renders it with the scene's own BRDF (`--brdf auto`).
    pub fn new(scene: &'s Scene, frame: u32, size: (u32, u32)) -> Self {
        Self::with_brdf(scene, frame, size, scene.lighting.brdf)
    }

    pub fn with_brdf(scene: &'s Scene, frame: u32, size: (u32, u32), brdf: Brdf) -> Self {
        let state = scene.frame(frame);
        let eye = state.camera.eye;
        let g = scene.geometry(&state);
        let triangles = g
            .indices
            .chunks_exact(3)
            .enumerate()
            .map(|(k, t)| {
                let v = [t[0], t[1], t[2]].map(|i| g.vertices[i as usize]);
                Triangle {
                    // As the vertex stage: world minus the eye in f32.
                    p: v.map(|v| (Vec3::from(v.position) - eye).as_dvec3()),
                    n: v.map(|v| Vec3::from(v.normal)),
                    material: v[0].material as usize,
                    transparent: k * 3 >= g.opaque_indices,
                    uv: [v.map(|v| Vec2::from(v.uv)), v.map(|v| Vec2::from(v.uv1))],
                    color: v.map(|v| Vec4::from(v.color.map(|c| f32::from(c) / 255.0))),
                    tangent: v
                        .map(|v| Vec4::from(v.tangent.map(|c| (f32::from(c) / 32767.0).max(-1.0)))),
                }
            })
            .collect();
        let lights = state
            .lights
            .iter()
            .map(|l| Light {
                position: l.position - eye,
                ..*l
            })
            .collect();
        let c = state.camera;
        let forward = (c.target - c.eye).as_dvec3().normalize();
        let right = forward.cross(c.up.as_dvec3()).normalize();
        let up = right.cross(forward);
        Frame {
            scene,
            triangles,
            lights,
            basis: [right, up, forward],
            tan_half_fov: (f64::from(c.fov_y) * 0.5).tan(),
            near: f64::from(c.near),
            size,
            brdf,
            light_scale: light_scale(scene, brdf),
            shadows: false,
        }
    }

    /// Does an opaque triangle (not alpha tested) cross the segment from `from` to `to`
    /// (camera-relative), strictly between its ends? In f64, every triangle tested.
    pub fn blocked(&self, from: DVec3, to: DVec3) -> bool {
        let d = to - from;
        let end = 1.0 - 1e-6;
        self.triangles.iter().any(|tri| {
            if tri.transparent || self.scene.materials[tri.material].alpha_cutoff.is_some() {
                return false;
            }
            let [a, b, c] = tri.p;
            let (e1, e2) = (b - a, c - a);
            let p = d.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-18 {
                return false;
            }
            let s = (from - a) / det;
            let u = s.dot(p);
            let q = s.cross(e1);
            let v = d.dot(q);
            let t = e2.dot(q);
            u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 1e-6 && t < end
        })
    }

    /// Per light, is it blocked from the surface at `hit` (false where it would not light it)?
    fn shadowed(&self, hit: &Hit, ray: DVec3) -> Vec<bool> {
        let (position, normal) = self.surface(hit, ray);
        self.lights
            .iter()
            .map(|light| {
                self.contribution(light, position, normal).is_some()
                    && self.blocked(position.as_dvec3(), light.position.as_dvec3())
            })
            .collect()
    }

    /// The hit's camera-relative position and its normal facing the ray's side.
    fn surface(&self, hit: &Hit, ray: DVec3) -> (Vec3, Vec3) {
        let tri = &self.triangles[hit.triangle];
        let at = |v: [DVec3; 3]| v[0] * hit.w[0] + v[1] * hit.w[1] + v[2] * hit.w[2];
        let position = at(tri.p).as_vec3();
        let mut normal = at(tri.n.map(Vec3::as_dvec3)).normalize().as_vec3();
        // Two-sided: a triangle wound clockwise as seen is a back face, lit from its side.
        let [a, b, c] = tri.p;
        if (b - a).cross(c - a).dot(ray) > 0.0 {
            normal = -normal;
        }
        (position, normal)
    }

    /// Does the ray see the hit's triangle from its back (wound clockwise as seen)?
    fn back_face(&self, hit: &Hit, ray: DVec3) -> bool {
        let [a, b, c] = self.triangles[hit.triangle].p;
        (b - a).cross(c - a).dot(ray) > 0.0
    }

    /// The material at `hit` as the sample reads it ([`Sampled`]).
    fn sampled(&self, hit: &Hit, ray: DVec3) -> Sampled {
        let tri = &self.triangles[hit.triangle];
        let m = self.material(hit);
        let w = hit.w.map(|x| x as f32);
        let at2 = |c: [Vec2; 3]| c[0] * w[0] + c[1] * w[1] + c[2] * w[2];
        let at4 = |c: [Vec4; 3]| c[0] * w[0] + c[1] * w[1] + c[2] * w[2];
        let uv = [at2(tri.uv[0]), at2(tri.uv[1])];
        let mut texels = Vec::new();
        let mut read = |slot: u32, texture: Option<u32>| match texture {
            None => Vec4::ONE,
            Some(t) => {
                let v = self.texel(m, slot, t, uv);
                texels.push(v);
                v
            }
        };
        let base = read(TEXTURE_SLOT_BASE, m.texture) * at4(tri.color);
        let n = (tri.n[0] * w[0] + tri.n[1] * w[1] + tri.n[2] * w[2]).normalize();
        let mut normal = n;
        if let Some((t, scale)) = m.normal_texture {
            // glTF §3.9.3: the texel's x and y (times the scale) along the tangent and the
            // bitangent, z along the normal.
            let tn = (read(TEXTURE_SLOT_NORMAL, Some(t)).truncate() * 2.0 - 1.0)
                * Vec3::new(scale, scale, 1.0);
            let tg = at4(tri.tangent);
            let tangent = tg.truncate() - n * n.dot(tg.truncate());
            if tangent.length_squared() >= 1e-12 {
                let u = tangent.normalize();
                let v = n.cross(u) * if tg.w < 0.0 { -1.0 } else { 1.0 };
                let mapped = u * tn.x + v * tn.y + n * tn.z;
                if mapped.length_squared() > 1e-12 {
                    normal = mapped.normalize();
                }
            }
        }
        if self.back_face(hit, ray) {
            normal = -normal;
        }
        let colour = base.truncate();
        let (mut diffuse, mut specular, mut shininess) =
            (m.diffuse * colour, m.specular, m.shininess);
        if let Some(mr) = m.metallic_roughness {
            // glTF Appendix B: B metallic, G roughness; α = roughness², and the exponent whose
            // Blinn-Phong lobe matches it, 2/α² − 2.
            let t = read(TEXTURE_SLOT_METAL_ROUGH, mr.texture);
            let metallic = (mr.metallic * t.z).clamp(0.0, 1.0);
            let roughness = (mr.roughness * t.y).clamp(0.0, 1.0);
            let c = mr.base * colour;
            let alpha = (roughness * roughness).max(1e-3);
            diffuse = c * (1.0 - metallic);
            specular = Vec3::splat(0.04).lerp(c, metallic);
            // README: the exponent from just above 0 (roughness 1) to 2048 (roughness 0.18).
            shininess = (2.0 / (alpha * alpha) - 2.0).clamp(1e-3, 2048.0);
        }
        let emissive = m.emissive * read(TEXTURE_SLOT_EMISSIVE, m.emissive_texture).truncate();
        let mut ambient = m.ambient * colour;
        if let Some((t, strength)) = m.occlusion_texture {
            let o = read(TEXTURE_SLOT_OCCLUSION, Some(t)).x;
            ambient *= 1.0 + strength * (o - 1.0);
        }
        Sampled {
            diffuse,
            specular,
            shininess,
            emissive,
            ambient,
            alpha: m.alpha * base.w,
            normal,
            texels,
        }
    }

    /// Texture `texture` of `m`'s slot `slot` at the sample's coordinates, linear RGBA, as a
    /// glTF sampler reads it at the base level: the slot's coordinate set and transform, its
    /// wrapping (repeat, clamp to edge, mirrored repeat: on the texel indices) and bilinear
    /// or nearest magnification, the sRGB-encoded texels decoded first.
    fn texel(&self, m: &Material, slot: u32, texture: u32, uv: [Vec2; 2]) -> Vec4 {
        let t = &self.scene.textures[texture as usize];
        let p = self.texture_coordinates(m, slot, uv);
        let wrap = (m.wraps >> (4 * slot)) & 15;
        let index = |i: i64, n: u32, mode: u32| -> u32 {
            let n = i64::from(n);
            let i = match mode {
                WRAP_CLAMP => i.clamp(0, n - 1),
                WRAP_MIRROR => {
                    let k = i.rem_euclid(2 * n);
                    if k >= n {
                        2 * n - 1 - k
                    } else {
                        k
                    }
                }
                _ => i.rem_euclid(n),
            };
            i as u32
        };
        let fetch = |x: i64, y: i64| {
            let (x, y) = (index(x, t.width, wrap & 3), index(y, t.height, wrap >> 2));
            let o = 4 * (y * t.width + x) as usize;
            let decode = |c: u8| {
                let c = f32::from(c) / 255.0;
                if c <= 0.04045 {
                    c / 12.92
                } else {
                    ((c + 0.055) / 1.055).powf(2.4)
                }
            };
            let px = &t.rgba[o..o + 4];
            Vec4::new(
                decode(px[0]),
                decode(px[1]),
                decode(px[2]),
                f32::from(px[3]) / 255.0,
            )
        };
        let x = f64::from(p.x) * f64::from(t.width);
        let y = f64::from(p.y) * f64::from(t.height);
        if (m.nearest >> slot) & 1 != 0 {
            return fetch(x.floor() as i64, y.floor() as i64);
        }
        let (x, y) = (x - 0.5, y - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = fetch(x0, y0).lerp(fetch(x0 + 1, y0), fx);
        let bottom = fetch(x0, y0 + 1).lerp(fetch(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }

    /// The coordinates slot `slot` of `m` reads: its set, through its `KHR_texture_transform`.
    fn texture_coordinates(&self, m: &Material, slot: u32, uv: [Vec2; 2]) -> Vec2 {
        let set = ((m.uv_sets >> slot) & 1) as usize;
        m.uv_transforms[slot as usize].transform_point2(uv[set])
    }

    /// Is some texture of the hit's material minified at pixel (x, y) (a pixel step moves
    /// its coordinates by more than a texel), so the GPU would read a smaller mip level than
    /// the one the reference reads?
    fn minified(&self, hit: &Hit, x: f64, y: f64) -> bool {
        let m = self.material(hit);
        let tri = &self.triangles[hit.triangle];
        let uv_at = |x: f64, y: f64| {
            let w = self
                .plane_weights(hit.triangle, self.ray(x, y))
                .map(|x| x as f32);
            [0, 1].map(|s| tri.uv[s][0] * w[0] + tri.uv[s][1] * w[1] + tri.uv[s][2] * w[2])
        };
        let here = uv_at(x, y);
        let slots = [
            (TEXTURE_SLOT_BASE, m.texture),
            (TEXTURE_SLOT_EMISSIVE, m.emissive_texture),
            (
                TEXTURE_SLOT_METAL_ROUGH,
                m.metallic_roughness.and_then(|r| r.texture),
            ),
            (TEXTURE_SLOT_NORMAL, m.normal_texture.map(|t| t.0)),
            (TEXTURE_SLOT_OCCLUSION, m.occlusion_texture.map(|t| t.0)),
        ];
        [uv_at(x + 1.0, y), uv_at(x, y + 1.0)].iter().any(|next| {
            slots.iter().any(|&(slot, texture)| {
                texture.is_some_and(|t| {
                    let t = &self.scene.textures[t as usize];
                    let step = self.texture_coordinates(m, slot, *next)
                        - self.texture_coordinates(m, slot, here);
                    let texels = step * Vec2::new(t.width as f32, t.height as f32);
                    texels.abs().max_element() > 1.0
                })
            })
        })
    }

    /// The barycentric weights of where the ray meets the triangle's plane (inside or not).
    fn plane_weights(&self, triangle: usize, d: DVec3) -> [f64; 3] {
        let [a, b, c] = self.triangles[triangle].p;
        let (e1, e2) = (b - a, c - a);
        let p = d.cross(e2);
        let s = -a / e1.dot(p);
        let u = s.dot(p);
        let v = d.dot(s.cross(e1));
        [1.0 - u - v, u, v]
    }

    /// The light's direction, squared distance, n·l and cone factor at the point, where it
    /// lights it (None outside its range, behind the surface or outside its cone).
    fn contribution(
        &self,
        light: &Light,
        position: Vec3,
        normal: Vec3,
    ) -> Option<(Vec3, f32, f32, f32)> {
        let to_light = light.position - position;
        let dist_sq = to_light.length_squared();
        if dist_sq >= light.range * light.range {
            return None;
        }
        let l = to_light / dist_sq.sqrt();
        let n_dot_l = normal.dot(l);
        let cone = match light.spot {
            None => 1.0,
            Some(Spot {
                direction,
                cos_inner,
                cos_outer,
            }) => {
                assert!(cos_outer > POINT_LIGHT_COS);
                let t = ((-l.dot(direction) - cos_outer) / (cos_inner - cos_outer)).clamp(0.0, 1.0);
                match self.scene.lighting.spot_cone {
                    // The papers' smoothstep; KHR_lights_punctual's square of the ramp.
                    SpotCone::Smoothstep => t * t * (3.0 - 2.0 * t),
                    SpotCone::Squared => t * t,
                }
            }
        };
        (n_dot_l > 0.0 && cone > 0.0).then_some((l, dist_sq, n_dot_l, cone))
    }

    /// Which lights are blocked from each surface a pixel ray meets (the opaque one, then the
    /// glass): a shadow's edge runs through the pixel where the rays around its centre differ.
    pub fn shadow_key(&self, x: f64, y: f64) -> Option<Vec<Vec<bool>>> {
        let d = self.ray(x, y);
        let (opaque, glass, _) = self.seen(x, y)?;
        Some(
            std::iter::once(&opaque)
                .chain(&glass)
                .map(|h| self.shadowed(h, d))
                .collect(),
        )
    }

    /// The ray through framebuffer position (x, y) (pixels, y down).
    pub fn ray(&self, x: f64, y: f64) -> DVec3 {
        let (w, h) = (f64::from(self.size.0), f64::from(self.size.1));
        let aspect = w / h;
        let sx = (x / w * 2.0 - 1.0) * self.tan_half_fov * aspect;
        let sy = (1.0 - y / h * 2.0) * self.tan_half_fov;
        let [r, u, f] = self.basis;
        (r * sx + u * sy + f).normalize()
    }

    /// Every triangle the ray meets beyond the near plane (Möller-Trumbore, in f64).
    fn hits(&self, d: DVec3) -> Vec<Hit> {
        let mut out = Vec::new();
        for (i, tri) in self.triangles.iter().enumerate() {
            let [a, b, c] = tri.p;
            let (e1, e2) = (b - a, c - a);
            let p = d.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-18 {
                continue;
            }
            let s = -a / det;
            let u = s.dot(p);
            let q = s.cross(e1);
            let v = d.dot(q);
            if u < 0.0 || v < 0.0 || u + v > 1.0 {
                continue;
            }
            let t = e2.dot(q);
            if t * d.dot(self.basis[2]) > self.near {
                out.push(Hit {
                    t,
                    triangle: i,
                    w: [1.0 - u - v, u, v],
                });
            }
        }
        out
    }

    pub fn material(&self, hit: &Hit) -> &Material {
        &self.scene.materials[self.triangles[hit.triangle].material]
    }

    /// Does the material's alpha test drop the fragment (glTF MASK), its alpha the material's
    /// times the base colour's texel and vertex colour?
    fn discarded(&self, hit: &Hit, ray: DVec3) -> bool {
        let m = self.material(hit);
        m.alpha_cutoff
            .is_some_and(|c| self.sampled(hit, ray).alpha < c)
    }

    /// What a pixel's centre ray sees: the nearest opaque surface and the glass in front of
    /// it, in drawing order. None where there is no opaque surface.
    pub fn seen(&self, x: f64, y: f64) -> Option<(Hit, Vec<Hit>, f64)> {
        let ray = self.ray(x, y);
        let mut hits = self.hits(ray);
        hits.retain(|h| !self.discarded(h, ray));
        let opaque = hits
            .iter()
            .filter(|h| !self.triangles[h.triangle].transparent)
            .min_by(|a, b| a.t.total_cmp(&b.t))
            .copied()?;
        let second = hits
            .iter()
            .filter(|h| !self.triangles[h.triangle].transparent && h.triangle != opaque.triangle)
            .map(|h| h.t)
            .fold(f64::INFINITY, f64::min);
        let mut glass: Vec<Hit> = hits
            .into_iter()
            .filter(|h| self.triangles[h.triangle].transparent && h.t < opaque.t)
            .collect();
        glass.sort_by_key(|h| h.triangle);
        Some((opaque, glass, second))
    }

    /// The pixel's reference colour, or None where its surface is ambiguous: an edge (a ray a
    /// third of a pixel off the centre meets other triangles), a second surface within 0.1 %
    /// of the depth, a texture's edge (a texel read a third of a pixel off differs by more
    /// than 0.01) or a minified texture (the GPU reads a smaller mip level; the reference
    /// reads the base level).
    pub fn reference(&self, px: u32, py: u32, model: Model) -> Option<(Vec3, bool)> {
        let (x, y) = (f64::from(px) + 0.5, f64::from(py) + 0.5);
        let (opaque, glass, second) = self.seen(x, y)?;
        if second < opaque.t * 1.001 {
            return None;
        }
        let key = |o: &Hit, g: &[Hit]| {
            let mut k = vec![o.triangle];
            k.extend(g.iter().map(|h| h.triangle));
            k
        };
        let here = key(&opaque, &glass);
        for (dx, dy) in [(-1.0, 0.0), (1.0, 0.0), (0.0, -1.0), (0.0, 1.0)] {
            let (o, g, _) = self.seen(x + dx / 3.0, y + dy / 3.0)?;
            if key(&o, &g) != here {
                return None;
            }
        }
        let d = self.ray(x, y);
        for h in std::iter::once(&opaque).chain(&glass) {
            if self.material(h).textures().next().is_none() {
                continue;
            }
            if self.minified(h, x, y) {
                return None;
            }
            let centre = self.sampled(h, d).texels;
            for (dx, dy) in [(-1.0, 0.0), (1.0, 0.0), (0.0, -1.0), (0.0, 1.0)] {
                let (x, y) = (x + dx / 3.0, y + dy / 3.0);
                let ray = self.ray(x, y);
                let w = self.plane_weights(h.triangle, ray);
                let near = self.sampled(&Hit { w, ..*h }, ray).texels;
                let differ = |(a, b): (&Vec4, &Vec4)| (*a - *b).abs().max_element() > 0.01;
                if centre.iter().zip(&near).any(differ) {
                    return None;
                }
            }
        }
        let keys = if self.shadows {
            let centre = self.shadow_key(x, y)?;
            for (dx, dy) in [(-1.0, 0.0), (1.0, 0.0), (0.0, -1.0), (0.0, 1.0)] {
                if self.shadow_key(x + dx / 3.0, y + dy / 3.0)? != centre {
                    return None;
                }
            }
            centre
        } else {
            vec![vec![false; self.lights.len()]; 1 + glass.len()]
        };
        let (mut colour, lit) = self.shade(&opaque, d, model, &keys[0]);
        let mut any_lit = lit;
        for (h, blocked) in glass.iter().zip(&keys[1..]) {
            let (c, lit) = self.shade(h, d, model, blocked);
            let a = self.sampled(h, d).alpha;
            colour = c * a + colour * (1.0 - a);
            any_lit |= lit;
        }
        Some((colour, any_lit))
    }

    /// The surface at `hit` lit by every light not `blocked` (linear HDR), and whether any
    /// light reached it.
    fn shade(&self, hit: &Hit, ray: DVec3, model: Model, blocked: &[bool]) -> (Vec3, bool) {
        let (position, _) = self.surface(hit, ray);
        let m = self.material(hit);
        let s = self.sampled(hit, ray);
        let normal = s.normal;
        let view = -position.normalize();
        let (shader, paint, power) = m.shader.gpu();
        let grazing = (1.0 - normal.dot(view).clamp(0.0, 1.0)).powf(power);
        let diffuse = match shader {
            MATERIAL_SHADER_CAR_PAINT => s.diffuse.lerp(paint, grazing),
            MATERIAL_SHADER_RIM => s.diffuse + paint * grazing,
            _ => s.diffuse,
        };
        let specular = match model {
            Model::MonoAlbedo => Vec3::splat(luminance(s.specular)),
            _ => s.specular,
        };
        let (mut e_diffuse, mut e_specular, mut e_specular_lum) = (Vec3::ZERO, Vec3::ZERO, 0.0);
        let mut lit = false;
        for (light, &blocked) in self.lights.iter().zip(blocked) {
            let Some((l, dist_sq, n_dot_l, cone)) = self.contribution(light, position, normal)
            else {
                continue;
            };
            if blocked {
                continue;
            }
            let e = light.color
                * (light.intensity * self.light_scale)
                * (falloff(self.scene.lighting.units, dist_sq, light.range) * cone * n_dot_l);
            let (d, s) = match self.brdf {
                Brdf::Phong => {
                    let h = (l + view).normalize();
                    (e, e * normal.dot(h).max(0.0).powf(s.shininess))
                }
                Brdf::Ggx => ggx(normal, view, l, n_dot_l, s.shininess, specular, e),
            };
            e_diffuse += d;
            e_specular += s;
            e_specular_lum += luminance(s);
            lit |= d.max_element() > 1e-3;
        }
        let specular_light = match model {
            // Grey where the diffuse irradiance is next to nothing beside the specular (its
            // colour would be rounding: 1 − F of a white metal).
            Model::Mono if luminance(e_diffuse) <= (1e-6 * e_specular_lum).max(1e-8) => {
                Vec3::splat(e_specular_lum)
            }
            Model::Mono => e_diffuse * (e_specular_lum / luminance(e_diffuse)),
            _ => e_specular,
        };
        let base = s.emissive + s.ambient * SCENE_AMBIENT;
        // GGX's Fresnel holds the specular colour; Blinn-Phong multiplies by it.
        let specular_albedo = match self.brdf {
            Brdf::Phong => specular,
            Brdf::Ggx => Vec3::ONE,
        };
        (
            base + e_diffuse * diffuse + specular_light * specular_albedo,
            lit,
        )
    }
}

/// What a light's colour × intensity is multiplied by: the scene's exposure, and π between
/// the papers' units (a white Blinn-Phong surface's radiance) and GGX's Lambert `c/π`.
pub fn light_scale(scene: &Scene, brdf: Brdf) -> f32 {
    let pi = std::f32::consts::PI;
    let convention = match (scene.lighting.units, brdf) {
        (LightUnits::Papers, Brdf::Phong) | (LightUnits::Photometric, Brdf::Ggx) => 1.0,
        (LightUnits::Papers, Brdf::Ggx) => pi,
        (LightUnits::Photometric, Brdf::Phong) => 1.0 / pi,
    };
    scene.lighting.exposure * convention
}

/// Distance falloff: the papers' window `(1 − d²/r²)²`, or KHR_lights_punctual's
/// `clamp(1 − (d/r)⁴, 0, 1)² / d²` (the squared distance at least 1e-4).
pub fn falloff(units: LightUnits, dist_sq: f32, range: f32) -> f32 {
    let x = dist_sq / (range * range);
    match units {
        LightUnits::Papers => (1.0 - x).clamp(0.0, 1.0).powi(2),
        LightUnits::Photometric => (1.0 - x * x).clamp(0.0, 1.0).powi(2) / dist_sq.max(1e-4),
    }
}

/// glTF 2.0 appendix B, written from its formulas: for irradiance `e` (n·l included) from
/// direction `l`, the diffuse irradiance `e (1 − F) / π` (times the diffuse colour by the
/// caller: the spec's `fresnel_mix`) and the specular `e · F · D · V` with roughness
/// `α = √(2 / (shininess + 2))`:
/// D = α² / (π ((n·h)² (α² − 1) + 1)²),
/// V = 0.5 / (n·l √((n·v)² (1 − α²) + α²) + n·v √((n·l)² (1 − α²) + α²)),
/// F = F0 + (1 − F0)(1 − v·h)⁵.
pub fn ggx(
    n: Vec3,
    v: Vec3,
    l: Vec3,
    n_dot_l: f32,
    shininess: f32,
    f0: Vec3,
    e: Vec3,
) -> (Vec3, Vec3) {
    let pi = std::f32::consts::PI;
    let h = (l + v).normalize();
    let n_dot_v = n.dot(v).clamp(0.0, 1.0);
    let n_dot_h = n.dot(h).clamp(0.0, 1.0);
    let v_dot_h = v.dot(h).clamp(0.0, 1.0);
    let a2 = 2.0 / (shininess.max(0.0) + 2.0);
    let d = a2 / (pi * (n_dot_h * n_dot_h * (a2 - 1.0) + 1.0).powi(2));
    let vis = 0.5
        / (n_dot_l * (n_dot_v * n_dot_v * (1.0 - a2) + a2).sqrt()
            + n_dot_v * (n_dot_l * n_dot_l * (1.0 - a2) + a2).sqrt());
    let f = f0 + (Vec3::ONE - f0) * (1.0 - v_dot_h).powi(5);
    (e * (Vec3::ONE - f) / pi, e * f * (d * vis))
}

/// Linear HDR to the display's 8-bit sRGB: the tone curve, then the sRGB encoding.
pub fn display(c: Vec3) -> [u8; 3] {
    let tone = |x: f32| 1.0 - (-x.max(0.0) * EXPOSURE).exp();
    let srgb = |x: f32| {
        if x <= 0.003_130_8 {
            12.92 * x
        } else {
            1.055 * x.powf(1.0 / 2.4) - 0.055
        }
    };
    c.to_array()
        .map(|x| (srgb(tone(x)).clamp(0.0, 1.0) * 255.0).round() as u8)
}

/// How a frame compared: pixels checked, of them lit, behind glass, and the worst difference.
#[derive(Debug, Default)]
pub struct Checked {
    pub pixels: usize,
    pub lit: usize,
    pub glass: usize,
    pub shaders: [usize; 3],
    /// Pixels where some light was blocked (with shadows).
    pub shadowed: usize,
    pub worst: u8,
}

/// Compare every `step`-th pixel of `image`, `model`'s frame of `f`, with the reference;
/// panics at the first pixel differing by more than one level. `out` counts what was checked.
pub fn compare(f: &Frame, image: &image::RgbaImage, model: Model, step: u32, out: &mut Checked) {
    let (w, h) = f.size;
    for py in (step / 2..h).step_by(step as usize) {
        for px in (step / 2..w).step_by(step as usize) {
            let Some((hdr, lit)) = f.reference(px, py, model) else {
                continue;
            };
            let want = display(hdr);
            let got = image.get_pixel(px, py).0;
            let worst = (0..3).map(|c| got[c].abs_diff(want[c])).max().unwrap();
            assert!(
                worst <= 1,
                "{}, {}: pixel ({px}, {py}) is {:?}, the reference {want:?} (HDR {hdr})",
                f.scene.name,
                model.pipeline(),
                &got[..3]
            );
            if model == Model::Full {
                out.pixels += 1;
                out.lit += usize::from(lit);
                let centre = (f64::from(px) + 0.5, f64::from(py) + 0.5);
                let (opaque, glass, _) = f.seen(centre.0, centre.1).unwrap();
                out.glass += usize::from(!glass.is_empty());
                if f.shadows {
                    let keys = f.shadow_key(centre.0, centre.1).unwrap();
                    out.shadowed += usize::from(keys.iter().flatten().any(|&b| b));
                }
                out.shaders[f.material(&opaque).shader.gpu().0 as usize] += 1;
            }
            out.worst = out.worst.max(worst);
        }
    }
}

/// Render `frame` of `scene` with each model's `forward` and [`compare`] it, with the scene's
/// own BRDF.
pub fn check(
    ctx: &lightgrid::gpu::GpuContext,
    scene: &Scene,
    frame: u32,
    size: (u32, u32),
    step: u32,
) -> Checked {
    check_brdf(ctx, scene, frame, size, step, None)
}

/// [`check`] with `--brdf` `brdf` (`None`: auto, the scene's own).
pub fn check_brdf(
    ctx: &lightgrid::gpu::GpuContext,
    scene: &Scene,
    frame: u32,
    size: (u32, u32),
    step: u32,
    brdf: Option<Brdf>,
) -> Checked {
    let settings = RenderSettings {
        brdf,
        ..RenderSettings::default()
    };
    check_with(ctx, scene, frame, size, step, settings)
}

/// [`check`] with `settings`' BRDF and shadows (every light casting; the reference casts rays,
/// for shadow maps too).
pub fn check_with(
    ctx: &lightgrid::gpu::GpuContext,
    scene: &Scene,
    frame: u32,
    size: (u32, u32),
    step: u32,
    settings: RenderSettings,
) -> Checked {
    assert!(
        settings.shadow_lights.is_none(),
        "the reference shadows every light"
    );
    let mut f = Frame::with_brdf(
        scene,
        frame,
        size,
        settings.brdf.unwrap_or(scene.lighting.brdf),
    );
    // Maps (at the default 1024-texel faces, well under a pixel here) shade what the rays do
    // away from the outlines the reference skips.
    f.shadows = settings.shadows != lightgrid::scene::Shadows::Off;
    let mut r = Renderer::new(ctx, size.0, size.1, settings).unwrap();
    let mut out = Checked::default();
    for model in [Model::Full, Model::Mono, Model::MonoAlbedo] {
        let image = r.render(scene, frame, model.pipeline()).unwrap().image;
        compare(&f, &image, model, step, &mut out);
    }
    out
}
