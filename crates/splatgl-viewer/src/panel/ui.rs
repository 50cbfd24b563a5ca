//! The side panel's contents: scene, statistics, view settings, cameras, crop box.

use egui::{CollapsingHeader, DragValue, Grid, RichText, Ui};

use super::model::{Action, Facts, Live, Settings};
use crate::stats::thousands;
use splatgl::camera::UpAxis;
use splatgl::cull::CropBox;

/// Where the camera buttons were laid out (points), for [`super::Panel`]'s layout log.
pub type CameraRects = Vec<egui::Rect>;

/// Lays out the panel; pushes what the viewer must do to `actions`.
pub fn contents(
    ui: &mut Ui,
    facts: &Facts,
    live: &Live,
    up: UpAxis,
    s: &mut Settings,
    actions: &mut Vec<Action>,
    rects: &mut CameraRects,
) {
    egui::ScrollArea::vertical().show(ui, |ui| {
        cameras(ui, facts, actions, rects);
        scene(ui, facts);
        statistics(ui, live, facts.splats);
        view(ui, facts, up, s, actions);
        crop(ui, facts, s);
        ui.separator();
        ui.label(RichText::new("G hides this panel · H prints the controls").weak());
    });
}

fn scene(ui: &mut Ui, f: &Facts) {
    CollapsingHeader::new("Scene")
        .default_open(true)
        .show(ui, |ui| {
            Grid::new("scene-grid").num_columns(2).show(ui, |ui| {
                ui.label("file");
                let name = ui.label(&f.name);
                if let Some(p) = &f.path {
                    name.on_hover_text(p);
                }
                ui.end_row();
                let mut row = |k: &str, v: String| {
                    ui.label(k);
                    ui.label(v);
                    ui.end_row();
                };
                row("format", f.format.clone());
                if let Some(c) = &f.container {
                    row("container", c.clone());
                }
                let splats = if f.splats < f.file_splats {
                    format!("{} of {}", thousands(f.splats), thousands(f.file_splats))
                } else {
                    thousands(f.splats)
                };
                row("splats", splats);
                row("SH degree", f.sh_degree.to_string());
                row("colour space", f.colour_space.clone());
                row("kernel", f.kernel.clone());
                if let Some((lo, hi)) = f.bounds {
                    row("bounds min", vec3(lo));
                    row("bounds max", vec3(hi));
                }
            });
            if !f.warnings.is_empty() {
                let n = f.warnings.len();
                let title = format!("{n} warning{}", if n == 1 { "" } else { "s" });
                ui.collapsing(title, |ui| {
                    for w in &f.warnings {
                        ui.label(w);
                    }
                });
            }
        });
}

fn vec3(v: [f32; 3]) -> String {
    format!("{:.3}, {:.3}, {:.3}", v[0], v[1], v[2])
}

fn statistics(ui: &mut Ui, l: &Live, resident: usize) {
    CollapsingHeader::new("Statistics")
        .default_open(true)
        .show(ui, |ui| {
            Grid::new("stats-grid").num_columns(2).show(ui, |ui| {
                let mut row = |k: &str, v: String| {
                    ui.label(k);
                    ui.label(v);
                    ui.end_row();
                };
                row("fps", format!("{:.1}", l.fps));
                row(
                    "frame",
                    format!("{:.2} ms (p99 {:.2})", l.frame_ms.0, l.frame_ms.1),
                );
                row("sort", format!("{:.2} ms", l.sort_ms));
                row("order upload", format!("{:.2} ms", l.upload_ms));
                row("order", l.order.clone());
                row("resident", thousands(resident));
                row("drawn", thousands(l.drawn));
                row(
                    "interface CPU",
                    format!("{:.2} ms layout, {:.2} ms paint", l.ui_ms.0, l.ui_ms.1),
                );
                if let Some(t) = &l.tiles {
                    row(
                        "tiles",
                        format!("{} selected, {} loading", t.selected, t.loading),
                    );
                    row(
                        "tile splats",
                        format!(
                            "{} of {} ({:.0} % of the budget)",
                            thousands(t.splats as usize),
                            thousands(t.budget as usize),
                            100.0 * t.splats as f64 / t.budget.max(1) as f64
                        ),
                    );
                    row(
                        "tile cache",
                        format!("{} tiles, {} MB", t.resident, t.resident_mb),
                    );
                    row("GPU pages", format!("{} of {}", t.pages_used, t.pages));
                }
            });
        });
}

