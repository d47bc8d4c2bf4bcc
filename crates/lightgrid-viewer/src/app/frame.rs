//! One redraw (the order is in `app/mod.rs`'s docs): advance the camera and the animation,
//! render on the real-time path, blit the frame or the debug view onto the surface, draw the
//! panel, present.

use super::*;
use lightgrid::scene::FrameState;

impl App {
    pub(super) fn redraw(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        if let Some(reason) = self.lost.lock().ok().and_then(|mut l| l.take()) {
            bail!("the GPU device was lost ({reason}); restart the viewer");
        }
        // GPU errors no scope returned to its call: on native a bug, already printed; on the
        // web every validation error of the last frames (`web.rs`), undone like a failed frame.
        for e in lightgrid::gpu::take_late_errors() {
            if cfg!(target_arch = "wasm32") {
                #[cfg(target_arch = "wasm32")]
                web::console_error(&format!("lightgrid: {e}"));
                let failed = (self.applied.pipeline.clone(), self.applied.settings);
                if !self
                    .refused
                    .iter()
                    .any(|(p, s, _)| (p, s) == (&failed.0, &failed.1))
                {
                    self.refused.push((failed.0, failed.1, e.to_string()));
                }
                self.recover(e)?;
            }
        }
        let now = Instant::now();
        self.check_patience(now)?;
        self.collect_analysis()?;
        if !self.pending(now) {
            self.run_due_steps()?;
        }
        self.apply_draft(now)?;
        self.follow_size(now)?;
        let Some(win) = &self.win else { return Ok(()) };
        let size = win.window.inner_size();
        if size.width == 0 || size.height == 0 {
            return Ok(());
        }
        self.advance(now);
        if !self.render()? {
            return Ok(());
        }
        self.after_frame(event_loop, now)
    }

    /// Move the fly camera by the held keys and step the animation.
    pub(super) fn advance(&mut self, now: Instant) {
        let dt = self
            .last_display
            .map_or(0.0, |t| now.duration_since(t).as_secs_f32().min(0.25));
        let axis = |plus: KeyCode, minus: KeyCode| {
            f32::from(u8::from(self.keys.contains(&plus)))
                - f32::from(u8::from(self.keys.contains(&minus)))
        };
        let m = Movement {
            forward: axis(KeyCode::KeyW, KeyCode::KeyS),
            right: axis(KeyCode::KeyD, KeyCode::KeyA),
            up: axis(KeyCode::KeyE, KeyCode::KeyQ),
        };
        if !m.is_still() {
            let fast = if self.keys.contains(&KeyCode::ShiftLeft) {
                4.0
            } else {
                1.0
            };
            let speed = self.fly_speed * fast;
            let fly = self.fly_camera();
            fly.speed = speed;
            fly.advance(m, dt);
            self.generation += 1;
        }
        if self.playing && !std::mem::take(&mut self.hold_frame) {
            self.frame = (self.frame + 1) % self.scene.frame_count();
        }
    }

    /// What the window shows now: the scene at the current frame, seen by the fly camera
    /// when there is one (the path's lens kept).
    pub(super) fn frame_state(&self) -> FrameState {
        let mut state = self.scene.frame(self.frame);
        if let Some(fly) = &self.fly {
            state.camera = fly.camera(&state.camera);
        }
        state
    }

    /// The fly camera, starting where the path's camera is now.
    pub(super) fn fly_camera(&mut self) -> &mut FlyCamera {
        let camera = self.scene.camera_path.at(self.frame);
        let speed = self.fly_speed;
        self.fly.get_or_insert_with(|| FlyCamera {
            speed,
            ..FlyCamera::from_camera(&camera)
        })
    }

