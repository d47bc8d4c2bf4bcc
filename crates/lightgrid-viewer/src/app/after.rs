//! After a frame is shown: the patience of a scripted session, queued screenshots (drawn
//! like the window, without the panel), `--exit-after-frames`, and the analysis frames sent
//! to and collected from the worker.

use super::*;

impl App {
    /// A scripted run that has waited too long (for a settled view or a screenshot) ends
    /// with what it waited for, rather than hanging.
    pub(super) fn check_patience(&mut self, now: Instant) -> Result<()> {
        if let Some(s) = self.requested_size {
            if self.win.as_ref().is_some_and(|w| w.surface.size() == s) {
                self.requested_size = None;
            }
        }
        let waiting = self.pending(now) || !self.screenshots.is_empty();
        if !waiting {
            self.pending_since = None;
            return Ok(());
        }
        let since = *self.pending_since.get_or_insert(now);
        if self.scripted && now.duration_since(since) > SCRIPT_PATIENCE {
            let win = self.win.as_ref().context("no window")?;
            bail!(
                "the scripted session waited {} s for the view to settle (window {:?}{}, renderer {:?}, {} screenshot(s) waiting)",
                SCRIPT_PATIENCE.as_secs(),
                win.surface.size(),
                self.requested_size
                    .map_or(String::new(), |s| format!(" of the {s:?} asked for")),
                win.renderer.size(),
                self.screenshots.len()
            );
        }
        Ok(())
    }

    pub(super) fn after_frame(&mut self, event_loop: &ActiveEventLoop, now: Instant) -> Result<()> {
        if !self.pending(now) {
            if let Some(path) = self.screenshots.front().cloned() {
                let taken = match self.screenshot(&path) {
                    Ok(Shot::Retry) if self.screenshot_retries < MAX_SCREENSHOT_RETRIES => {
                        self.screenshot_retries += 1;
                        Ok(false)
                    }
                    Ok(Shot::Retry) => Err(anyhow!(
                        "{}: {MAX_SCREENSHOT_RETRIES} frames in a row overflowed their light lists; no screenshot written",
                        path.display()
                    )),
                    Ok(Shot::Taken) => Ok(true),
                    Ok(Shot::Wait) => Ok(false),
                    Err(e) => Err(e),
                };
                match taken {
                    Ok(false) => {}
                    Ok(true) => {
                        eprintln!(
                            "screenshot {} ({}, frame {}, {}, {:?})",
                            path.display(),
                            self.applied.pipeline,
                            self.frame,
                            self.applied.view.name(),
                            self.win
                                .as_ref()
                                .map(|w| w.renderer.size())
                                .unwrap_or_default()
                        );
                        self.screenshots.pop_front();
                        self.screenshot_retries = 0;
                        self.report.screenshots.push(path);
                    }
                    Err(e) if self.scripted => return Err(e),
                    Err(e) => {
                        self.screenshots.pop_front();
                        self.screenshot_retries = 0;
                        self.message = Some(format!("{e:#}"));
                    }
                }
            } else {
                self.settled = self.settled.saturating_add(1);
            }
        }
        self.leave_when_done(event_loop);
        #[cfg(target_arch = "wasm32")]
        self.publish();
        self.request_analysis(now)
    }

    pub(super) fn leave_when_done(&mut self, event_loop: &ActiveEventLoop) {
        let Some(n) = self.exit_after else { return };
        if self.settled < n || self.next_step < self.script.len() {
            return;
        }
        if !self.leaving {
            self.leaving = true;
            if let Some(p) = self.final_screenshot.take() {
                self.screenshots.push_back(p);
            }
        }
        if self.screenshots.is_empty() {
            event_loop.exit();
        }
    }

