//! The side panel. Controls edit the app's state only;
//! `ViewerApp::sync_session` sends what changed at the end of the frame, so
//! every widget here is free of render-thread plumbing. Numeric controls go
//! through [`inputs`], so a value is never changed silently.

use super::app::{ViewKind, ViewerApp};
use super::display::{CompareMode, DenoiseMode};
use super::inputs;
use super::inspect::{HISTOGRAM_BINS, Histogram};
use crate::film::ToneMap;
use crate::render::IntegratorKind;
use crate::render::session::{Command, SessionState};
use crate::settings::SettingsPatch;
use egui::{Color32, Response, RichText, Ui};
use std::path::PathBuf;
use std::time::Duration;

/// Marks the render as interactive (coarse) while `response` is dragged.
fn track(app: &mut ViewerApp, response: &Response) {
    if response.dragged() {
        app.interacting = true;
    }
}

/// Keeps the first refusal of this frame for display.
fn refuse(app: &mut ViewerApp, refusal: Option<String>) {
    if let Some(reason) = refusal {
        app.input_error = Some(reason);
    }
}

pub(super) fn ui_controls(app: &mut ViewerApp, ui: &mut Ui) {
    ui.spacing_mut().slider_width = 130.0;
    ui.heading("Prism");
    ui_scene(app, ui);
    ui.separator();
    ui_render(app, ui);
    if let Some(reason) = app.input_error.clone() {
        ui.horizontal_wrapped(|ui| {
            ui.colored_label(ui.visuals().error_fg_color, format!("Not changed: {reason}"));
            if ui.small_button("OK").clicked() {
                app.input_error = None;
            }
        });
    }
    ui.separator();
    ui_camera(app, ui);
    ui.separator();
    ui_display(app, ui);
    ui.separator();
    ui_inspect(app, ui);
    ui.separator();
    ui_snapshot(app, ui);
}

fn ui_scene(app: &mut ViewerApp, ui: &mut Ui) {
    ui.label(RichText::new(app.scene_name()).monospace());
    ui.horizontal(|ui| {
        let field = ui.add(
            egui::TextEdit::singleline(&mut app.open.path_text)
                .desired_width(200.0)
                .hint_text("scene.toml"),
        );
        field.widget_info(|| egui::WidgetInfo::labeled(egui::Role::TextInput, true, "Scene path"));
        if app.open.focus_path {
            field.request_focus();
            app.open.focus_path = false;
        }
        let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
        if ui.button("Open").clicked() || entered {
            app.open_scene_path();
        }
    });
    ui.horizontal(|ui| {
        if ui.button("Browse…").clicked() {
            app.open_scene_dialog();
        }
        if ui.button("Reload").clicked() {
            app.load_scene(app.scene_path.clone());
        }
    });
    ui.horizontal(|ui| {
        egui::ComboBox::from_label("Scenes")
            .selected_text("Recent and shipped")
            .width(170.0)
            .show_ui(ui, |ui| {
                let mut chosen: Option<Option<PathBuf>> = None;
                for path in &app.open.recent {
                    if ui.selectable_label(false, path.display().to_string()).clicked() {
                        chosen = Some(Some(path.clone()));
                    }
                }
                if !app.open.recent.is_empty() {
                    ui.separator();
                }
                if ui.selectable_label(false, "<default scene>").clicked() {
                    chosen = Some(None);
                }
                for path in &app.open.shipped {
                    if ui.selectable_label(false, path.display().to_string()).clicked() {
                        chosen = Some(Some(path.clone()));
                    }
                }
                if let Some(path) = chosen {
                    app.open.path_text = path.as_ref().map_or_else(String::new, |p| p.display().to_string());
                    app.load_scene(path);
                }
            });
    });
    if let Some(message) = &app.open.message {
        ui.colored_label(ui.visuals().warn_fg_color, message);
    }
    ui.checkbox(&mut app.auto_reload, "Reload when the file changes");
    ui.small("Or drop a scene file on the window.");
}

