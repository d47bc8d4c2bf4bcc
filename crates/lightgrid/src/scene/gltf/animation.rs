//! A file's own animation (glTF 2.0 §3.11): the first of its `animations` drives its nodes'
//! translation, rotation and scale (step, linear and cubic-spline samplers), sampled at
//! [`FPS`] frames per second, so frame `f` shows time `f / FPS`. Everything placed by an
//! animated node (meshes, lights, the camera) moves with it. Morph target weights are not
//! animated (morph targets are not applied; `unread.rs` says so).

use super::json::Node;
use super::read::{Document, Res};
use glam::{Mat4, Quat, Vec3, Vec4};
use serde::Deserialize;

/// Frames per second a file's animation is sampled at: frame `f` shows time `f / FPS`
/// seconds (the bench's frames are this clock's too).
pub const FPS: f32 = 30.0;
/// Most frames sampled (two minutes at [`FPS`]); a longer animation is cut there, with a
/// warning.
pub const MAX_FRAMES: u32 = 3600;

#[derive(Deserialize, Default)]
#[serde(default)]
struct AnimationDef {
    channels: Vec<ChannelDef>,
    samplers: Vec<SamplerDef>,
}

#[derive(Deserialize, Default)]
#[serde(default)]
struct ChannelDef {
    sampler: usize,
    target: TargetDef,
}

#[derive(Deserialize, Default)]
#[serde(default)]
struct TargetDef {
    node: Option<usize>,
    path: String,
}

#[derive(Deserialize, Default)]
#[serde(default)]
struct SamplerDef {
    input: usize,
    output: usize,
    interpolation: Option<String>,
}

/// What a channel animates.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Property {
    Translation,
    Rotation,
    Scale,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Interpolation {
    Step,
    Linear,
    CubicSpline,
}

/// One animated property of one node: key times and values (xyz, or a quaternion's xyzw);
/// a cubic spline holds three values per key (in-tangent, value, out-tangent).
struct Channel {
    node: usize,
    property: Property,
    interpolation: Interpolation,
    times: Vec<f32>,
    values: Vec<Vec4>,
}

impl Channel {
    /// The property's value at time `t` (held before the first key and after the last).
    fn sample(&self, t: f32) -> Vec4 {
        let cubic = self.interpolation == Interpolation::CubicSpline;
        let value = |k: usize| {
            if cubic {
                self.values[3 * k + 1]
            } else {
                self.values[k]
            }
        };
        let n = self.times.len();
        let k = self.times.partition_point(|&x| x <= t);
        if k == 0 {
            return value(0);
        }
        if k >= n {
            return value(n - 1);
        }
        let (k0, k1) = (k - 1, k);
        let dt = self.times[k1] - self.times[k0];
        let s = if dt > 0.0 {
            (t - self.times[k0]) / dt
        } else {
            0.0
        };
        let rotation = self.property == Property::Rotation;
        match self.interpolation {
            Interpolation::Step => value(k0),
            Interpolation::Linear if rotation => {
                let (a, b) = (Quat::from_vec4(value(k0)), Quat::from_vec4(value(k1)));
                Vec4::from(a.normalize().slerp(b.normalize(), s))
            }
            Interpolation::Linear => value(k0).lerp(value(k1), s),
            // §3.11 Appendix C: the Hermite spline, tangents scaled by the key interval.
            Interpolation::CubicSpline => {
                let (s2, s3) = (s * s, s * s * s);
                let p0 = self.values[3 * k0 + 1];
                let m0 = self.values[3 * k0 + 2] * dt;
                let p1 = self.values[3 * k1 + 1];
                let m1 = self.values[3 * k1] * dt;
                let v = p0 * (2.0 * s3 - 3.0 * s2 + 1.0)
                    + m0 * (s3 - 2.0 * s2 + s)
                    + p1 * (-2.0 * s3 + 3.0 * s2)
                    + m1 * (s3 - s2);
                if rotation {
                    Vec4::from(Quat::from_vec4(v).normalize())
                } else {
                    v
                }
            }
        }
    }
}

/// The animation a file plays.
pub(super) struct Animation {
    channels: Vec<Channel>,
    /// Seconds from 0 to the last key.
    pub duration: f32,
}

impl Animation {
    /// Frames sampled: every frame of [`FPS`] from 0 to the last key, at most [`MAX_FRAMES`].
    pub fn frames(&self) -> u32 {
        ((self.duration * FPS + 1e-3).floor() as u32)
            .saturating_add(1)
            .min(MAX_FRAMES)
    }

