//! What the panel edits, and what a change costs: the pipeline switches within the renderer
//! (it keeps every technique it made), settings rebuild the renderer, and the scene's lights,
//! spots and transparency reopen the scene (`scene::open`, the same way every command opens
//! it). A change that fails is reverted to the last state that rendered, with its message.

use lightgrid::debug_view::DebugView;
use lightgrid::pipelines::{self, Msaa, PipelineInfo};
use lightgrid::scene::SceneRequest;
use lightgrid::RenderSettings;

/// The viewer's configurable state.
#[derive(Clone, Debug, PartialEq)]
pub struct Controls {
    pub pipeline: String,
    pub settings: RenderSettings,
    pub request: SceneRequest,
    pub view: DebugView,
}

/// The work a change of [`Controls`] needs, most expensive first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Rebuild {
    Nothing,
    /// Another pipeline or view: the next frame uses it.
    Switch,
    /// New render settings (tile, slices, strategy, MSAA, G-buffer) or size: a new renderer.
    Renderer,
    /// The scene's lights, spots or transparency: the scene is opened again (and a new
    /// renderer made, whose upload it needs).
    Scene,
}

impl Controls {
    /// What going from `self` (applied) to `next` needs.
    pub fn rebuild_for(&self, next: &Controls) -> Rebuild {
        if self.request != next.request {
            Rebuild::Scene
        } else if self.settings != next.settings {
            Rebuild::Renderer
        } else if self.pipeline != next.pipeline || self.view != next.view {
            Rebuild::Switch
        } else {
            Rebuild::Nothing
        }
    }
}

/// Why `info` cannot render with `settings`, or None when it can.
pub fn refusal(info: &PipelineInfo, settings: &RenderSettings) -> Option<String> {
    match info.msaa {
        Msaa::Refused(reason) if settings.grid.samples > 1 => {
            Some(format!("{} does not render with MSAA: {reason}", info.id))
        }
        _ => None,
    }
}

/// Built for a web page (`app/web.rs`).
pub const WEB: bool = cfg!(target_arch = "wasm32");

/// Why the page offers no debug view and no analysis.
pub const NATIVE_ONLY: &str = "debug views and analysis frames are native-only: they read the \
GPU's results back and wait for them, which a web page cannot do (run `lightgrid view`)";

/// The registry's pipelines with why each cannot run now (None: it can).
pub fn pipeline_choices(settings: &RenderSettings) -> Vec<(&'static PipelineInfo, Option<String>)> {
    pipelines::PIPELINES
        .iter()
        .map(|p| (p, refusal(p, settings)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn controls() -> Controls {
        Controls {
            pipeline: "forward".into(),
            settings: RenderSettings::default(),
            request: SceneRequest::new("robots-many"),
            view: DebugView::Shaded,
        }
    }

    #[test]
    fn each_change_rebuilds_what_it_must() {
        let a = controls();
        assert_eq!(a.rebuild_for(&a.clone()), Rebuild::Nothing);
        let mut b = a.clone();
        b.pipeline = "tiled_deferred".into();
        assert_eq!(a.rebuild_for(&b), Rebuild::Switch);
        b.view = DebugView::WastedWork;
        assert_eq!(a.rebuild_for(&b), Rebuild::Switch);
        b.settings.grid.tile_size = 32;
        assert_eq!(a.rebuild_for(&b), Rebuild::Renderer);
        b.request.params.spot_fraction = 0.5;
        assert_eq!(a.rebuild_for(&b), Rebuild::Scene);
        let mut c = a.clone();
        c.request.params.transparency = !c.request.params.transparency;
        assert_eq!(a.rebuild_for(&c), Rebuild::Scene);
    }

    #[test]
    fn msaa_greys_out_no_pipeline_since_every_one_renders_with_it() {
        for msaa in [1, 4] {
            let s = RenderSettings {
                grid: lightgrid::CullConfig {
                    samples: msaa,
                    ..lightgrid::CullConfig::default()
                },
                ..Default::default()
            };
            for (p, why) in pipeline_choices(&s) {
                assert_eq!(why, None, "{} at {msaa}x", p.id);
                assert_eq!(p.msaa, Msaa::Supported, "{}", p.id);
            }
        }
    }
}