    /// Draw what the window shows (without the panel) into a texture of the surface's format
    /// and write it. A shaded frame is first waited for and checked: an overflowed frame is
    /// retried on the next one, a frame with loops cut short is refused.
    pub(super) fn screenshot(&mut self, path: &Path) -> Result<Shot> {
        let ctx = self.ctx.clone();
        let view = self.applied.view;
        let win = self.win.as_mut().context("no window")?;
        let debug = view != DebugView::Shaded && win.debug_texture.is_some();
        if !debug {
            // On the web nothing waits: the shown frame's report comes back a frame or two
            // later, and the screenshot waits for it.
            #[cfg(not(target_arch = "wasm32"))]
            {
                let finished = win.renderer.finish()?;
                self.observe(finished);
            }
            let serial = self.submitted.context("no frame rendered yet")?;
            let Some(report) = self.recent.iter().rfind(|f| f.serial == serial) else {
                return Ok(if cfg!(target_arch = "wasm32") {
                    Shot::Wait
                } else {
                    Shot::Retry
                });
            };
            if report.truncated_loops > 0 || report.fragments_off_bounds > 0 {
                bail!(
                    "{}: the frame shown was wrong ({} shader loops cut short, {} fragments off their cell's bounds); no screenshot written",
                    path.display(),
                    report.truncated_loops,
                    report.fragments_off_bounds
                );
            }
            if report.overflowed {
                return Ok(Shot::Retry);
            }
        }
        let win = self.win.as_ref().context("no window")?;
        let size = match (&self.analysis.latest, debug) {
            (Some((_, a)), true) => a
                .image
                .as_ref()
                .map_or(win.renderer.size(), |i| i.image.dimensions()),
            _ => win.renderer.size(),
        };
        let capture = Capture::new(&ctx.device, win.surface.format(), size);
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        win.blit.encode(
            &ctx.device,
            &mut encoder,
            Self::source(win, view),
            &capture.view,
        );
        ctx.queue.submit([encoder.finish()]);
        #[cfg(not(target_arch = "wasm32"))]
        {
            let image = capture.read(&ctx.device, &ctx.queue)?;
            lightgrid::image_io::save_png(&image, path)?;
        }
        #[cfg(target_arch = "wasm32")]
        web::read_later(&ctx, capture, path.to_string_lossy().into_owned());
        Ok(Shot::Taken)
    }

    pub(super) fn collect_analysis(&mut self) -> Result<()> {
        loop {
            match self.done.try_recv() {
                Ok(done) => {
                    self.analysis.in_flight = false;
                    match done.result {
                        Ok(a) => {
                            self.upload_debug(&a);
                            self.analysis.latest = Some((done.generation, a));
                        }
                        Err(e) if self.scripted => bail!("analysis frame: {e}"),
                        Err(e) => {
                            self.analysis.failed_generation = Some(done.generation);
                            self.message = Some(format!("analysis frame: {e}"));
                        }
                    }
                }
                Err(TryRecvError::Empty) => return Ok(()),
                Err(TryRecvError::Disconnected) => bail!("the analysis thread stopped"),
            }
        }
    }

    pub(super) fn upload_debug(&mut self, a: &Analysed) {
        let Some(win) = &mut self.win else { return };
        win.debug_texture = a
            .image
            .as_ref()
            .map(|img| upload_image(&self.ctx.device, &self.ctx.queue, &img.image));
    }

    /// Send the next analysis job: continuously while a debug view shows, else on demand or
    /// once a second when asked to.
    pub(super) fn request_analysis(&mut self, now: Instant) -> Result<()> {
        let a = &self.analysis;
        // No analysis worker on the web (`web.rs`): the debug views are native-only there.
        if a.in_flight || cfg!(target_arch = "wasm32") {
            return Ok(());
        }
        let since = a.last_request.map(|t| now.duration_since(t));
        let due = |every: Duration| since.is_none_or(|s| s >= every);
        let want = if self.applied.view != DebugView::Shaded {
            let current = self.analysis_current(false);
            (!current && a.failed_generation != Some(self.generation))
                || (self.playing && due(DEBUG_REFRESH))
        } else {
            a.wanted_now || (a.every_second && due(Duration::from_secs(1)))
        };
        if !want {
            return Ok(());
        }
        let win = self.win.as_ref().context("no window")?;
        let job = Job {
            generation: self.generation,
            scene: self.scene.clone(),
            state: self.frame_state(),
            pipeline: pipelines::find(&self.applied.pipeline)?.id,
            settings: self.applied.settings,
            size: win.renderer.size(),
            view: self.applied.view,
        };
        self.jobs
            .send(job)
            .map_err(|_| anyhow!("the analysis thread stopped"))?;
        self.analysis.in_flight = true;
        self.analysis.wanted_now = false;
        self.analysis.last_request = Some(now);
        Ok(())
    }
}

/// `dir/stem.png`, or `dir/stem-2.png`, ... : a name nothing has yet.
pub(super) fn free_name(dir: &Path, stem: &str) -> PathBuf {
    let mut path = dir.join(format!("{stem}.png"));
    let mut n = 2;
    while path.exists() {
        path = dir.join(format!("{stem}-{n}.png"));
        n += 1;
    }
    path
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    pub(super) fn free_name_never_names_an_existing_file() {
        let dir = std::env::temp_dir().join(format!("lightgrid-free-name-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let a = free_name(&dir, "shot");
        assert_eq!(a, dir.join("shot.png"));
        std::fs::write(&a, b"x").unwrap();
        let b = free_name(&dir, "shot");
        assert_eq!(b, dir.join("shot-2.png"));
        std::fs::write(&b, b"x").unwrap();
        assert_eq!(free_name(&dir, "shot"), dir.join("shot-3.png"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
