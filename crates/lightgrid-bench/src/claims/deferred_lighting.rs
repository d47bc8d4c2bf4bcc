//! Claims of deferred-shading-vs-deferred-lighting: deferred lighting's marginal advantage and
//! the blog's traffic break-evens (writes above 0.5 lights per pixel; with monochrome specular
//! on both sides, equal writes and fewer reads above 2), checked on the pipelines' traffic
//! models at the measured lights per pixel.

use super::*;
use lightgrid::pipelines::ids;

/// "At most a marginal advantage": deferred lighting no more than 18% faster (0.85 of deferred's time).
pub const MARGINAL: Band = Band {
    words: "at most a marginal GPU advantage",
    quantity: "deferred ÷ light_prepass avg ms",
    low: 0.0,
    high: 1.18,
};

/// 8. Deferred lighting is no real win over deferred shading.
pub(super) fn lighting_marginal(r: &BenchResults, scene: &str) -> (String, Verdict) {
    match (
        find(r, scene, ids::LIGHT_PREPASS, None).and_then(avg_ms),
        find(r, scene, ids::DEFERRED, None).and_then(avg_ms),
    ) {
        (Some(l), Some(d)) => (
            format!(
                "avg ms: light_prepass {l:.1}, deferred {d:.1} ({:.2}x)",
                d / l.max(1e-9)
            ),
            verdict(MARGINAL.contains(d / l.max(1e-9))),
        ),
        _ => missing(),
    }
}

/// The blog's mono-specular compromise on both sides: deferred lighting then needs as little as
/// 16 bytes per pixel against deferred shading's 20. The verdict compares the two pipelines'
/// render targets per pixel; their times are given as information.
pub fn less_memory(
    lighting_bytes: u32,
    shading_bytes: u32,
    lighting_ms: Option<f64>,
    shading_ms: Option<f64>,
) -> (String, Verdict) {
    let times = match (lighting_ms, shading_ms) {
        (Some(l), Some(d)) => format!("; avg ms: light_prepass_mono {l:.1}, deferred_mono {d:.1}"),
        _ => String::new(),
    };
    (
        format!(
            "render targets per pixel: light_prepass_mono {lighting_bytes} B, deferred_mono {shading_bytes} B{times}"
        ),
        verdict(lighting_bytes < shading_bytes),
    )
}

/// Claim 18: the mono-specular pipelines' render targets, as the runs recorded them.
pub(super) fn mono_memory(r: &BenchResults, scene: &str) -> (String, Verdict) {
    let bytes = |p| Some(find(r, scene, p, None)?.summary.as_ref()?.bytes_per_pixel);
    match (bytes(ids::LIGHT_PREPASS_MONO), bytes(ids::DEFERRED_MONO)) {
        (Some(l), Some(d)) => less_memory(
            l,
            d,
            find(r, scene, ids::LIGHT_PREPASS_MONO, None).and_then(avg_ms),
            find(r, scene, ids::DEFERRED_MONO, None).and_then(avg_ms),
        ),
        _ => not_measured("light_prepass_mono and deferred_mono"),
    }
}

/// The blog's write break-even: deferred shading writes 20 B per pixel + 8 per lit pixel,
/// deferred lighting 16 + 16, so lighting writes more above 0.5 lights per pixel.
pub const WRITE_BREAK_EVEN: f64 = 0.5;

/// The verdict on the measured lights per pixel and the two pipelines' modelled writes per
/// frame: lighting writes more exactly when the lights per pixel pass the break-even.
pub fn writes_more(
    lights_per_pixel: f64,
    lighting_bytes: f64,
    shading_bytes: f64,
) -> (String, Verdict) {
    let more = lighting_bytes > shading_bytes;
    (
        format!(
            "{lights_per_pixel:.2} lights per pixel (deferred's opaque lighting computations / pixels); modelled writes per frame: light_prepass {:.1} MiB, deferred {:.1} MiB",
            lighting_bytes / 1048576.0,
            shading_bytes / 1048576.0
        ),
        verdict(more == (lights_per_pixel > WRITE_BREAK_EVEN)),
    )
}