    /// Whether node `n`'s own transform is animated.
    pub fn moves(&self, n: usize) -> bool {
        self.channels.iter().any(|c| c.node == n)
    }

    /// Node `n`'s local transform at time `t`: its translation, rotation and scale with the
    /// animated ones sampled (a node given as a matrix is decomposed first).
    pub fn local(&self, node: &Node, n: usize, rest: Mat4, t: f32) -> Mat4 {
        if !self.moves(n) {
            return rest;
        }
        let (mut s, mut r, mut tr) = match node.matrix {
            Some(_) => rest.to_scale_rotation_translation(),
            None => (
                Vec3::from(node.scale.unwrap_or([1.0; 3])),
                Quat::from_array(node.rotation.unwrap_or([0.0, 0.0, 0.0, 1.0])).normalize(),
                Vec3::from(node.translation.unwrap_or([0.0; 3])),
            ),
        };
        for c in self.channels.iter().filter(|c| c.node == n) {
            let v = c.sample(t);
            match c.property {
                Property::Translation => tr = v.truncate(),
                Property::Rotation => r = Quat::from_vec4(v).normalize(),
                Property::Scale => s = v.truncate(),
            }
        }
        Mat4::from_scale_rotation_translation(s, r, tr)
    }
}

/// A sampler's interpolation and keys, checked: times finite, non-negative and increasing,
/// one finite value (three with cubic-spline tangents) per key, rotations quaternions.
fn sampler_keys(
    doc: &Document,
    sampler: &SamplerDef,
    property: Property,
    what: &str,
) -> Res<(Interpolation, Vec<f32>, Vec<Vec4>)> {
    let interpolation = match sampler.interpolation.as_deref().unwrap_or("LINEAR") {
        "LINEAR" => Interpolation::Linear,
        "STEP" => Interpolation::Step,
        "CUBICSPLINE" => Interpolation::CubicSpline,
        other => {
            return Err(format!(
                "{what}: interpolation '{other}' is not LINEAR, STEP or CUBICSPLINE"
            ))
        }
    };
    let times = doc.read_floats(sampler.input, 1, &format!("{what} input"))?;
    if times.is_empty() {
        return Err(format!("{what}: no key times"));
    }
    let increasing = times.windows(2).all(|w| w[1] > w[0]);
    if !times.iter().all(|t| t.is_finite() && *t >= 0.0) || !increasing {
        return Err(format!(
            "{what}: key times must be finite, at least 0 and increasing"
        ));
    }
    let comps = if property == Property::Rotation { 4 } else { 3 };
    let flat = doc.read_floats(sampler.output, comps, &format!("{what} output"))?;
    let per_key = if interpolation == Interpolation::CubicSpline {
        3
    } else {
        1
    };
    if flat.len() != times.len() * per_key * comps {
        return Err(format!(
            "{what}: {} output values for {} keys (needs {})",
            flat.len() / comps,
            times.len(),
            times.len() * per_key
        ));
    }
    if !flat.iter().all(|v| v.is_finite()) {
        return Err(format!("{what}: an output value is NaN or infinite"));
    }
    let values = flat
        .chunks_exact(comps)
        .map(|v| match comps {
            4 => Vec4::new(v[0], v[1], v[2], v[3]),
            _ => Vec4::new(v[0], v[1], v[2], 0.0),
        })
        .collect::<Vec<_>>();
    if property == Property::Rotation {
        let key_values = values.iter().skip(per_key / 2).step_by(per_key);
        if key_values.clone().any(|q| q.length_squared() < 1e-12) {
            return Err(format!("{what}: a rotation key is not a quaternion"));
        }
    }
    Ok((interpolation, times, values))
}

