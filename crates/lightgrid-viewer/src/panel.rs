//! The egui panel: what can be switched live (it edits a draft of [`Controls`], which the
//! window applies once it has stopped changing) and the live figures. Its buttons come back
//! as [`PanelAction`]s; the panel itself changes nothing but the draft.

use crate::analysis::Analysed;
use crate::controls::{pipeline_choices, Controls};
use crate::live::LiveFigures;
use egui::{Color32, RichText};
use lightgrid::debug_view::DebugView;
use lightgrid::scene::AddLights;

/// What the panel shows but does not edit.
pub struct PanelInfo<'a> {
    pub adapter: &'a str,
    pub scene: &'a str,
    /// The catalog scene takes a light count (`--lights`).
    pub variable_lights: bool,
    pub lights: usize,
    pub frame: u32,
    pub frame_count: u32,
    pub playing: bool,
    pub flying: bool,
    pub fly_speed: f32,
    pub render_size: (u32, u32),
    pub msaa_counts: &'a [u32],
    pub figures: &'a LiveFigures,
    /// The newest analysis frame, and whether it shows the current state.
    pub analysis: Option<(&'a Analysed, bool)>,
    pub analysing: bool,
    pub sample_every_second: bool,
    pub message: Option<&'a str>,
    /// Draft and applied differ: the change is waiting to be applied.
    pub applying: bool,
    /// Pipelines the GPU refused with these settings, and why.
    pub refused: Vec<(&'a str, &'a str)>,
}

/// Buttons pressed this frame.
#[derive(Clone, Debug, PartialEq)]
pub enum PanelAction {
    TogglePause,
    Step(i32),
    JumpTo(u32),
    FollowPath,
    FlySpeed(f32),
    Analyse,
    SampleEverySecond(bool),
    Screenshot,
    HidePanel,
}

pub fn draw(ctx: &egui::Context, draft: &mut Controls, info: &PanelInfo) -> Vec<PanelAction> {
    let mut actions = Vec::new();
    egui::Window::new("lightgrid")
        .default_pos([8.0, 8.0])
        .default_width(300.0)
        .resizable(true)
        .vscroll(true)
        .show(ctx, |ui| {
            ui.label(format!("{} on {}", info.scene, info.adapter));
            status(ui, info);
            ui.separator();
            technique(ui, draft, info);
            ui.separator();
            debug_views(ui, draft, info, &mut actions);
            ui.separator();
            figures(ui, info);
            ui.separator();
            animation(ui, info, &mut actions);
            ui.separator();
            scene(ui, draft, info);
            ui.separator();
            ui.horizontal(|ui| {
                let shot = ui.button("screenshot (F12)");
                remember_spot(ui.ctx(), "screenshot", shot.rect);
                if shot.clicked() {
                    actions.push(PanelAction::Screenshot);
                }
                if ui.button("hide panel (H)").clicked() {
                    actions.push(PanelAction::HidePanel);
                }
            });
            ui.label(
                RichText::new(
                    "WASD/QE fly, right-drag (or left-drag on the image) turn, wheel speed, \
                     C camera path, Space pause, ,/. step, [/] pipeline, V view, I analyse, Esc quit",
                )
                .small(),
            );
        });
    actions
}

fn status(ui: &mut egui::Ui, info: &PanelInfo) {
    let f = info.figures;
    let bad = f.overflowed + f.truncated + f.off_bounds > 0;
    ui.label(RichText::new(f.status_line()).color(if bad {
        Color32::from_rgb(255, 140, 60)
    } else {
        ui.visuals().text_color()
    }));
    if let Some(m) = info.message {
        ui.label(RichText::new(m).color(Color32::from_rgb(255, 110, 110)));
    }
    if info.applying {
        ui.label(RichText::new("applying…").italics());
    }
}