fn view(ui: &mut Ui, f: &Facts, up: UpAxis, s: &mut Settings, actions: &mut Vec<Action>) {
    CollapsingHeader::new("View")
        .default_open(true)
        .show(ui, |ui| {
            let max = f.sh_degree;
            s.sh_degree = s.sh_degree.min(max);
            ui.add_enabled(
                max > 0,
                egui::Slider::new(&mut s.sh_degree, 0..=max.max(1)).text("SH degree"),
            );
            ui.horizontal(|ui| {
                ui.color_edit_button_rgb(&mut s.background);
                ui.label("background");
            });
            let mut chosen = up;
            egui::ComboBox::from_label("up axis")
                .selected_text(up.name())
                .show_ui(ui, |ui| {
                    for a in [UpAxis::Y, UpAxis::NegY, UpAxis::Z] {
                        ui.selectable_value(&mut chosen, a, a.name());
                    }
                });
            if chosen != up {
                actions.push(Action::Up(chosen));
            }
            ui.add(
                egui::Slider::new(&mut s.resolution_scale, 0.25..=2.0)
                    .step_by(0.05)
                    .text("resolution scale"),
            );
            budget(ui, f, s, actions);
            ui.horizontal_wrapped(|ui| {
                let buttons = [
                    ("Reset view", Action::Reset),
                    ("Frame", Action::Frame),
                    ("Screenshot", Action::Screenshot),
                    ("Open file…", Action::Open),
                ];
                for (label, action) in buttons {
                    if ui.button(label).clicked() {
                        actions.push(action);
                    }
                }
            });
        });
}

/// `--max-splats`: a check box and a count; applying reloads the file.
fn budget(ui: &mut Ui, f: &Facts, s: &mut Settings, actions: &mut Vec<Action>) {
    ui.horizontal(|ui| {
        let mut on = s.budget.is_some();
        ui.checkbox(&mut on, "max splats");
        let mut n = s.budget.unwrap_or(f.file_splats.max(1));
        ui.add_enabled(
            on,
            DragValue::new(&mut n).range(1..=usize::MAX).speed(1000.0),
        );
        s.budget = on.then_some(n);
        if ui
            .button("Apply")
            .on_hover_text("reloads the file")
            .clicked()
        {
            actions.push(Action::Budget(s.budget));
        }
    });
}

fn cameras(ui: &mut Ui, f: &Facts, actions: &mut Vec<Action>, rects: &mut CameraRects) {
    CollapsingHeader::new(format!("Cameras ({})", f.cameras.len()))
        .default_open(true)
        .show(ui, |ui| {
            if f.cameras.is_empty() {
                ui.label("no glTF camera nodes, no --camera views");
            }
            for (i, name) in f.cameras.iter().enumerate() {
                let resp = ui.button(name);
                rects.push(resp.rect);
                if resp.clicked() {
                    actions.push(Action::Camera(i));
                }
            }
        });
}

fn crop(ui: &mut Ui, f: &Facts, s: &mut Settings) {
    CollapsingHeader::new("Crop box")
        .default_open(true)
        .show(ui, |ui| {
            let mut on = s.crop.is_some();
            ui.checkbox(&mut on, "crop (splats outside are not drawn)");
            match (on, s.crop) {
                (true, None) => s.crop = f.bounds.map(|(min, max)| CropBox { min, max }),
                (false, Some(_)) => s.crop = None,
                _ => {}
            }
            let Some(b) = &mut s.crop else {
                return;
            };
            ui.checkbox(&mut s.show_crop, "show the box (drag its faces)");
            let span = f.bounds.map_or(1.0, |(lo, hi)| {
                (0..3).map(|a| hi[a] - lo[a]).fold(0.0f32, f32::max)
            });
            let speed = (span * 0.002).max(1e-4) as f64;
            Grid::new("crop-grid").num_columns(4).show(ui, |ui| {
                for (label, v) in [("min", &mut b.min), ("max", &mut b.max)] {
                    ui.label(label);
                    for x in v.iter_mut() {
                        ui.add(DragValue::new(x).speed(speed).max_decimals(4));
                    }
                    ui.end_row();
                }
            });
            // Keep min ≤ max whichever end was edited.
            for a in 0..3 {
                if b.min[a] > b.max[a] {
                    std::mem::swap(&mut b.min[a], &mut b.max[a]);
                }
            }
            if ui.button("Fit to the scene").clicked()
                && let Some((min, max)) = f.bounds
            {
                *b = CropBox { min, max };
            }
        });
}
