//! SPPM's two radius schedules at equal iterations: Hachisuka & Jensen's
//! per-pixel update (the default) against Knaus & Zwicker's global schedule
//! (what farm renders use, since it makes iterations independent). Each
//! schedule renders one progressive run; at iterations 1, 2, 4 … its image
//! is compared with the scene's converged reference (RMSE, relMSE, and the
//! mean signed error per channel, which shows the bias of the blur).
//! Iterations, not time, are the axis: the two cost the same per iteration,
//! and counts make the result independent of machine load.

use super::{BenchError, Csv, format_number};
use crate::film::Frame;
use crate::integrator::Integrator;
use crate::integrator::sppm::SppmIntegrator;
use crate::metrics::{ErrorMetrics, error_metrics};
use crate::render::ProgressiveRender;
use crate::scene::LoadedScene;
use crate::settings::{IntegratorKind, RadiusSchedule, RenderSettings};
use std::ops::ControlFlow;
use std::sync::atomic::AtomicBool;

/// The error of one schedule after some iterations.
#[derive(Clone, Debug)]
pub struct ScheduleRow {
    /// Which radius schedule rendered this row.
    pub schedule: RadiusSchedule,
    /// SPPM iterations (photon passes) completed.
    pub iterations: u32,
    /// Error of the image after `iterations` against the reference.
    pub metrics: ErrorMetrics,
    /// Mean gather radius of the latest iteration, in scene units.
    pub mean_radius: f64,
}

/// Iterations 1, 2, 4 … up to and including `last`.
pub fn iteration_ladder(last: u32) -> Vec<u32> {
    std::iter::successors(Some(1u32), |&i| i.checked_mul(2))
        .take_while(|&i| i <= last.max(1))
        .collect()
}

/// Renders `loaded` with SPPM at the reference's size under each schedule,
/// measuring at each rung of `ladder` (on the current rayon pool).
pub fn measure(
    loaded: &LoadedScene,
    reference: &Frame,
    ladder: &[u32],
    seed: u64,
    mut progress: impl FnMut(&ScheduleRow),
) -> Result<Vec<ScheduleRow>, BenchError> {
    let mut rows = Vec::new();
    for schedule in RadiusSchedule::ALL {
        let mut settings = RenderSettings {
            width: reference.width,
            height: reference.height,
            integrator: IntegratorKind::Sppm,
            samples_per_pixel: ladder.last().copied(),
            time_limit: None,
            seed,
            ..loaded.settings.clone()
        };
        settings.sppm.radius_schedule = schedule;
        let mut render = ProgressiveRender::with_integrator(Box::new(SppmIntegrator::new(&settings)), &settings);
        let mut failure = None;
        render.run(&loaded.scene, &loaded.camera, &AtomicBool::new(false), |render| {
            let integrator = render.integrator();
            let iterations = integrator.passes();
            if !ladder.contains(&iterations) {
                return ControlFlow::Continue(());
            }
            match error_metrics(&integrator.frame(), reference) {
                Ok(metrics) => {
                    let row = ScheduleRow {
                        schedule,
                        iterations,
                        metrics,
                        mean_radius: mean_radius(integrator),
                    };
                    progress(&row);
                    rows.push(row);
                    ControlFlow::Continue(())
                }
                Err(error) => {
                    failure = Some(error);
                    ControlFlow::Break(())
                }
            }
        });
        if let Some(error) = failure {
            return Err(BenchError::Reference(error.to_string()));
        }
    }
    Ok(rows)
}

fn mean_radius(integrator: &dyn Integrator) -> f64 {
    let radii = integrator.gather_radii().unwrap_or_default();
    let (sum, count) = radii
        .iter()
        .filter(|&&r| r > 0.0)
        .fold((0.0, 0usize), |(s, n), &r| (s + r as f64, n + 1));
    if count == 0 { 0.0 } else { sum / count as f64 }
}

/// The table: one row per schedule and rung.
pub fn csv(rows: &[ScheduleRow], scene: &str, photons: u32, seed: u64, machine: &str) -> Csv {
    let mut table = Csv::new(vec![
        "scene",
        "schedule",
        "iterations",
        "rmse",
        "relmse",
        "bias_r",
        "bias_g",
        "bias_b",
        "mean_radius",
    ]);
    table.comments = vec![
        "SPPM radius schedules at equal iterations (prism bench --sppm-schedules)".into(),
        format!("{photons} photons per iteration, seed {seed}; machine: {machine}"),
    ];
    for row in rows {
        let [r, g, b] = row.metrics.bias;
        table.rows.push(vec![
            scene.to_string(),
            row.schedule.to_string(),
            row.iterations.to_string(),
            format_number(row.metrics.rmse),
            format_number(row.metrics.relative_mse),
            format_number(r),
            format_number(g),
            format_number(b),
            format_number(row.mean_radius),
        ]);
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ladder_doubles_up_to_the_last_rung() {
        assert_eq!(iteration_ladder(100), vec![1, 2, 4, 8, 16, 32, 64]);
        assert_eq!(iteration_ladder(0), vec![1]);
    }
}