fn technique(ui: &mut egui::Ui, draft: &mut Controls, info: &PanelInfo) {
    let settings = draft.settings;
    let combo = egui::ComboBox::from_label("pipeline")
        .selected_text(draft.pipeline.as_str())
        .show_ui(ui, |ui| {
            for (p, refused) in pipeline_choices(&settings) {
                let refused = refused.or_else(|| {
                    let gpu = info.refused.iter().find(|(id, _)| *id == p.id);
                    gpu.map(|(_, why)| why.to_string())
                });
                let r = ui.add_enabled(
                    refused.is_none(),
                    egui::Button::selectable(draft.pipeline == p.id, p.id),
                );
                let r = r.on_hover_text(p.description);
                let r = match &refused {
                    Some(why) => r.on_disabled_hover_text(why),
                    None => r,
                };
                remember_spot(ui.ctx(), &format!("pipeline:{}", p.id), r.rect);
                if r.clicked() {
                    draft.pipeline = p.id.to_string();
                }
            }
        });
    remember_spot(ui.ctx(), "pipeline", combo.response.rect);
    let pipeline = lightgrid::pipelines::find(&draft.pipeline).ok();
    let grid = pipeline.is_some_and(|p| p.uses_grid);
    ui.add_enabled(
        grid,
        egui::Slider::new(
            &mut draft.settings.grid.tile_size,
            lightgrid::consts::MIN_TILE_SIZE..=lightgrid::consts::MAX_TILE_SIZE,
        )
        .text("tile px"),
    );
    for axis in lightgrid::pipelines::AXES {
        let applies = pipeline.is_some_and(|p| (axis.applies)(p, &draft.settings));
        setting(ui, axis, &mut draft.settings, applies, info);
    }
    ui.label(format!(
        "rendering {}x{}",
        info.render_size.0, info.render_size.1
    ));
}

/// One row of the settings table (`AXES`): its values by name, or a number the row checks
/// (MSAA: the counts the adapter offers), greyed out where the pipeline does not read it.
fn setting(
    ui: &mut egui::Ui,
    axis: &lightgrid::pipelines::Axis,
    settings: &mut lightgrid::RenderSettings,
    applies: bool,
    info: &PanelInfo,
) {
    let current = (axis.get)(settings);
    let mut names: Vec<(String, &str)> = (axis.values)()
        .into_iter()
        .map(|v| (v.name.to_string(), v.help))
        .collect();
    if axis.flag == "msaa" {
        names = info
            .msaa_counts
            .iter()
            .map(|n| (n.to_string(), ""))
            .collect();
    }
    ui.add_enabled_ui(applies, |ui| {
        let row = ui.horizontal(|ui| {
            if names.is_empty() {
                let mut n: u32 = current.parse().unwrap_or(0);
                let r = ui.add(egui::DragValue::new(&mut n));
                if r.changed() {
                    let mut next = *settings;
                    if (axis.set)(&mut next, &n.to_string()).is_ok() {
                        *settings = next;
                    }
                }
                ui.label(axis.flag);
            } else {
                egui::ComboBox::from_label(axis.flag)
                    .selected_text(current.as_str())
                    .show_ui(ui, |ui| {
                        for (name, help) in &names {
                            let r = ui.selectable_label(current == *name, name.as_str());
                            let r = if help.is_empty() {
                                r
                            } else {
                                r.on_hover_text(*help)
                            };
                            if r.clicked() {
                                let mut next = *settings;
                                if (axis.set)(&mut next, name).is_ok() {
                                    *settings = next;
                                }
                            }
                        }
                    });
            }
        });
        row.response.on_hover_text(axis.help);
    });
}

fn scene(ui: &mut egui::Ui, draft: &mut Controls, info: &PanelInfo) {
    ui.label(format!("{} lights", info.lights));
    let params = &mut draft.request.params;
    ui.checkbox(&mut params.transparency, "transparent objects");
    ui.add(egui::Slider::new(&mut params.spot_fraction, 0.0..=1.0).text("spot fraction"));
    if info.variable_lights {
        let mut n = params.lights.unwrap_or(info.lights as u32).max(1);
        if ui
            .add(
                egui::Slider::new(&mut n, 1..=lightgrid::scene::catalog::STRESS_MAX_LIGHTS)
                    .logarithmic(true)
                    .text("scene lights"),
            )
            .changed()
        {
            params.lights = Some(n);
        }
    }
    let mut added = draft.request.add_lights.map_or(0, |a| a.count);
    let mut range = draft
        .request
        .add_lights
        .and_then(|a| a.range)
        .unwrap_or(0.0);
    let count_changed = ui
        .add(
            egui::Slider::new(&mut added, 0..=lightgrid::consts::MAX_LIGHTS)
                .logarithmic(true)
                .text("added lights"),
        )
        .changed();
    let range_changed = ui
        .add_enabled(
            added > 0,
            egui::Slider::new(&mut range, 0.0..=100.0)
                .logarithmic(true)
                .text("added range (0: default)"),
        )
        .changed();
    if count_changed || range_changed {
        draft.request.add_lights = (added > 0).then_some(AddLights {
            count: added,
            range: (range > 0.0).then_some(range),
        });
    }
}