fn ui_render(app: &mut ViewerApp, ui: &mut Ui) {
    let state = app.display.stats.state;
    ui.horizontal(|ui| {
        if matches!(state, SessionState::Paused | SessionState::Stopped) {
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
    if state == SessionState::Finished {
        ui.small("Finished: raise the target to continue this render.");
    }

    egui::ComboBox::from_label("Integrator")
        .selected_text(integrator_label(app.settings.integrator))
        .show_ui(ui, |ui| {
            for kind in IntegratorKind::ALL {
                ui.selectable_value(&mut app.settings.integrator, kind, integrator_label(kind));
            }
        });

    // A dispersive glass makes the render spectral whatever the setting, so
    // the box shows that instead of a choice it would not honour.
    if app.scene.as_ref().is_some_and(|scene| scene.has_dispersion()) {
        ui.add_enabled(false, egui::Checkbox::new(&mut true, "Spectral (dispersive glass)"))
            .on_disabled_hover_text("This scene has a dispersive glass, so it is always rendered spectrally");
    } else {
        ui.checkbox(&mut app.settings.spectral, "Spectral")
            .on_hover_text("Carry 4 sampled wavelengths per path and photon instead of RGB (path tracing and SPPM)");
    }
    if app.settings.integrator == IntegratorKind::PathTracing {
        ui.checkbox(&mut app.settings.caustic_light_paths, "Caustics from the lights")
            .on_hover_text(
                "Trace the light that mirrors and glass focus onto what the camera sees from the lights, \
                 and connect it to the lens: the same image, far less noise in caustics \
                 (RGB, without adaptive sampling)",
            );
    }

    let sppm = app.settings.integrator == IntegratorKind::Sppm;
    let mut unlimited = app.settings.samples_per_pixel.is_none();
    ui.horizontal(|ui| {
        let label = ui.label(if sppm { "Target iterations" } else { "Target samples/pixel" });
        let mut target = app.settings.samples_per_pixel.unwrap_or(256);
        let (response, refusal) = inputs::number(
            ui,
            &mut target,
            4.0,
            "",
            !unlimited,
            inputs::setting(|value| SettingsPatch {
                spp: Some(value),
                ..Default::default()
            }),
        );
        response.labelled_by(label.id);
        ui.checkbox(&mut unlimited, "unlimited");
        app.settings.samples_per_pixel = (!unlimited).then_some(target);
        refuse(app, refusal);
    });
    ui.horizontal(|ui| {
        let mut limited = app.settings.time_limit.is_some();
        let mut seconds = app.settings.time_limit.map_or(60.0, |t| t.as_secs_f64());
        let label = ui.checkbox(&mut limited, "Time limit");
        let (response, refusal) = inputs::number(ui, &mut seconds, 1.0, " s", limited, inputs::time_limit);
        response.labelled_by(label.id);
        app.settings.time_limit = limited.then(|| Duration::from_secs_f64(seconds));
        refuse(app, refusal);
    });
    let (response, refusal) = inputs::slider(
        ui,
        &mut app.settings.max_depth,
        1..=64,
        "Max depth",
        false,
        inputs::setting(|value| SettingsPatch {
            max_depth: Some(value),
            ..Default::default()
        }),
    );
    track(app, &response);
    refuse(app, refusal);

    ui.add_enabled_ui(sppm, |ui| {
        egui::CollapsingHeader::new("SPPM")
            .default_open(sppm)
            .show(ui, |ui| ui_sppm(app, ui));
    });

    // The scaled image must pass the same size and memory checks as a scene's own.
    let (width, height) = (app.settings.width, app.settings.height);
    let (response, refusal) = inputs::slider(
        ui,
        &mut app.resolution_scale,
        0.1..=2.0,
        "Resolution scale",
        false,
        move |scale: f32| {
            if !(scale.is_finite() && scale > 0.0) {
                return Err(format!("the resolution scale must be a positive number (found {scale})"));
            }
            let scaled = |side: u32| ((side as f32 * scale).round() as u32).max(1);
            inputs::setting(|_: ()| SettingsPatch {
                width: Some(scaled(width)),
                height: Some(scaled(height)),
                ..Default::default()
            })(())
        },
    );
    track(app, &response);
    refuse(app, refusal);
    let effective = app.effective_settings();
    ui.horizontal(|ui| {
        ui.small(format!("{} × {} pixels", effective.width, effective.height));
        ui.toggle_value(&mut app.region_tool, "Draw region")
            .on_hover_text("Drag a rectangle on the image to render only there (or Ctrl+drag)");
        if app.settings.region.is_some() && ui.button("Clear region").clicked() {
            app.settings.region = None;
        }
    });
}

fn ui_sppm(app: &mut ViewerApp, ui: &mut Ui) {
    let (photons, refusal) = inputs::slider(
        ui,
        &mut app.settings.sppm.photons_per_iteration,
        1_000..=5_000_000,
        "Photons / iteration",
        true,
        inputs::setting(|value| SettingsPatch {
            photons_per_iteration: Some(value),
            ..Default::default()
        }),
    );
    refuse(app, refusal);
    let (alpha, refusal) = inputs::slider(
        ui,
        &mut app.settings.sppm.alpha,
        0.05..=0.95,
        "Alpha",
        false,
        inputs::setting(|value| SettingsPatch {
            alpha: Some(value),
            ..Default::default()
        }),
    );
    refuse(app, refusal);
    let distance = app.home_distance();
    let mut automatic = app.settings.sppm.initial_radius.is_none();
    let mut radius = app.settings.sppm.initial_radius.unwrap_or(distance * 0.01);
    ui.checkbox(&mut automatic, "Initial radius from the pixel footprint");
    let (radius_response, refusal) = ui
        .add_enabled_ui(!automatic, |ui| {
            inputs::slider(
                ui,
                &mut radius,
                distance * 1e-4..=distance * 0.1,
                "Initial radius",
                true,
                inputs::setting(|value| SettingsPatch {
                    initial_radius: Some(value),
                    ..Default::default()
                }),
            )
        })
        .inner;
    refuse(app, refusal);
    app.settings.sppm.initial_radius = (!automatic).then_some(radius);
    for response in [photons, alpha, radius_response] {
        track(app, &response);
    }
}

fn ui_camera(app: &mut ViewerApp, ui: &mut Ui) {
    let distance = app.home_distance();
    let Some(mut camera) = app.camera else {
        ui.label("Camera: waiting for the scene");
        return;
    };
    let (aperture, refusal) = inputs::slider(
        ui,
        &mut camera.aperture_radius,
        0.0..=distance * 0.05,
        "Aperture radius",
        false,
        inputs::not_negative("the aperture radius"),
    );
    refuse(app, refusal);
    let (focus, refusal) = inputs::slider(
        ui,
        &mut camera.focal_distance,
        distance * 0.01..=distance * 4.0,
        "Focal distance",
        true,
        inputs::positive("the focal distance"),
    );
    refuse(app, refusal);
    app.camera = Some(camera);
    let reset = ui.button("Reset view").clicked();
    ui.add(
        egui::Label::new(
            RichText::new("Drag: orbit · right or Shift+drag: pan camera · Ctrl+wheel: dolly · click: focus there").small(),
        )
        .wrap(),
    );
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
    let (_, refusal) = inputs::slider(
        ui,
        &mut app.exposure,
        -10.0..=10.0,
        "Exposure (stops)",
        false,
        inputs::exposure,
    );
    refuse(app, refusal);
    egui::ComboBox::from_label("Tone map")
        .selected_text(format!("{:?}", app.tone_map))
        .show_ui(ui, |ui| {
            for tone_map in ToneMap::ALL {
                ui.selectable_value(&mut app.tone_map, tone_map, format!("{tone_map:?}"));
            }
        });
    let has_radii = app.display.frame.as_ref().is_some_and(|f| f.radii.is_some());
    let has_noise = app.noise_view_available();
    ui.horizontal(|ui| {
        ui.radio_value(&mut app.view, ViewKind::Image, "Image");
        let noise = ui
            .add_enabled(has_noise, egui::RadioButton::new(app.view == ViewKind::Noise, "Noise"))
            .on_disabled_hover_text(
                "This integrator has no per-pixel noise estimate: SPPM's progressive density estimate \
                 is not an average of independent samples.",
            );
        if noise.clicked() {
            app.view = ViewKind::Noise;
        }
        let radii = ui
            .add_enabled(has_radii, egui::RadioButton::new(app.view == ViewKind::Radii, "SPPM radii"))
            .on_disabled_hover_text("Only SPPM has gather radii.");
        if radii.clicked() {
            app.view = ViewKind::Radii;
        }
    });
    match app.view {
        ViewKind::Noise => {
            ui.small("Relative standard error per pixel: dark blue 0.1 %, then red, yellow, white 100 % or more.");
        }
        ViewKind::Radii => match app.display.radii_range {
            Some((low, high)) if high > low => {
                ui.small(format!(
                    "Gather radius, log scale: dark {low:.3e} … white {high:.3e}; black = none yet."
                ));
            }
            Some((low, _)) => {
                ui.small(format!("Every gather radius is {low:.3e} (one colour); black = none yet."));
            }
            None => {
                ui.small("No radii yet.");
            }
        },
        ViewKind::Image => {}
    }
    ui.horizontal(|ui| {
        ui.label("Denoised preview");
        for (mode, label) in [
            (DenoiseMode::Off, "Off"),
            (DenoiseMode::On, "On"),
            (DenoiseMode::SideBySide, "Side by side"),
        ] {
            if ui.selectable_value(&mut app.denoise_mode, mode, label).clicked() {
                app.request_denoise();
            }
        }
    });
    ui.horizontal(|ui| {
        let mut clamp = app.firefly_clamp.is_some();
        let mut value = app.firefly_clamp.unwrap_or(10.0);
        let label = ui
            .checkbox(&mut clamp, "Firefly clamp")
            .on_hover_text("Caps each pixel's luminance on screen: hides fireflies but is biased (removes energy).");
        let (response, refusal) = inputs::number(ui, &mut value, 0.1, "", clamp, |v: f32| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("the firefly clamp must be a positive luminance (got {v})"))
            }
        });
        response.labelled_by(label.id);
        refuse(app, refusal);
        let new = clamp.then_some(value);
        if new != app.firefly_clamp {
            app.firefly_clamp = new;
            app.display.denoised = None;
            app.request_denoise();
        }
    });
}

