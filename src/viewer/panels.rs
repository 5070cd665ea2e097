//! The side panel of controls and the status line. Controls edit the app's
//! state only; `ViewerApp::sync_session` sends what changed at the end of
//! the frame, so every widget here is free of render-thread plumbing.

use super::app::{ViewKind, ViewerApp};
use crate::film::ToneMap;
use crate::render::IntegratorKind;
use crate::render::session::{Command, SessionState};
use egui::{DragValue, Response, RichText, Slider, Ui};
use std::time::Duration;

/// Marks the render as interactive (coarse) while `response` is dragged.
fn track(app: &mut ViewerApp, response: &Response) {
    if response.dragged() {
        app.interacting = true;
    }
}

pub(super) fn ui_controls(app: &mut ViewerApp, ui: &mut Ui) {
    ui.heading("Prism");
    ui_scene(app, ui);
    ui.separator();
    ui_render(app, ui);
    ui.separator();
    ui_camera(app, ui);
    ui.separator();
    ui_display(app, ui);
    ui.separator();
    ui_snapshot(app, ui);
}

fn ui_scene(app: &mut ViewerApp, ui: &mut Ui) {
    ui.label(RichText::new(app.scene_name()).monospace());
    ui.horizontal(|ui| {
        if ui.button("Open scene…").clicked() {
            app.open_scene_dialog();
        }
        if ui.button("Reload").clicked() {
            app.load_scene(app.scene_path.clone());
        }
    });
    ui.checkbox(&mut app.auto_reload, "Reload when the file changes");
    ui.small("Drop a scene file on the window to open it.");
}

fn ui_render(app: &mut ViewerApp, ui: &mut Ui) {
    ui.horizontal(|ui| {
        let state = app.display.stats.state;
        if state == SessionState::Paused {
            if ui.button("Resume").clicked() {
                app.send(Command::Resume);
            }
        } else if ui
            .add_enabled(state == SessionState::Rendering, egui::Button::new("Pause"))
            .clicked()
        {
            app.send(Command::Pause);
        }
        if ui
            .add_enabled(
                matches!(state, SessionState::Rendering | SessionState::Paused),
                egui::Button::new("Stop"),
            )
            .clicked()
        {
            app.send(Command::Stop);
        }
        if ui.button("Restart").clicked() {
            app.send(Command::Restart);
        }
    });

    egui::ComboBox::from_label("Integrator")
        .selected_text(integrator_label(app.settings.integrator))
        .show_ui(ui, |ui| {
            for kind in IntegratorKind::ALL {
                ui.selectable_value(&mut app.settings.integrator, kind, integrator_label(kind));
            }
        });

    let sppm = app.settings.integrator == IntegratorKind::Sppm;
    let mut unlimited = app.settings.samples_per_pixel.is_none();
    ui.horizontal(|ui| {
        let label = ui.label(if sppm { "Target iterations" } else { "Target samples/pixel" });
        let mut target = app.settings.samples_per_pixel.unwrap_or(256);
        let response = ui
            .add_enabled(!unlimited, DragValue::new(&mut target).range(1..=1_000_000).speed(4.0))
            .labelled_by(label.id);
        ui.checkbox(&mut unlimited, "unlimited");
        app.settings.samples_per_pixel = (!unlimited).then_some(target);
        track(app, &response);
    });
    ui.horizontal(|ui| {
        let mut limited = app.settings.time_limit.is_some();
        let mut seconds = app.settings.time_limit.map_or(60.0, |t| t.as_secs_f64());
        let label = ui.checkbox(&mut limited, "Time limit");
        ui.add_enabled(
            limited,
            DragValue::new(&mut seconds).range(0.1..=86_400.0).speed(1.0).suffix(" s"),
        )
        .labelled_by(label.id);
        app.settings.time_limit = limited.then(|| Duration::from_secs_f64(seconds.max(0.1)));
    });
    let response = ui.add(Slider::new(&mut app.settings.max_depth, 1..=64).text("Max depth"));
    track(app, &response);

    ui.add_enabled_ui(sppm, |ui| {
        egui::CollapsingHeader::new("SPPM").default_open(sppm).show(ui, |ui| {
            let photons = ui.add(
                Slider::new(&mut app.settings.sppm.photons_per_iteration, 1_000..=5_000_000)
                    .logarithmic(true)
                    .text("Photons / iteration"),
            );
            let alpha = ui.add(Slider::new(&mut app.settings.sppm.alpha, 0.05..=0.95).text("Alpha"));
            let mut automatic = app.settings.sppm.initial_radius.is_none();
            let mut radius = app.settings.sppm.initial_radius.unwrap_or(app.home_distance() * 0.01);
            let radius_response = ui
                .horizontal(|ui| {
                    ui.checkbox(&mut automatic, "auto");
                    ui.add_enabled(
                        !automatic,
                        Slider::new(&mut radius, app.home_distance() * 1e-4..=app.home_distance() * 0.1)
                            .logarithmic(true)
                            .text("Initial radius"),
                    )
                })
                .inner;
            app.settings.sppm.initial_radius = (!automatic).then_some(radius);
            for response in [photons, alpha, radius_response] {
                track(app, &response);
            }
        });
    });

    let response = ui.add(Slider::new(&mut app.resolution_scale, 0.1..=2.0).text("Resolution scale"));
    track(app, &response);
    let effective = app.effective_settings();
    ui.small(format!("{} × {} pixels", effective.width, effective.height));
}