/// The first animation of the file, read and checked, or None when it has none (or none
/// that moves a node). `warn` takes what is not applied: other animations, weight channels,
/// and an animation cut at [`MAX_FRAMES`].
pub(super) fn read(doc: &Document, warn: &mut dyn FnMut(String)) -> Res<Option<Animation>> {
    let Some(first) = doc.root.animations.first() else {
        return Ok(None);
    };
    if doc.root.animations.len() > 1 {
        warn(format!(
            "animation 0 is played; the file's other {} animation(s) are not",
            doc.root.animations.len() - 1
        ));
    }
    let def: AnimationDef = serde_json::from_value(first.clone())
        .map_err(|e| format!("animation 0: malformed: {e}"))?;
    let mut channels = Vec::new();
    let mut weights = false;
    for (ci, c) in def.channels.iter().enumerate() {
        let what = format!("animation 0 channel {ci}");
        let property = match c.target.path.as_str() {
            "translation" => Property::Translation,
            "rotation" => Property::Rotation,
            "scale" => Property::Scale,
            "weights" => {
                weights = true;
                continue;
            }
            other => {
                return Err(format!(
                    "{what}: target path '{other}' is not translation, rotation, scale or weights"
                ))
            }
        };
        // A channel without a node is for an extension (§3.11): nothing to move.
        let Some(node) = c.target.node else { continue };
        if node >= doc.root.nodes.len() {
            return Err(format!("{what}: node {node} does not exist"));
        }
        let sampler = def
            .samplers
            .get(c.sampler)
            .ok_or_else(|| format!("{what}: sampler {} does not exist", c.sampler))?;
        let (interpolation, times, values) = sampler_keys(doc, sampler, property, &what)?;
        channels.push(Channel {
            node,
            property,
            interpolation,
            times,
            values,
        });
    }
    if weights {
        warn("animation 0 animates morph target weights, which are not applied".into());
    }
    if channels.is_empty() {
        return Ok(None);
    }
    let duration = channels
        .iter()
        .filter_map(|c| c.times.last().copied())
        .fold(0.0, f32::max);
    let animation = Animation { channels, duration };
    if (animation.duration * FPS).floor() as u64 + 1 > u64::from(MAX_FRAMES) {
        warn(format!(
            "animation 0 lasts {:.1} s; the first {} s ({MAX_FRAMES} frames at {FPS} per second) are played",
            animation.duration,
            MAX_FRAMES as f32 / FPS
        ));
    }
    Ok(Some(animation))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(
        property: Property,
        interpolation: Interpolation,
        times: &[f32],
        values: &[Vec4],
    ) -> Channel {
        Channel {
            node: 0,
            property,
            interpolation,
            times: times.to_vec(),
            values: values.to_vec(),
        }
    }

    #[test]
    fn step_linear_and_cubic_samplers_follow_the_specification() {
        let (a, b) = (
            Vec4::new(0.0, 0.0, 0.0, 0.0),
            Vec4::new(2.0, 4.0, -6.0, 0.0),
        );
        let step = channel(
            Property::Translation,
            Interpolation::Step,
            &[1.0, 3.0],
            &[a, b],
        );
        assert_eq!(step.sample(0.0), a, "held before the first key");
        assert_eq!(step.sample(2.9), a);
        assert_eq!(step.sample(3.0), b);
        assert_eq!(step.sample(9.0), b, "held after the last key");
        let linear = channel(
            Property::Translation,
            Interpolation::Linear,
            &[1.0, 3.0],
            &[a, b],
        );
        assert!(linear
            .sample(1.5)
            .abs_diff_eq(Vec4::new(0.5, 1.0, -1.5, 0.0), 1e-6));
        // Zero tangents: the smoothstep between the values; tangents scale with the interval.
        let z = Vec4::ZERO;
        let cubic = channel(
            Property::Translation,
            Interpolation::CubicSpline,
            &[1.0, 3.0],
            &[z, a, z, z, b, z],
        );
        let s: f32 = 0.25;
        let smooth = 3.0 * s * s - 2.0 * s * s * s;
        assert!(cubic.sample(1.5).abs_diff_eq(b * smooth, 1e-6));
        let slope = Vec4::new(1.0, 0.0, 0.0, 0.0);
        let ramp = channel(
            Property::Translation,
            Interpolation::CubicSpline,
            &[0.0, 2.0],
            &[z, a, slope, slope, a + slope * 2.0, z],
        );
        // A straight line with matching tangents stays on it.
        assert!(ramp
            .sample(0.5)
            .abs_diff_eq(Vec4::new(0.5, 0.0, 0.0, 0.0), 1e-5));
        // Rotations: spherical, unit length.
        let q0 = Vec4::from(Quat::IDENTITY);
        let q1 = Vec4::from(Quat::from_rotation_y(std::f32::consts::FRAC_PI_2));
        let turn = channel(
            Property::Rotation,
            Interpolation::Linear,
            &[0.0, 1.0],
            &[q0, q1],
        );
        let half = Quat::from_vec4(turn.sample(0.5));
        assert!(half.abs_diff_eq(Quat::from_rotation_y(std::f32::consts::FRAC_PI_4), 1e-6));
    }
}