    /// Render and present one frame; false when nothing was shown.
    pub(super) fn render(&mut self) -> Result<bool> {
        let ctx = self.ctx.clone();
        let pipeline = self.applied.pipeline.clone();
        let state = self.frame_state();
        let win = self.win.as_mut().context("no window")?;
        // The surface first: a frame is rendered only when it can be shown.
        let texture = match win.surface.acquire(&ctx)? {
            Acquired::Frame(t) => t,
            Acquired::Skip => {
                self.idle_until = Some(Instant::now() + SKIP_PAUSE);
                return Ok(false);
            }
        };
        let held = (win.renderer.scene()).is_some_and(|s| Arc::ptr_eq(s, &self.scene));
        let rendered = match held {
            true => Ok(()),
            false => win.renderer.set_scene(self.scene.clone()),
        };
        // On the web a screenshot cannot wait for its frame's report (`after.rs`): no new
        // frame replaces the shown one until that report is back.
        let hold = cfg!(target_arch = "wasm32")
            && !self.screenshots.is_empty()
            && self
                .submitted
                .is_some_and(|s| !self.recent.iter().any(|f| f.serial == s));
        let rendered = match hold {
            true => rendered.map(|()| None),
            false => rendered.and_then(|()| win.renderer.render_frame(&state, &pipeline).map(Some)),
        };
        match rendered {
            Ok(None) => {}
            Ok(Some(s)) => {
                self.submitted = Some(s.serial);
                // On the web a frame's errors arrive later: it is good once it has finished.
                if cfg!(not(target_arch = "wasm32")) {
                    self.last_good = self.applied.clone();
                }
            }
            Err(e) => {
                self.recover(e)?;
                return Ok(false);
            }
        }
        let finished = win.renderer.poll_finished()?;
        self.observe(finished);
        self.present(texture)
    }

    pub(super) fn observe(&mut self, finished: Vec<FinishedFrame>) {
        for f in finished {
            if cfg!(target_arch = "wasm32") && Some(f.serial) == self.submitted {
                self.last_good = self.applied.clone();
            }
            self.figures.finished(&f);
            if self.recent.len() == 8 {
                self.recent.pop_front();
            }
            self.recent.push_back(f);
        }
    }

    /// The image the window shows now: the debug view's (once one came back) or the frame.
    pub(super) fn source(win: &Win, view: DebugView) -> &wgpu::TextureView {
        match (&win.debug_texture, view) {
            (Some(t), v) if v != DebugView::Shaded => t,
            _ => win.renderer.display_view(),
        }
    }

    pub(super) fn present(&mut self, texture: wgpu::SurfaceTexture) -> Result<bool> {
        let ctx = self.ctx.clone();
        let win = self.win.as_mut().context("no window")?;
        let target = texture.texture.create_view(&Default::default());
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let source = Self::source(win, self.applied.view);
        win.blit.encode(&ctx.device, &mut encoder, source, &target);
        let actions = self.draw_ui(&mut encoder, &target)?;
        ctx.queue.submit([encoder.finish()]);
        ctx.queue.present(texture);
        let now = Instant::now();
        if let Some(t) = self.last_display {
            self.figures
                .displayed(now.duration_since(t).as_secs_f64() * 1e3);
        }
        self.last_display = Some(now);
        self.report.frames += 1;
        for a in actions {
            self.panel_action(a);
        }
        Ok(true)
    }

