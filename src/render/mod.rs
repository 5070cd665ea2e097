//! Rendering as a process: settings, the shared pixel loop, and the
//! progressive driver that the CLI, the viewer and the benchmarks all use.

pub mod pass;
pub mod session;
pub mod settings;

pub use settings::{IntegratorKind, RenderSettings, SppmSettings};

use crate::camera::Camera;
use crate::integrator::{self, Integrator};
use crate::scene::Scene;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Where a progressive render stands after a pass.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    pub passes: u32,
    pub target_passes: Option<u32>,
    pub elapsed: Duration,
    pub time_limit: Option<Duration>,
}

impl Progress {
    /// Fraction done, by passes or by time, whichever is further along.
    pub fn fraction(&self) -> Option<f64> {
        let by_passes = self.target_passes.map(|t| self.passes as f64 / t.max(1) as f64);
        let by_time = self
            .time_limit
            .map(|t| self.elapsed.as_secs_f64() / t.as_secs_f64().max(1e-9));
        match (by_passes, by_time) {
            (Some(a), Some(b)) => Some(a.max(b).min(1.0)),
            (a, b) => a.or(b).map(|f| f.min(1.0)),
        }
    }

    pub fn finished(&self) -> bool {
        self.fraction().is_some_and(|f| f >= 1.0)
    }
}

/// Renders passes until the sample target or time limit is reached, adaptive
/// sampling has stopped every pixel (`Integrator::converged`), or `cancel` is
/// raised, calling `on_pass` after each completed pass. At least one pass is
/// rendered unless cancelled. Runs on the current rayon pool.
pub fn render_progressive(
    scene: &Scene,
    camera: &Camera,
    settings: &RenderSettings,
    cancel: &AtomicBool,
    mut on_pass: impl FnMut(&dyn Integrator, &Progress),
) -> Box<dyn Integrator> {
    let mut integrator = integrator::create(settings);
    let start = Instant::now();
    loop {
        if cancel.load(Ordering::Relaxed) || !integrator.render_pass(scene, camera, cancel) {
            break;
        }
        let progress = Progress {
            passes: integrator.passes(),
            target_passes: settings.samples_per_pixel,
            elapsed: start.elapsed(),
            time_limit: settings.time_limit,
        };
        on_pass(integrator.as_ref(), &progress);
        if progress.finished() || integrator.converged() {
            break;
        }
    }
    integrator
}

/// Renders to completion with `threads` worker threads (all cores if `None`).
pub fn render_with_threads(
    scene: &Scene,
    camera: &Camera,
    settings: &RenderSettings,
    threads: Option<usize>,
) -> Result<Box<dyn Integrator>, rayon::ThreadPoolBuildError> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0)).build()?;
    let cancel = AtomicBool::new(false);
    Ok(pool.install(|| render_progressive(scene, camera, settings, &cancel, |_, _| {})))
}
