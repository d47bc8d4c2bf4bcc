//! What holds a scripted session and how changes are applied: a frame is *settled* when no
//! resize, change or stale debug view is pending; script steps run one per settled frame;
//! a change switches the pipeline, makes a renderer or reopens the scene, and a failing
//! one goes back to the last state that rendered.

use super::*;

impl App {
    /// Something the next frames will change by themselves: scripts and screenshots wait.
    pub(super) fn pending(&self, now: Instant) -> bool {
        let Some(win) = &self.win else { return true };
        let size_settling = win
            .size_changed_at
            .is_some_and(|t| now.duration_since(t) < SETTLE);
        let wrong_size = win.renderer.size() != render_size(&self.ctx, win.surface.size());
        let debug_stale = self.applied.view != DebugView::Shaded
            && self.analysis.failed_generation != Some(self.generation)
            && !self.analysis_current(true);
        let resize_asked = self.requested_size.is_some_and(|s| s != win.surface.size());
        size_settling || wrong_size || resize_asked || self.draft != self.applied || debug_stale
    }

    /// The newest analysis frame shows the current state (and, paused, the current frame);
    /// with `image`, it also has the debug view's image.
    pub(super) fn analysis_current(&self, image: bool) -> bool {
        self.analysis.latest.as_ref().is_some_and(|(g, a)| {
            *g == self.generation
                && (self.playing || a.stats.frame == self.frame)
                && (!image || a.image.is_some())
        })
    }

    /// Run the steps that are due, together in this frame: their changes of settings are
    /// gathered and applied once (10,000 steps at frame 0 cost one frame and one renderer,
    /// not 10,000 frames). A screenshot or a resize ends the batch, since it must see the
    /// frame the steps before it make; none runs while a screenshot waits.
    pub(super) fn run_due_steps(&mut self) -> Result<()> {
        let mut gathered: Option<(Controls, Vec<String>)> = None;
        while self.screenshots.is_empty() && self.requested_size.is_none() {
            let Some(step) = self.script.get(self.next_step).cloned() else {
                break;
            };
            if step.at > self.settled {
                break;
            }
            self.next_step += 1;
            let what = format!("script step at {}: {:?}", step.at, step.action);
            let (next, _) = gathered.get_or_insert_with(|| (self.applied.clone(), Vec::new()));
            if Self::change_controls(next, &step).with_context(|| what.clone())? {
                if let Some((_, steps)) = &mut gathered {
                    steps.push(what);
                }
                continue;
            }
            // The gathered changes first: this step comes after them.
            self.apply_gathered(gathered.take())?;
            self.run_step(&step).with_context(|| what)?;
        }
        self.apply_gathered(gathered)
    }

    /// Apply the settings several steps changed, naming them when it fails.
    fn apply_gathered(&mut self, gathered: Option<(Controls, Vec<String>)>) -> Result<()> {
        let Some((next, steps)) = gathered else {
            return Ok(());
        };
        self.apply(next)
            .map_err(|e| anyhow!(e))
            .with_context(|| steps.join("; "))
    }

