//! Keys and the mouse: WASD/QE fly, drags turn, the wheel sets the speed, and the shortcut
//! keys the panel lists.

use super::*;

impl App {
    pub(super) fn key(
        &mut self,
        event_loop: &ActiveEventLoop,
        code: KeyCode,
        pressed: bool,
        repeat: bool,
    ) {
        if !pressed {
            self.keys.remove(&code);
            return;
        }
        self.keys.insert(code);
        if repeat {
            return;
        }
        // The keys for the panel's buttons do what the buttons do.
        let action = match code {
            KeyCode::Space => Some(PanelAction::TogglePause),
            KeyCode::Period => Some(PanelAction::Step(1)),
            KeyCode::Comma => Some(PanelAction::Step(-1)),
            KeyCode::KeyI => Some(PanelAction::Analyse),
            KeyCode::KeyC => Some(PanelAction::FollowPath),
            KeyCode::F12 | KeyCode::KeyP => Some(PanelAction::Screenshot),
            _ => None,
        };
        if let Some(a) = action {
            return self.panel_action(a);
        }
        match code {
            KeyCode::Escape => event_loop.exit(),
            KeyCode::BracketRight => self.cycle_pipeline(1),
            KeyCode::BracketLeft => self.cycle_pipeline(-1),
            KeyCode::KeyV => self.draft.view = self.draft.view.next(),
            KeyCode::KeyH | KeyCode::F1 => self.panel = !self.panel,
            _ => {}
        }
    }

    /// The next pipeline of the registry that runs with the current settings.
    pub(super) fn cycle_pipeline(&mut self, d: i32) {
        let n = PIPELINES.len() as i32;
        let at = PIPELINES
            .iter()
            .position(|p| p.id == self.draft.pipeline)
            .unwrap_or(0) as i32;
        for k in 1..=n {
            let p = &PIPELINES[(at + d * k).rem_euclid(n) as usize];
            if refusal(p, &self.draft.settings).is_none() {
                self.draft.pipeline = p.id.to_string();
                return;
            }
        }
    }

    pub(super) fn mouse_button(&mut self, button: MouseButton, pressed: bool, over_panel: bool) {
        let turns = button == MouseButton::Right || (button == MouseButton::Left && !over_panel);
        if pressed && turns {
            self.drag = Some((button, None));
        } else if !pressed && self.drag.is_some_and(|(b, _)| b == button) {
            self.drag = None;
        }
    }

    pub(super) fn cursor(&mut self, x: f64, y: f64) {
        let Some((button, last)) = self.drag else {
            return;
        };
        if let Some((lx, ly)) = last {
            let (dx, dy) = ((x - lx) as f32, (y - ly) as f32);
            if dx != 0.0 || dy != 0.0 {
                self.fly_camera().turn(dx, dy);
                self.generation += 1;
            }
        }
        self.drag = Some((button, Some((x, y))));
    }

    pub(super) fn wheel(&mut self, lines: f32) {
        if lines.is_finite() {
            self.fly_speed = (self.fly_speed * 1.25f32.powf(lines)).clamp(0.01, 1e4);
        }
    }
}