fn animation(ui: &mut egui::Ui, info: &PanelInfo, actions: &mut Vec<PanelAction>) {
    ui.horizontal(|ui| {
        if ui
            .button(if info.playing { "pause" } else { "play" })
            .clicked()
        {
            actions.push(PanelAction::TogglePause);
        }
        if ui.button("step -1").clicked() {
            actions.push(PanelAction::Step(-1));
        }
        if ui.button("step +1").clicked() {
            actions.push(PanelAction::Step(1));
        }
    });
    let mut frame = info.frame;
    if ui
        .add(egui::Slider::new(&mut frame, 0..=info.frame_count.saturating_sub(1)).text("frame"))
        .changed()
    {
        actions.push(PanelAction::JumpTo(frame));
    }
    ui.horizontal(|ui| {
        if info.flying {
            ui.label("fly camera");
            if ui.button("follow the path (C)").clicked() {
                actions.push(PanelAction::FollowPath);
            }
        } else {
            ui.label("the scene's camera path (WASD to fly)");
        }
    });
    let mut speed = info.fly_speed;
    if ui
        .add(
            egui::Slider::new(&mut speed, 0.1..=1000.0)
                .logarithmic(true)
                .text("fly speed /s"),
        )
        .changed()
    {
        actions.push(PanelAction::FlySpeed(speed));
    }
}

fn debug_views(
    ui: &mut egui::Ui,
    draft: &mut Controls,
    info: &PanelInfo,
    actions: &mut Vec<PanelAction>,
) {
    ui.horizontal_wrapped(|ui| {
        for v in DebugView::ALL {
            let offered = v == DebugView::Shaded || !crate::controls::WEB;
            let r = ui.add_enabled(offered, egui::Button::selectable(draft.view == v, v.name()));
            if r.on_disabled_hover_text(crate::controls::NATIVE_ONLY)
                .clicked()
            {
                draft.view = v;
            }
        }
    });
    if crate::controls::WEB {
        ui.label(RichText::new(crate::controls::NATIVE_ONLY).small());
        return;
    }
    if draft.view != DebugView::Shaded {
        match info.analysis.and_then(|(a, _)| a.image.as_ref()) {
            Some(img) => {
                legend(ui, img.max, img.unit);
                if let Some(t) = img.total {
                    ui.label(format!("total {t:.0} {}", img.unit));
                }
                if let Some(n) = &img.note {
                    ui.label(RichText::new(n).small());
                }
            }
            None => {
                ui.label("waiting for an analysis frame…");
            }
        }
    }
    ui.horizontal(|ui| {
        if ui.button("analyse now (I)").clicked() {
            actions.push(PanelAction::Analyse);
        }
        let mut every = info.sample_every_second;
        if ui.checkbox(&mut every, "every second").changed() {
            actions.push(PanelAction::SampleEverySecond(every));
        }
        if info.analysing {
            ui.spinner();
        }
    });
    if let Some((a, current)) = info.analysis {
        let s = &a.stats;
        ui.label(format!(
            "{} frame {}{}: {:.2}s to analyse",
            s.pipeline,
            s.frame,
            if current { "" } else { " (older view)" },
            a.seconds
        ));
        ui.label(format!(
            "lighting computations {} / ideal {} ({})",
            s.lighting_computations
                .map_or("n/a".into(), |n| n.to_string()),
            s.ideal_lighting_computations,
            s.efficiency
                .map_or("n/a".into(), |e| format!("{:.1}% efficient", e * 100.0)),
        ));
        if let (Some(avg), Some(max)) = (s.lights_per_tile_avg, s.lights_per_tile_max) {
            ui.label(format!("lights per cell: avg {avg:.1}, max {max}"));
        }
    }
}