    /// Fold a step that changes the settings into `next`; false for a step that acts at once
    /// (frame, pause, play, panel, resize, screenshot).
    fn change_controls(next: &mut Controls, step: &Step) -> Result<bool> {
        match &step.action {
            Action::Pipeline(id) => next.pipeline = pipelines::find(id)?.id.to_string(),
            Action::Tile(n) => next.settings.grid.tile_size = *n,
            Action::Setting(flag, value) => {
                let axis = pipelines::find_axis(flag).context("a row of the settings table")?;
                (axis.set)(&mut next.settings, value).map_err(|e| anyhow!(e))?;
            }
            Action::View(v) => next.view = *v,
            Action::Spots(f) => next.request.params.spot_fraction = *f,
            Action::Transparency(on) => next.request.params.transparency = *on,
            Action::AddLights(n) => {
                next.request.add_lights = (*n > 0).then_some(lightgrid::scene::AddLights {
                    count: *n,
                    range: None,
                })
            }
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// A step that acts at once (those [`Self::change_controls`] does not gather), or any
    /// step alone.
    pub(super) fn run_step(&mut self, step: &Step) -> Result<()> {
        let mut next = self.applied.clone();
        if Self::change_controls(&mut next, step)? {
            return self.apply(next).map_err(|e| anyhow!(e));
        }
        match &step.action {
            Action::Resize(w, h) => {
                let win = self.win.as_ref().context("no window")?;
                let _ = win
                    .window
                    .request_inner_size(winit::dpi::PhysicalSize::new(*w, *h));
                // Pending until the surface has it (X11 answers with a later event).
                self.requested_size = Some((*w, *h));
            }
            Action::Frame(f) => {
                self.scene.check_frame(*f)?;
                self.jump_to(*f);
            }
            Action::Pause => self.set_playing(false),
            Action::Play => self.set_playing(true),
            Action::Panel(on) => self.panel = *on,
            Action::Screenshot(path) => self.screenshots.push_back(path.clone()),
            _ => unreachable!("settings changes are gathered above"),
        }
        Ok(())
    }

    // --- applying changes -------------------------------------------------------------------

    /// Go to `next`: switch, make a renderer or reopen the scene, as the change needs.
    pub(super) fn apply(&mut self, next: Controls) -> Result<(), String> {
        let rebuild = self.applied.rebuild_for(&next);
        if rebuild == Rebuild::Nothing {
            return Ok(());
        }
        let info = pipelines::find(&next.pipeline).map_err(|e| e.to_string())?;
        if let Some(why) = refusal(info, &next.settings) {
            return Err(why);
        }
        if crate::controls::WEB && next.view != DebugView::Shaded {
            return Err(crate::controls::NATIVE_ONLY.into());
        }
        // Everything is made before anything is replaced, so a failure leaves the viewer as
        // it was.
        let opened = match rebuild {
            Rebuild::Scene => {
                Some(lightgrid::scene::open(&next.request).map_err(|e| e.to_string())?)
            }
            _ => None,
        };
        let renderer = match rebuild {
            Rebuild::Scene | Rebuild::Renderer => {
                let win = self.win.as_ref().ok_or("no window")?;
                let (w, h) = win.renderer.size();
                Some(Renderer::new(&self.ctx, w, h, next.settings).map_err(|e| e.to_string())?)
            }
            _ => None,
        };
        let scene = opened.map(|opened| {
            if let Some(w) = opened.warnings.first() {
                self.message = Some(format!(
                    "{} (and {} more warnings)",
                    w,
                    opened.warnings.len() - 1
                ));
            }
            opened.scene
        });
        self.install(next, scene, renderer);
        Ok(())
    }

    /// Put what `apply` or `recover` made in place and make `next` the applied state.
    fn install(&mut self, next: Controls, scene: Option<Scene>, renderer: Option<Renderer>) {
        if let Some(scene) = scene {
            self.set_scene(scene);
        }
        if let Some(r) = renderer {
            self.replace_renderer(r);
        }
        self.applied = next;
        // A script's or key's change is the panel's draft from now on too.
        self.draft = self.applied.clone();
        self.generation += 1;
        self.figures.restart_times();
        if let Some(win) = &self.win {
            win.window.set_title(&self.title());
        }
    }

    /// Apply the panel's draft once it has stopped changing (a pipeline or view at once).
    pub(super) fn apply_draft(&mut self, now: Instant) -> Result<()> {
        if self.draft == self.applied {
            return Ok(());
        }
        let quick = self.applied.rebuild_for(&self.draft) == Rebuild::Switch;
        let still = self
            .draft_edited
            .is_none_or(|t| now.duration_since(t) >= DRAFT_SETTLE);
        if !(quick || still) {
            return Ok(());
        }
        let next = self.draft.clone();
        if let Err(e) = self.apply(next) {
            if self.scripted {
                bail!("{e}");
            }
            self.message = Some(e);
            self.draft = self.applied.clone();
        }
        Ok(())
    }

    /// A frame failed to render: go back to the last state that rendered, or give up.
    pub(super) fn recover(&mut self, e: lightgrid::Error) -> Result<()> {
        if self.applied == self.last_good || self.scripted {
            return Err(anyhow!(e).context(format!("rendering with {}", self.applied.pipeline)));
        }
        self.message = Some(format!(
            "{}: {e}; back to the last setting that rendered",
            self.applied.pipeline
        ));
        let good = self.last_good.clone();
        // A new renderer for the old settings whatever the difference, so nothing of the
        // failed one stays.
        let win = self.win.as_ref().context("no window")?;
        let (w, h) = win.renderer.size();
        let renderer = Renderer::new(&self.ctx, w, h, good.settings)?;
        let scene = match self.applied.request != good.request {
            true => Some(lightgrid::scene::open(&good.request)?.scene),
            false => None,
        };
        self.install(good, scene, Some(renderer));
        Ok(())
    }

    /// Make a renderer at the window's size once it has settled.
    pub(super) fn follow_size(&mut self, now: Instant) -> Result<()> {
        let Some(win) = &mut self.win else {
            return Ok(());
        };
        let wanted = render_size(&self.ctx, win.surface.size());
        let settling = win
            .size_changed_at
            .is_some_and(|t| now.duration_since(t) < SETTLE);
        if wanted == win.renderer.size() || settling {
            return Ok(());
        }
        let renderer = Renderer::new(&self.ctx, wanted.0, wanted.1, self.applied.settings)?;
        self.replace_renderer(renderer);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::parse;

    /// Driven by the settings table: every value of every row, written as a script step, is
    /// what the next settings read back; a value the row refuses never reaches them.
    #[test]
    fn every_value_of_every_setting_is_a_script_step_the_settings_read_back() {
        let base = Controls {
            pipeline: "forward".into(),
            settings: lightgrid::RenderSettings::default(),
            request: lightgrid::scene::SceneRequest::new("robots-many"),
            view: DebugView::Shaded,
        };
        for axis in pipelines::AXES {
            let mut values: Vec<String> =
                (axis.values)().iter().map(|v| v.name.to_string()).collect();
            if values.is_empty() {
                // A number: the default and one more the row accepts.
                let default = (axis.get)(&lightgrid::RenderSettings::default());
                let other = if axis.flag == "msaa" { "4" } else { "16" };
                values = vec![default, other.to_string()];
            }
            for v in values {
                let steps = parse(&format!("{} {v}", axis.flag)).unwrap();
                let mut next = base.clone();
                assert!(App::change_controls(&mut next, &steps[0]).unwrap());
                assert_eq!((axis.get)(&next.settings), v, "{}", axis.flag);
            }
            let mut next = base.clone();
            let bad = Step {
                at: 0,
                action: Action::Setting(axis.flag, "no-such-value".into()),
            };
            assert!(
                App::change_controls(&mut next, &bad).is_err(),
                "{}",
                axis.flag
            );
            assert_eq!(next.settings, base.settings);
        }
    }
}
