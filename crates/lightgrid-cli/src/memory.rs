//! `lightgrid memory`: render targets and the traffic model of every pipeline.

use crate::args::{parse_size, setting, Size};
use anyhow::Result;
use clap::Args;
use lightgrid::passes::GBufferFormat;
use lightgrid::pipelines::PIPELINES;
use lightgrid::RenderSettings;

#[derive(Args)]
pub(crate) struct MemoryArgs {
    /// Frame size WIDTHxHEIGHT.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_size, default_value = "1920x1080")]
    pub(crate) size: Size,
    /// G-buffer channel precision in bits for deferred pipelines.
    #[arg(long, default_value = "16", value_parser = setting::<GBufferFormat>())]
    pub(crate) gbuffer: GBufferFormat,
    /// MSAA samples per pixel, or a list (1,2,4,8): one table per count (tiled-forward-shading
    /// Fig. 4.4). A model: any count lightgrid knows (1, 2, 4, 8, 16), whether or not this
    /// machine's adapter offers it.
    #[arg(
        long,
        allow_hyphen_values = true,
        value_delimiter = ',',
        default_value = "1"
    )]
    pub(crate) msaa: Vec<u32>,
}

pub(crate) fn memory(a: &MemoryArgs) -> Result<()> {
    lightgrid_bench::check_distinct("--msaa", &a.msaa, |&n| n)?;
    for &n in &a.msaa {
        lightgrid::frame::validate_msaa(n)?;
    }
    for &n in &a.msaa {
        table(a, n)?;
    }
    footer(a)
}

/// The targets and traffic of every pipeline at `samples` samples per pixel.
fn table(a: &MemoryArgs, samples: u32) -> Result<()> {
    let Size(w, h) = a.size;
    let settings = RenderSettings {
        grid: lightgrid::CullConfig {
            samples,
            ..lightgrid::CullConfig::default()
        },
        gbuffer: a.gbuffer,
        ..Default::default()
    };
    let msaa = if samples > 1 {
        format!(", {samples}x MSAA (every target per sample)")
    } else {
        String::new()
    };
    outln!("render targets at {w}x{h}, {}-bit G-buffer{msaa} (the lighting-count target is a statistics aid, not counted)", a.gbuffer.bits());
    outln!(
        "{:<22} {:>6} {:>10}   {:>9} {:>9} {:>9} {:>9}   targets",
        "pipeline",
        "B/px",
        "total MiB",
        "wr B/px",
        "rd B/px",
        "wr B/lit",
        "rd B/lit"
    );
    for p in PIPELINES {
        if let (true, lightgrid::pipelines::Msaa::Refused(why)) = (samples > 1, p.msaa) {
            outln!("{:<22} refuses MSAA: {why}", p.id);
            continue;
        }
        let m = p.memory_model(&settings);
        let t = m.traffic;
        let targets: Vec<String> = m
            .targets
            .iter()
            .map(|t| format!("{} {}", t.name, t.bytes_per_pixel))
            .collect();
        outln!(
            "{:<22} {:>6} {:>10.2}   {:>9} {:>9} {:>9} {:>9}   {}",
            p.id,
            m.bytes_per_pixel(),
            m.target_bytes(w, h) as f64 / (1024.0 * 1024.0),
            t.write_per_pixel,
            t.read_per_pixel,
            t.write_per_lit,
            t.read_per_lit,
            targets.join(", ")
        );
    }
    outln!();
    Ok(())
}

fn footer(a: &MemoryArgs) -> Result<()> {
    let Size(w, h) = a.size;
    let settings = RenderSettings {
        gbuffer: a.gbuffer,
        ..Default::default()
    };
    outln!(
        "traffic model (deferred-shading-vs-deferred-lighting): render-target bytes per pixel and per lit pixel \
         (one lighting computation); blending counts as read + write; light data {} B per light, grid indices {} B; \
         tiled pipelines also upload their grid each frame (see --stats memory.grid_bytes)",
        lightgrid::memory::LIGHT_BYTES,
        lightgrid::memory::INDEX_BYTES
    );
    // The grid's cell array (offset + count per cell); frames with transparent objects and
    // separate lists (the default) keep a second layer of cells for the transparent lists.
    let (tile, slices) = (settings.grid.tile_size, settings.grid.slices);
    let tiles = lightgrid::culling::GridDims::new(w, h, tile)?;
    let clusters = tiles.clustered(slices, 1.0, 2.0)?;
    let kib = |d: &lightgrid::culling::GridDims| (d.cell_count() * 8) as f64 / 1024.0;
    let separate = lightgrid::culling::GridLists::Separate;
    outln!(
        "light grid cells (8 B each) at tile {tile}: tiled {} cells = {:.1} KiB, clustered ({slices} slices) {} cells = {:.1} KiB; \
         with transparent objects and --lists separate a second layer: {:.1} and {:.1} KiB (the index lists depend on the frame: --stats memory.grid_bytes)",
        tiles.cell_count(),
        kib(&tiles),
        clusters.cell_count(),
        kib(&clusters),
        kib(&tiles.with_lists(separate)),
        kib(&clusters.with_lists(separate)),
    );
    Ok(())
}
