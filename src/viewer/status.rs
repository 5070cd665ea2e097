//! The status line: a progress bar and one line of text that never wraps
//! and never says a thing twice (state, passes against the target, the
//! integrator's own status, speed, render time and estimate, running
//! between passes, noise), or a scene load's stage while one runs.

use super::app::ViewerApp;
use crate::render::IntegratorKind;
use crate::render::session::SessionState;
use egui::{Label, ProgressBar, Ui};
use std::time::Instant;

pub(super) fn ui_status(app: &mut ViewerApp, ui: &mut Ui) {
    ui.horizontal(|ui| {
        if let Some((stage, running)) = app.loader_stage() {
            ui.add(ProgressBar::new(0.0).desired_width(140.0).animate(true));
            ui.add(Label::new(format!("Loading scene: {stage} · {:.1} s", running.as_secs_f64())).truncate());
            return;
        }
        let now = Instant::now();
        let stats = &app.display.stats;
        let mut progress = stats.progress();
        progress.elapsed = stats.live_elapsed(now);
        let fraction = progress.fraction().unwrap_or(0.0) as f32;
        ui.add(
            ProgressBar::new(fraction)
                .desired_width(140.0)
                .text(format!("{:.0} %", fraction * 100.0)),
        );
        ui.add(Label::new(status_text(app, now)).truncate());
    });
}

/// The one line of status text.
pub(super) fn status_text(app: &ViewerApp, now: Instant) -> String {
    let stats = &app.display.stats;
    let unit = if stats.settings.integrator == IntegratorKind::Sppm {
        "iterations"
    } else {
        "spp"
    };
    let target = stats.target_passes.map_or("∞".to_string(), |t| t.to_string());
    let mut parts = vec![format!("{:?}", stats.state), format!("{}/{target} {unit}", stats.passes)];
    if !stats.integrator_status.is_empty() {
        parts.push(stats.integrator_status.clone());
    }
    parts.push(format!("{:.2} Msamples/s", stats.samples_per_second / 1e6));
    parts.push(format!("elapsed {:.1} s", stats.live_elapsed(now).as_secs_f64()));
    if stats.state == SessionState::Rendering
        && let Some(remaining) = stats.live_remaining(now)
    {
        parts.push(format!("ETA {:.1} s", remaining.as_secs_f64()));
    }
    match app.display.noise {
        Some(noise) => parts.push(format!("noise {:.2} %", noise * 100.0)),
        None if app.noise_view_available() => parts.push("noise —".into()),
        None => {}
    }
    if stats.settings.region.is_some() {
        parts.push("region".into());
    }
    if stats.rejected_samples > 0 {
        parts.push(format!("{} NaN/inf samples dropped", stats.rejected_samples));
    }
    parts.join("  ·  ")
}