fn ui_inspect(app: &mut ViewerApp, ui: &mut Ui) {
    ui.horizontal(|ui| {
        ui.label("Zoom");
        if ui.selectable_label(app.zoom.scale.is_none(), "Fit").clicked() {
            app.zoom.fit();
        }
        let pixels_per_point = ui.ctx().pixels_per_point();
        let one_to_one = app.zoom.scale.is_some_and(|s| (s * pixels_per_point - 1.0).abs() < 1e-3);
        if ui.selectable_label(one_to_one, "1:1").clicked() {
            app.zoom.one_to_one(pixels_per_point);
        }
        if let Some(scale) = app.zoom.scale {
            ui.small(format!("{:.0} %", scale * pixels_per_point * 100.0));
        }
    });
    ui.small("Wheel: zoom image · middle-drag: pan image");
    ui.checkbox(&mut app.show_histogram, "Histogram");
    if app.show_histogram
        && let Some(histogram) = &app.display.histogram
    {
        paint_histogram(ui, histogram, app.exposure);
    }
    egui::CollapsingHeader::new("Compare (A/B)").show(ui, |ui| ui_compare(app, ui));
}

fn ui_compare(app: &mut ViewerApp, ui: &mut Ui) {
    ui.horizontal(|ui| {
        if ui.button("Keep this image as A").clicked()
            && let Some(info) = &app.display.frame
        {
            app.reference = Some(super::display::Reference {
                name: format!("snapshot at {} passes", info.passes),
                frame: std::sync::Arc::clone(&info.frame),
            });
        }
        if app.reference.is_some() && ui.button("Forget A").clicked() {
            app.reference = None;
            app.compare_mode = CompareMode::Off;
        }
    });
    ui.horizontal(|ui| {
        let field = ui.add(
            egui::TextEdit::singleline(&mut app.reference_path_text)
                .desired_width(190.0)
                .hint_text("reference.exr / .png"),
        );
        field.widget_info(|| egui::WidgetInfo::labeled(egui::Role::TextInput, true, "Reference path"));
        if ui.button("Load A").clicked() {
            app.load_reference();
        }
    });
    let Some(reference) = &app.reference else {
        ui.small("No reference: keep the current image or load a file.");
        return;
    };
    ui.small(format!("A: {}", reference.name));
    ui.horizontal(|ui| {
        ui.selectable_value(&mut app.compare_mode, CompareMode::Off, "Render");
        ui.selectable_value(&mut app.compare_mode, CompareMode::Reference, "A");
        ui.selectable_value(&mut app.compare_mode, CompareMode::Difference, "Difference");
    });
    match &app.display.comparison {
        Some(Ok(metrics)) => {
            ui.label(format!("relMSE {:.3e} · RMSE {:.3e}", metrics.relative_mse, metrics.rmse));
        }
        Some(Err(why)) => {
            ui.colored_label(ui.visuals().warn_fg_color, format!("Cannot compare: {why}"));
        }
        None => {}
    }
}