fn ui_camera(app: &mut ViewerApp, ui: &mut Ui) {
    let distance = app.home_distance();
    let Some(camera) = app.camera.as_mut() else {
        ui.label("Camera: waiting for the scene");
        return;
    };
    let aperture = ui.add(Slider::new(&mut camera.aperture_radius, 0.0..=distance * 0.05).text("Aperture radius"));
    let focus = ui.add(
        Slider::new(&mut camera.focal_distance, distance * 0.01..=distance * 4.0)
            .logarithmic(true)
            .text("Focal distance"),
    );
    let reset = ui.button("Reset view").clicked();
    ui.small("Drag: orbit · right/middle or shift-drag: pan · wheel: zoom · click: focus there");
    if focus.dragged() || focus.has_focus() {
        app.show_focal_plane = true;
    }
    track(app, &aperture);
    track(app, &focus);
    if reset {
        app.reset_view();
    }
}

fn ui_display(app: &mut ViewerApp, ui: &mut Ui) {
    ui.label("Display (never restarts the render)");
    ui.add(Slider::new(&mut app.exposure, -10.0..=10.0).text("Exposure (stops)"));
    egui::ComboBox::from_label("Tone map")
        .selected_text(format!("{:?}", app.tone_map))
        .show_ui(ui, |ui| {
            for tone_map in ToneMap::ALL {
                ui.selectable_value(&mut app.tone_map, tone_map, format!("{tone_map:?}"));
            }
        });
    let has_radii = app.display.frame.as_ref().is_some_and(|f| f.radii.is_some());
    ui.horizontal(|ui| {
        ui.radio_value(&mut app.view, ViewKind::Image, "Image");
        ui.radio_value(&mut app.view, ViewKind::Noise, "Noise");
        let radii = ui.add_enabled(has_radii, egui::RadioButton::new(app.view == ViewKind::Radii, "SPPM radii"));
        if radii.clicked() {
            app.view = ViewKind::Radii;
        }
    });
    match app.view {
        ViewKind::Noise => {
            ui.small("Relative standard error per pixel: dark blue 0.1 %, then red, yellow, white 100 % or more.");
        }
        ViewKind::Radii if has_radii => {
            ui.small("Gather radius per pixel, log scale: dark = smallest, white = largest; black = none yet.");
        }
        ViewKind::Radii => {
            ui.small("No radii in this frame (not SPPM, or a preview): showing the noise view.");
        }
        ViewKind::Image => {}
    }
}

fn ui_snapshot(app: &mut ViewerApp, ui: &mut Ui) {
    if ui.button("Save snapshot… (Ctrl+S)").clicked() {
        app.open_save_dialog();
    }
    ui.horizontal(|ui| {
        let field = ui.add(
            egui::TextEdit::singleline(&mut app.save.path_text)
                .desired_width(170.0)
                .hint_text("path.png / .bmp / .exr"),
        );
        field.widget_info(|| egui::WidgetInfo::labeled(egui::Role::TextInput, true, "Snapshot path"));
        if app.save.dialog_unavailable {
            // The dialog could not open: the path field takes over.
            field.request_focus();
            app.save.dialog_unavailable = false;
        }
        if ui.button("Save").clicked() {
            let path = std::path::PathBuf::from(app.save.path_text.trim());
            app.save_snapshot(&path);
        }
    });
    if let Some((ok, message)) = &app.save.message {
        let color = if *ok {
            ui.visuals().text_color()
        } else {
            ui.visuals().error_fg_color
        };
        ui.colored_label(color, message);
    }
}

fn integrator_label(kind: IntegratorKind) -> &'static str {
    match kind {
        IntegratorKind::PathTracing => "Path tracing (NEE + MIS)",
        IntegratorKind::BsdfOnly => "Path tracing (BSDF only)",
        IntegratorKind::Sppm => "SPPM",
    }
}

/// The status line: progress, speed, time, estimate and noise.
pub(super) fn ui_status(app: &mut ViewerApp, ui: &mut Ui) {
    let stats = &app.display.stats;
    let sppm = stats.settings.integrator == IntegratorKind::Sppm;
    let target = stats.target_passes.map_or("∞".to_string(), |t| t.to_string());
    let progress = if sppm {
        format!("iteration {}/{target}", stats.passes)
    } else {
        format!("{}/{target} spp", stats.passes)
    };
    let mut parts = vec![format!("{:?}", stats.state), progress];
    if !stats.integrator_status.is_empty() {
        parts.push(stats.integrator_status.clone());
    }
    parts.push(format!("{:.2} Msamples/s", stats.samples_per_second / 1e6));
    parts.push(format!("elapsed {:.1} s", stats.elapsed.as_secs_f64()));
    if let Some(remaining) = stats.remaining().filter(|_| stats.state == SessionState::Rendering) {
        parts.push(format!("ETA {:.1} s", remaining.as_secs_f64()));
    }
    match app.display.noise {
        Some(noise) => parts.push(format!("noise {:.2} %", noise * 100.0)),
        None => parts.push("noise —".into()),
    }
    if stats.rejected_samples > 0 {
        parts.push(format!("{} NaN/inf samples dropped", stats.rejected_samples));
    }
    if app.loading() {
        parts.push("loading scene…".into());
    }
    ui.label(parts.join("  ·  "));
}