    /// The panel (or, hidden, the one status line) drawn over `target`.
    pub(super) fn draw_ui(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
    ) -> Result<Vec<PanelAction>> {
        let analysis_current = self.analysis_current(false);
        let win = self.win.as_mut().context("no window")?;
        let input = win.egui.state.take_egui_input(&win.window);
        let before = self.draft.clone();
        let adapter = self.report.adapter.clone();
        let info = PanelInfo {
            adapter: &adapter,
            scene: &self.scene.name,
            variable_lights: !self.applied.request.is_file()
                && lightgrid::scene::catalog::find(&self.applied.request.spec)
                    .is_ok_and(|s| s.variable_lights),
            lights: self.scene.lights.len(),
            frame: self.frame,
            frame_count: self.scene.frame_count(),
            playing: self.playing,
            flying: self.fly.is_some(),
            fly_speed: self.fly_speed,
            render_size: win.renderer.size(),
            msaa_counts: match self.draft.settings.gbuffer {
                GBufferFormat::F16 => &self.msaa_counts[0],
                GBufferFormat::F32 => &self.msaa_counts[1],
            },
            figures: &self.figures,
            analysis: self
                .analysis
                .latest
                .as_ref()
                .map(|(_, a)| (a, analysis_current)),
            analysing: self.analysis.in_flight,
            sample_every_second: self.analysis.every_second,
            message: self.message.as_deref(),
            applying: self.draft != self.applied,
            refused: self
                .refused
                .iter()
                .filter(|(_, s, _)| *s == self.draft.settings)
                .map(|(p, _, why)| (p.as_str(), why.as_str()))
                .collect(),
        };
        // A window too small for the panel leaves it out rather than letting egui shrink it
        // to that size (it would stay shrunk when the window grows back).
        let (sw, sh) = win.surface.size();
        let panel_on = self.panel && sw >= MIN_PANEL_WINDOW.0 && sh >= MIN_PANEL_WINDOW.1;
        let draft = &mut self.draft;
        let mut actions = Vec::new();
        let mut output = win.egui.ctx.run_pass(input, |ctx| {
            if panel_on {
                actions = panel::draw(ctx, draft, &info);
            } else {
                egui::Area::new(egui::Id::unique("lightgrid status"))
                    .fixed_pos([6.0, 4.0])
                    .show(ctx, |ui| {
                        ui.label(
                            egui::RichText::new(info.figures.status_line())
                                .background_color(egui::Color32::from_black_alpha(160)),
                        );
                    });
            }
        });
        if self.draft != before {
            self.draft_edited = Some(Instant::now());
        }
        win.egui
            .state
            .handle_platform_output(&win.window, std::mem::take(&mut output.platform_output));
        let size = win.surface.size();
        win.egui.paint(
            &self.ctx.device,
            &self.ctx.queue,
            encoder,
            target,
            output,
            size,
        );
        Ok(actions)
    }

    pub(super) fn panel_action(&mut self, a: PanelAction) {
        match a {
            PanelAction::TogglePause => self.set_playing(!self.playing),
            PanelAction::Step(d) => self.step(d),
            PanelAction::JumpTo(f) => self.jump_to(f.min(self.scene.frame_count() - 1)),
            PanelAction::FollowPath => {
                self.fly = None;
                self.generation += 1;
            }
            PanelAction::FlySpeed(s) => self.fly_speed = s.clamp(0.01, 1e4),
            PanelAction::Analyse => self.analysis.wanted_now = true,
            PanelAction::SampleEverySecond(on) => self.analysis.every_second = on,
            PanelAction::Screenshot => self.queue_user_screenshot(),
            PanelAction::HidePanel => self.panel = false,
        }
    }

    pub(super) fn step(&mut self, d: i32) {
        let n = self.scene.frame_count() as i64;
        self.set_playing(false);
        self.jump_to((i64::from(self.frame) + i64::from(d)).rem_euclid(n) as u32);
    }

    /// Show animation frame `f` next.
    pub(super) fn jump_to(&mut self, f: u32) {
        self.frame = f;
        self.hold_frame = true;
        self.generation += 1;
    }

    pub(super) fn queue_user_screenshot(&mut self) {
        let stem = format!(
            "lightgrid-{}-{}-{}",
            self.scene
                .name
                .replace(|c: char| !c.is_ascii_alphanumeric() && c != '-', "_"),
            self.applied.pipeline,
            self.frame
        );
        self.screenshots
            .push_back(after::free_name(Path::new("."), &stem));
    }
}

impl EguiLayer {
    /// Draw the pass's shapes over `target` (a window of `size` pixels), with its texture
    /// changes.
    fn paint(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        output: egui::FullOutput,
        size: (u32, u32),
    ) {
        let primitives = self.ctx.tessellate(output.shapes, output.pixels_per_point);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [size.0, size.1],
            pixels_per_point: output.pixels_per_point,
        };
        for (id, deltas) in &output.textures_delta.set {
            for delta in deltas {
                self.renderer.update_texture(device, queue, *id, delta);
            }
        }
        let extra = self
            .renderer
            .update_buffers(device, queue, encoder, &primitives, &screen);
        if !extra.is_empty() {
            queue.submit(extra);
        }
        {
            let mut pass = encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("viewer panel"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: target,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                })
                .forget_lifetime();
            self.renderer.render(&mut pass, &primitives, &screen);
        }
        for id in &output.textures_delta.free {
            self.renderer.free_texture(id);
        }
    }
}