/// Pixel counts by log₂ luminance, with the white point of the current
/// exposure (luminance 2^−exposure maps to 1) marked.
fn paint_histogram(ui: &mut Ui, histogram: &Histogram, exposure: f64) {
    let (rect, response) = ui.allocate_exact_size(egui::vec2(ui.available_width().min(290.0), 60.0), egui::Sense::hover());
    response.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, "Histogram"));
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, Color32::from_gray(24));
    let highest = histogram.bins.iter().copied().max().unwrap_or(0).max(1) as f32;
    let bar = rect.width() / HISTOGRAM_BINS as f32;
    for (i, &count) in histogram.bins.iter().enumerate() {
        // Square-root heights keep small populations (highlights) visible.
        let height = (count as f32 / highest).sqrt() * rect.height();
        let x = rect.left() + i as f32 * bar;
        painter.rect_filled(
            egui::Rect::from_min_max(egui::pos2(x, rect.bottom() - height), egui::pos2(x + bar, rect.bottom())),
            0.0,
            Color32::from_gray(170),
        );
    }
    let white = rect.left() + Histogram::position(-exposure) as f32 * rect.width();
    painter.line_segment(
        [egui::pos2(white, rect.top()), egui::pos2(white, rect.bottom())],
        egui::Stroke::new(1.5, Color32::from_rgb(255, 180, 60)),
    );
    ui.small(format!(
        "log₂ luminance −12 … +8; orange: white at this exposure; {} black pixels",
        histogram.black
    ));
}

fn ui_snapshot(app: &mut ViewerApp, ui: &mut Ui) {
    if ui.button("Save snapshot… (Ctrl+S)").clicked() {
        app.open_save_dialog();
    }
    ui.horizontal(|ui| {
        let field = ui.add(
            egui::TextEdit::singleline(&mut app.save.path_text)
                .desired_width(200.0)
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
    ui.checkbox(&mut app.save.denoised, "Save the denoised preview instead of the raw image");
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
