//! Shadows (`--preset shadows`): tiled-shading Table 1's row "Re-use shadow maps" (deferred
//! yes; tiled deferred and tiled forward no, "because all lights are in flight simultaneously
//! … storing shadow maps for hundreds of lights can be prohibitive in terms of memory") as
//! measured memory, and Forward+ §6's ray casting against the atlas.
//!
//! Each claim reads the runs of one (scene, pipeline) over the shadowed-light counts
//! (`--shadow-lights`): the bytes of the shadow-map texture each frame rendered into, and the
//! frames' mean GPU time.

use super::{BenchResults, Claim, RunRecord, Threshold, Verdict};
use lightgrid::scene::Shadows;

/// "Flat": the re-used maps' bytes the same at every shadowed-light count.
pub const FLAT: &str = "\"flat\": the re-used maps' texture bytes (mean over the frames) equal at every shadowed-light count measured (two at least)";
/// "Grows": the atlas's bytes larger at each larger count.
pub const GROWS: &str = "\"grows\": the atlas's texture bytes (mean over the frames) larger at each larger shadowed-light count measured (two at least), at one face size";
/// "Beats": ray casting's frame time at most the atlas's at the largest count.
pub const BEATS: &str = "\"beats\": at the largest shadowed-light count measured, the mean frame time with rays at most with the atlas; the break-even is the smallest count from which rays stay at most the atlas's";

pub(super) fn shadow_claims(r: &BenchResults) -> Vec<Claim> {
    let mut out = Vec::new();
    let mut keys: Vec<(&str, &str)> = r
        .runs
        .iter()
        .filter(|x| x.settings.shadows != Shadows::Off)
        .map(|x| (x.scene.as_str(), x.pipeline.as_str()))
        .collect();
    keys.sort();
    keys.dedup();
    for (scene, pipeline) in keys {
        let series = |mode: Shadows| -> Vec<&RunRecord> {
            let mut v: Vec<&RunRecord> = r
                .runs
                .iter()
                .filter(|x| x.scene == scene && x.pipeline == pipeline)
                .filter(|x| x.settings.shadows == mode && x.summary.is_some())
                .collect();
            v.sort_by_key(|x| shadowed(x));
            v
        };
        let maps = series(Shadows::Maps);
        let memory: Vec<(u32, u64)> = maps
            .iter()
            .filter_map(|x| Some((shadowed(x), map_bytes(x)?)))
            .collect();
        let reused = maps.iter().any(|x| {
            x.frames
                .iter()
                .any(|f| f.stats.shadow_maps.is_some_and(|m| m.reused))
        });
        if !memory.is_empty() {
            out.push(if reused {
                Claim::new(
                    scene,
                    "Re-used shadow maps: memory stays one light's maps whatever the number of shadowed lights",
                    "tiled-shading §5, Table 1 (\"Re-use shadow maps\": deferred yes)",
                    Threshold::Rule(FLAT),
                    named(pipeline, memory_flat(&memory)),
                )
            } else {
                Claim::new(
                    scene,
                    "All lights in flight: the shadow atlas grows with the number of shadowed lights",
                    "tiled-shading §5, Table 1 (\"Re-use shadow maps\": tiled deferred and tiled forward no)",
                    Threshold::Rule(GROWS),
                    named(pipeline, memory_grows(&memory)),
                )
            });
        }
        let times = |runs: &[&RunRecord]| -> Vec<(u32, f64)> {
            runs.iter()
                .map(|x| {
                    (
                        shadowed(x),
                        x.summary.as_ref().expect("filtered").gpu_ms.mean,
                    )
                })
                .collect()
        };
        let rays = series(Shadows::Rays);
        if !rays.is_empty() && !maps.is_empty() && !reused {
            out.push(Claim::new(
                scene,
                "Ray casting to each light beats rendering every shadowed light's maps past some number of shadowed lights",
                "forward-plus §6 (\"shadow computation from all the lights in the scene by local short ray casting to the lights\")",
                Threshold::Rule(BEATS),
                named(pipeline, rays_beat_atlas(&times(&rays), &times(&maps))),
            ));
        }
    }
    out
}

/// The run's shadowed-light count: `--shadow-lights`, or every light.
fn shadowed(x: &RunRecord) -> u32 {
    x.settings
        .shadow_lights
        .unwrap_or(x.lights.unwrap_or(0))
        .min(x.lights.unwrap_or(u32::MAX))
}

/// The mean bytes of the shadow-map texture over the run's frames.
fn map_bytes(x: &RunRecord) -> Option<u64> {
    let b: Vec<u64> = x
        .frames
        .iter()
        .filter_map(|f| f.stats.shadow_maps.map(|m| m.bytes))
        .collect();
    (!b.is_empty()).then(|| b.iter().sum::<u64>() / b.len() as u64)
}