/// Claim 15: lights per pixel from deferred's counts, writes from the traffic model.
pub(super) fn write_break_even(r: &BenchResults, scene: &str) -> (String, Verdict) {
    let pair = [ids::LIGHT_PREPASS, ids::DEFERRED];
    match (
        lights_per_pixel(r, scene),
        modelled(r, scene, pair[0], Side::Writes),
        modelled(r, scene, pair[1], Side::Writes),
    ) {
        (Some(l), Some(lp), Some(ds)) => {
            with_budgets(writes_more(l, lp, ds), r, scene, pair, Side::Writes)
        }
        _ => not_measured("deferred and light_prepass"),
    }
}

/// Lights reaching a pixel on average: deferred's opaque lighting computations per pixel
/// (each volume fragment that runs the light function is a lit pixel; the transparent pass
/// is outside the blog's model).
pub(super) fn lights_per_pixel(r: &BenchResults, scene: &str) -> Option<f64> {
    let x = find(r, scene, ids::DEFERRED, None)?;
    let pixels = f64::from(x.width) * f64::from(x.height);
    let opaque: Option<Vec<f64>> = x
        .frames
        .iter()
        .map(|f| {
            let n = f.stats.lighting_computations?;
            Some(n.saturating_sub(f.stats.transparent_lighting_computations.unwrap_or(0)) as f64)
        })
        .collect();
    let opaque = opaque.filter(|o| !o.is_empty())?;
    Some(opaque.iter().sum::<f64>() / opaque.len() as f64 / pixels.max(1.0))
}

/// Which side of the traffic model a claim weighs: bytes written or bytes read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    Writes,
    Reads,
}

/// A run's modelled bytes per frame (the traffic model applied to each frame's pixels and
/// lighting computations), averaged over its frames.
pub(super) fn modelled(r: &BenchResults, scene: &str, pipeline: &str, side: Side) -> Option<f64> {
    let x = find(r, scene, pipeline, None)?;
    let bytes: Option<Vec<u64>> = x
        .frames
        .iter()
        .map(|f| match side {
            Side::Writes => f.stats.memory.modelled_write_bytes,
            Side::Reads => f.stats.memory.modelled_read_bytes,
        })
        .collect();
    let bytes = bytes.filter(|b| !b.is_empty())?;
    Some(bytes.iter().sum::<u64>() as f64 / bytes.len() as f64)
}

/// The blog's mono-specular break-evens. With the specular monochrome on both sides (deferred
/// lighting keeps it in the diffuse irradiance's alpha, deferred shading in the diffuse
/// albedo's), its layouts give shading 16 B written per pixel + 8 per lit pixel and 20 read per
/// lit pixel, lighting 16 + 8 written and 8 per pixel + 16 per lit pixel read: equal writes,
/// and fewer reads for lighting above 2 lights per pixel.
pub const MONO_READ_BREAK_EVEN: f64 = 2.0;

/// Modelled writes within this fraction of each other count as equal.
pub const EQUAL_WRITES: f64 = 0.05;

/// The verdict on the measured lights per pixel and the mono-specular pipelines' modelled
/// bytes per frame: writes are equal (within [`EQUAL_WRITES`]), or lighting reads less exactly
/// when the lights per pixel pass [`MONO_READ_BREAK_EVEN`].
pub fn mono_traffic(
    side: Side,
    lights_per_pixel: f64,
    lighting_bytes: f64,
    shading_bytes: f64,
) -> (String, Verdict) {
    let what = match side {
        Side::Writes => "writes",
        Side::Reads => "reads",
    };
    let evidence = format!(
        "{lights_per_pixel:.2} lights per pixel (deferred's opaque lighting computations / pixels); modelled {what} per frame: light_prepass_mono {:.1} MiB, deferred_mono {:.1} MiB ({:.2}x)",
        lighting_bytes / 1048576.0,
        shading_bytes / 1048576.0,
        lighting_bytes / shading_bytes.max(1.0)
    );
    let held = match side {
        Side::Writes => (lighting_bytes - shading_bytes).abs() <= EQUAL_WRITES * shading_bytes,
        Side::Reads => {
            (lighting_bytes < shading_bytes) == (lights_per_pixel > MONO_READ_BREAK_EVEN)
        }
    };
    (evidence, verdict(held))
}