/// Where the panel's widgets were last drawn, by name, in points ([x, y, w, h]): what a
/// browser test clicks (`web.rs`, `Shared::spots`).
type Spots = std::collections::HashMap<String, [f32; 4]>;

fn remember_spot(ctx: &egui::Context, name: &str, r: egui::Rect) {
    ctx.data_mut(|d| {
        d.get_temp_mut_or_default::<Spots>(egui::Id::unique("lightgrid spots"))
            .insert(name.to_string(), [r.min.x, r.min.y, r.width(), r.height()]);
    });
}

/// The panel's widgets' places ([`remember_spot`]).
pub fn spots(ctx: &egui::Context) -> Spots {
    ctx.data(|d| d.get_temp::<Spots>(egui::Id::unique("lightgrid spots")))
        .unwrap_or_default()
}

/// The debug views' colour ramp from 0 to `max`.
fn legend(ui: &mut egui::Ui, max: f64, unit: &str) {
    let (rect, _) = ui.allocate_exact_size(egui::vec2(200.0, 12.0), egui::Sense::hover());
    let steps = 40;
    for i in 0..steps {
        let t = i as f32 / (steps - 1) as f32;
        let [r, g, b] = lightgrid::heatmap::ramp(t);
        let x0 = rect.left() + rect.width() * i as f32 / steps as f32;
        let x1 = rect.left() + rect.width() * (i + 1) as f32 / steps as f32;
        ui.painter().rect_filled(
            egui::Rect::from_x_y_ranges(x0..=x1, rect.y_range()),
            0.0,
            Color32::from_rgb((r * 255.0) as u8, (g * 255.0) as u8, (b * 255.0) as u8),
        );
    }
    ui.label(format!("0 … {max:.0} {unit}"));
}

fn figures(ui: &mut egui::Ui, info: &PanelInfo) {
    let f = info.figures;
    ui.label(format!(
        "frame {} ms (wall), GPU {} ms",
        LiveFigures::recent_mean(&f.frame_ms, 30).map_or("-".into(), |v| format!("{v:.1}")),
        LiveFigures::recent_mean(&f.gpu_ms, 30).map_or("n/a".into(), |v| format!("{v:.1}")),
    ));
    graph(ui, f);
    if !f.passes.is_empty() {
        egui::CollapsingHeader::new("GPU passes (ms)")
            .default_open(false)
            .show(ui, |ui| {
                egui::Grid::new("passes").striped(true).show(ui, |ui| {
                    for p in &f.passes {
                        ui.label(&p.label);
                        ui.label(format!("{:.2}", p.ms));
                        ui.end_row();
                    }
                    if let Some(a) = f.assign_ms {
                        ui.label("light assignment");
                        ui.label(format!("{a:.2}"));
                        ui.end_row();
                    }
                });
            });
    }
}

/// Frame times (wall: white, GPU: green) over the kept history, scaled to their maximum.
fn graph(ui: &mut egui::Ui, f: &LiveFigures) {
    let (rect, _) = ui.allocate_exact_size(egui::vec2(280.0, 60.0), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, Color32::from_gray(20));
    let max = f
        .frame_ms
        .iter()
        .chain(f.gpu_ms.iter())
        .fold(1.0f32, |m, &v| m.max(v));
    let line = |q: &std::collections::VecDeque<f32>, color: Color32| {
        let n = crate::live::HISTORY as f32;
        let points: Vec<egui::Pos2> = q
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                egui::pos2(
                    rect.left() + rect.width() * i as f32 / n,
                    rect.bottom() - rect.height() * (v / max),
                )
            })
            .collect();
        painter.add(egui::Shape::line(points, egui::Stroke::new(1.0, color)));
    };
    line(&f.frame_ms, Color32::WHITE);
    line(&f.gpu_ms, Color32::from_rgb(90, 220, 90));
    painter.text(
        rect.left_top() + egui::vec2(4.0, 2.0),
        egui::Align2::LEFT_TOP,
        format!("{max:.0} ms"),
        egui::FontId::proportional(10.0),
        Color32::GRAY,
    );
}