fn named(pipeline: &str, (evidence, verdict): (String, Verdict)) -> (String, Verdict) {
    (format!("{pipeline}: {evidence}"), verdict)
}

fn mib(b: u64) -> String {
    format!("{:.2} MiB", b as f64 / (1024.0 * 1024.0))
}

fn listed(points: &[(u32, u64)]) -> String {
    points
        .iter()
        .map(|(n, b)| format!("{n} lights {}", mib(*b)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// [`FLAT`]: `points` (shadowed lights, bytes).
pub fn memory_flat(points: &[(u32, u64)]) -> (String, Verdict) {
    if points.len() < 2 {
        return super::not_measured("two shadowed-light counts");
    }
    let flat = points.iter().all(|p| p.1 == points[0].1);
    (listed(points), super::verdict(flat))
}

/// [`GROWS`]: `points` (shadowed lights, bytes), sorted by lights.
pub fn memory_grows(points: &[(u32, u64)]) -> (String, Verdict) {
    if points.len() < 2 {
        return super::not_measured("two shadowed-light counts");
    }
    let grows = points
        .windows(2)
        .all(|w| w[1].0 > w[0].0 && w[1].1 > w[0].1);
    (listed(points), super::verdict(grows))
}

/// [`BEATS`]: frame times (shadowed lights, ms) with rays and with the atlas, at the same
/// counts (sorted).
pub fn rays_beat_atlas(rays: &[(u32, f64)], maps: &[(u32, f64)]) -> (String, Verdict) {
    let both: Vec<(u32, f64, f64)> = rays
        .iter()
        .filter_map(|&(n, r)| maps.iter().find(|m| m.0 == n).map(|m| (n, r, m.1)))
        .collect();
    let Some(&(largest, r, m)) = both.last() else {
        return super::not_measured("rays and maps at the same shadowed-light counts");
    };
    let table = both
        .iter()
        .map(|(n, r, m)| format!("{n} lights: rays {r:.1} ms, atlas {m:.1} ms"))
        .collect::<Vec<_>>()
        .join("; ");
    // The smallest count from which rays stay at most the atlas's.
    let from = both
        .iter()
        .rposition(|&(_, r, m)| r > m)
        .map_or(Some(0), |i| both.get(i + 1).map(|_| i + 1));
    let break_even = match from {
        Some(0) => format!("rays at most the atlas at every count from {}", both[0].0),
        Some(i) => format!(
            "break-even between {} and {} lights",
            both[i - 1].0,
            both[i].0
        ),
        None => format!("rays still slower at {largest} lights"),
    };
    (format!("{table}; {break_even}"), super::verdict(r <= m))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_memory_on_both_sides() {
        assert_eq!(
            memory_flat(&[(8, 100), (64, 100), (924, 100)]).1,
            Verdict::Held
        );
        assert_eq!(memory_flat(&[(8, 100), (64, 120)]).1, Verdict::NotHeld);
        assert_eq!(memory_flat(&[(8, 100)]).1, Verdict::NotMeasured);
    }

    #[test]
    fn growing_memory_on_both_sides() {
        let (e, v) = memory_grows(&[(8, 1 << 20), (64, 6 << 20), (924, 88 << 20)]);
        assert_eq!(v, Verdict::Held);
        assert!(e.contains("924 lights 88.00 MiB"), "{e}");
        assert_eq!(memory_grows(&[(8, 100), (64, 100)]).1, Verdict::NotHeld);
        assert_eq!(memory_grows(&[(8, 100), (64, 90)]).1, Verdict::NotHeld);
    }

    #[test]
    fn ray_break_even_on_both_sides() {
        let maps = [(8, 10.0), (64, 40.0), (256, 160.0)];
        let (e, v) = rays_beat_atlas(&[(8, 30.0), (64, 35.0), (256, 60.0)], &maps);
        assert_eq!(v, Verdict::Held);
        assert!(e.contains("break-even between 8 and 64 lights"), "{e}");
        let (e, v) = rays_beat_atlas(&[(8, 5.0), (64, 35.0), (256, 60.0)], &maps);
        assert_eq!(v, Verdict::Held);
        assert!(e.contains("at every count from 8"), "{e}");
        let (e, v) = rays_beat_atlas(&[(8, 30.0), (64, 80.0), (256, 400.0)], &maps);
        assert_eq!(v, Verdict::NotHeld);
        assert!(e.contains("still slower at 256"), "{e}");
        assert_eq!(rays_beat_atlas(&[], &maps).1, Verdict::NotMeasured);
    }
}