/// Claim 16: the mono-specular pipelines' writes.
pub(super) fn mono_writes(r: &BenchResults, scene: &str) -> (String, Verdict) {
    mono_break_even(r, scene, Side::Writes)
}

/// Claim 17: the mono-specular pipelines' reads.
pub(super) fn mono_reads(r: &BenchResults, scene: &str) -> (String, Verdict) {
    mono_break_even(r, scene, Side::Reads)
}

/// Claims 16 and 17: lights per pixel from deferred's counts, bytes from the traffic models of
/// the two mono-specular pipelines.
pub(super) fn mono_break_even(r: &BenchResults, scene: &str, side: Side) -> (String, Verdict) {
    let pair = [ids::LIGHT_PREPASS_MONO, ids::DEFERRED_MONO];
    match (
        lights_per_pixel(r, scene),
        modelled(r, scene, pair[0], side),
        modelled(r, scene, pair[1], side),
    ) {
        (Some(l), Some(lp), Some(ds)) => {
            with_budgets(mono_traffic(side, l, lp, ds), r, scene, pair, side)
        }
        _ => not_measured("deferred, light_prepass_mono and deferred_mono"),
    }
}

/// A break-even claim's evidence with the reason behind it: the two layouts' budgets (bytes
/// per pixel + per lit pixel, from the registry's models at the runs' G-buffer precision) and
/// the lights per pixel where they cross.
pub(super) fn with_budgets(
    (evidence, v): (String, Verdict),
    r: &BenchResults,
    scene: &str,
    [lighting, shading]: [&str; 2],
    side: Side,
) -> (String, Verdict) {
    match (budget(r, scene, lighting, side), budget(r, scene, shading, side)) {
        (Some(a), Some(b)) => (
            format!(
                "{evidence}; bytes per pixel + per lit pixel: {lighting} {} + {}, {shading} {} + {} ({})",
                a.0,
                a.1,
                b.0,
                b.1,
                crossing(a, b)
            ),
            v,
        ),
        _ => (evidence, v),
    }
}

/// Where two budgets `(per pixel, per lit pixel)` cross, said from the first's side: the
/// lights per pixel above which it moves more bytes, or that it never does.
pub fn crossing(lighting: (u32, u32), shading: (u32, u32)) -> String {
    let per_pixel = f64::from(lighting.0) - f64::from(shading.0);
    let per_lit = f64::from(lighting.1) - f64::from(shading.1);
    let l = -per_pixel / per_lit;
    match (per_lit > 0.0, per_lit < 0.0) {
        (true, _) if l > 0.0 => format!("lighting moves more above {l:.2} lights per pixel"),
        (true, _) => "lighting moves more at any light count".to_string(),
        (_, true) if l > 0.0 => format!("lighting moves less above {l:.2} lights per pixel"),
        (_, true) => "lighting moves less at any light count".to_string(),
        _ if per_pixel > 0.0 => {
            format!("lighting moves {per_pixel} B per pixel more at any light count")
        }
        _ if per_pixel < 0.0 => format!(
            "lighting moves {} B per pixel less at any light count",
            -per_pixel
        ),
        _ => "equal at any light count".to_string(),
    }
}

/// A run's traffic budget on one side, `(per pixel, per lit pixel)`, from the registry's model
/// at the run's G-buffer precision.
pub(super) fn budget(
    r: &BenchResults,
    scene: &str,
    pipeline: &str,
    side: Side,
) -> Option<(u32, u32)> {
    use lightgrid::frame::GBufferFormat;
    let x = find(r, scene, pipeline, None)?;
    let gbuffer = match x.gbuffer_bits() {
        Some(32) => GBufferFormat::F32,
        _ => GBufferFormat::F16,
    };
    let settings = lightgrid::RenderSettings {
        gbuffer,
        ..Default::default()
    };
    let t = lightgrid::pipelines::find(pipeline)
        .ok()?
        .memory_model(&settings)
        .traffic;
    Some(match side {
        Side::Writes => (t.write_per_pixel, t.write_per_lit),
        Side::Reads => (t.read_per_pixel, t.read_per_lit),
    })
}
