//! `lightgrid view`: the interactive viewer (`lightgrid_viewer`). Everything a window cannot
//! fix later is checked here first: the pipeline and settings, the scene options, the script
//! (its pipelines, tiles and sample counts) and every file it would write.

use crate::args::{check_applies, parse_size, RendererArgs, SceneOptions, Size, MAX_COUNT};
use crate::files::{Files, Kind};
use anyhow::{Context, Result};
use clap::Args;
use lightgrid::debug_view::DebugView;
use lightgrid::pipelines;
use lightgrid::pipelines::ids;
use lightgrid_viewer::script::{self, Action, Step};
use std::path::PathBuf;

/// The pipeline the viewer opens with: tiled deferred shading (tiled-shading §2), the
/// fastest on lavapipe at the catalog scenes' sizes (README, results).
const DEFAULT_PIPELINE: &str = ids::TILED_DEFERRED;

#[derive(Args)]
pub(crate) struct ViewArgs {
    #[command(flatten)]
    pub(crate) scene: SceneOptions,
    /// Pipeline to start with (see `lightgrid list`; the panel and [ ] switch live). The
    /// default is a culled one: `forward` loops every light per fragment, seconds per frame
    /// on a software adapter.
    #[arg(long, default_value = DEFAULT_PIPELINE)]
    pub(crate) pipeline: String,
    /// Window size WIDTHxHEIGHT in pixels (default: the scene's own size).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_size)]
    pub(crate) size: Option<Size>,
    /// Animation frame to start at.
    #[arg(long, allow_hyphen_values = true, default_value_t = 0)]
    pub(crate) frame: u32,
    /// Start with the animation paused.
    #[arg(long)]
    pub(crate) paused: bool,
    /// View to start with: shaded, lights (lights per cell), bounds (cell depth bounds) or
    /// wasted (lighting computations above the ideal, per pixel).
    #[arg(long, default_value = "shaded", value_parser = crate::args::parse_view)]
    pub(crate) view: DebugView,
    /// A scripted session: steps `at N ACTION` separated by `;` (N: settled frames shown).
    /// Actions: pipeline ID, tile N, msaa N, view V, resize WxH, frame F, pause, play,
    /// panel on|off, screenshot FILE.png.
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) script: Option<String>,
    /// Close the window after N settled frames (1 to 1000) and the script's steps.
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u32).range(1..=MAX_COUNT))]
    pub(crate) exit_after_frames: Option<u32>,
    /// Write what the window shows (without the panel) as PNG when it closes after
    /// --exit-after-frames.
    #[arg(long, requires = "exit_after_frames")]
    pub(crate) screenshot: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) renderer: RendererArgs,
}

/// A script's steps, with what can be checked before a window opens checked (the settings
/// table's steps by their rows, in `script::parse`).
fn checked_script(text: &str, files: &mut Files) -> Result<Vec<Step>> {
    let steps = script::parse(text).map_err(|e| anyhow::anyhow!("--script: {e}"))?;
    for step in &steps {
        let at = format!("--script step at {}", step.at);
        match &step.action {
            Action::Pipeline(id) => {
                pipelines::find(id).with_context(|| at.clone())?;
            }
            Action::Tile(n) => {
                lightgrid::frame::validate_tile_size(*n).with_context(|| at.clone())?;
            }
            Action::Screenshot(path) => files.output(&at, Some(path), Kind::Png)?,
            _ => {}
        }
    }
    Ok(steps)
}

pub(crate) fn view(adapter: Option<&str>, a: &ViewArgs) -> Result<()> {
    let info = pipelines::find(&a.pipeline)?;
    let settings = a.renderer.settings()?;
    check_applies(&a.renderer.given(), &[info], &settings)?;
    let mut files = Files::default();
    files.output("--screenshot", a.screenshot.as_deref(), Kind::Png)?;
    let script = match &a.script {
        Some(text) => checked_script(text, &mut files)?,
        None => Vec::new(),
    };
    a.scene.claim(&mut files)?;
    let request = a.scene.request()?;
    let report = lightgrid_viewer::run(lightgrid_viewer::ViewOptions {
        adapter: adapter.map(str::to_string),
        request,
        pipeline: info.id.to_string(),
        settings,
        size: a.size.map(|Size(w, h)| (w, h)),
        frame: a.frame,
        paused: a.paused,
        view: a.view,
        script,
        exit_after_frames: a.exit_after_frames,
        screenshot: a.screenshot.clone(),
    })?;
    eprintln!(
        "{} frames shown on {} ({} fps over the last second, GPU {} ms); {} overflowed their lists, {} had shader loops cut short{}",
        report.frames,
        report.adapter,
        report.fps.map_or("-".into(), |f| format!("{f:.1}")),
        report.gpu_ms.map_or("n/a".into(), |m| format!("{m:.1}")),
        report.overflowed,
        report.truncated,
        if report.screenshots.is_empty() {
            String::new()
        } else {
            format!("; {} screenshot(s) written", report.screenshots.len())
        }
    );
    Ok(())
}
