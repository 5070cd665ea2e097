//! The one progressive driver (pbrt-v4's `ImageTileIntegrator::Render`, in
//! spirit): it owns an integrator, renders one pass per [`step`], keeps the
//! render time and the pass count, and knows when the sample target, the time
//! limit or adaptive sampling's convergence ends the render. The CLI, the
//! viewer's render session and every benchmark drive their renders through
//! it, so "what a pass is" and "when a render is done" are written once.
//!
//! Callers stop a render in two ways: the `cancel` flag aborts the pass in
//! flight (its partial state is thrown away), and [`ProgressiveRender::run`]'s
//! callback ends the loop between passes, keeping everything rendered.
//!
//! [`step`]: ProgressiveRender::step

use crate::camera::Camera;
use crate::integrator::{self, Integrator};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Where a progressive render stands after a pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Completed passes (samples per pixel, or SPPM iterations).
    pub passes: u32,
    /// The pass target, if any.
    pub target_passes: Option<u32>,
    /// Time spent rendering passes (pauses and the callers' own work excluded).
    pub elapsed: Duration,
    /// The render-time limit, if any.
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

    /// The pass target or the time limit has been reached.
    pub fn target_reached(&self) -> bool {
        self.fraction().is_some_and(|f| f >= 1.0)
    }

    /// Estimated render time until the pass target or the time limit,
    /// whichever comes first; `None` before the first pass of an open-ended render.
    pub fn remaining(&self) -> Option<Duration> {
        let by_passes = self.target_passes.filter(|_| self.passes > 0).map(|target| {
            let per_pass = self.elapsed.as_secs_f64() / self.passes as f64;
            Duration::from_secs_f64(per_pass * target.saturating_sub(self.passes) as f64)
        });
        let by_time = self.time_limit.map(|limit| limit.saturating_sub(self.elapsed));
        match (by_passes, by_time) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
}

/// How a call to [`ProgressiveRender::run`] ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RunOutcome {
    /// The pass target or time limit was reached, or adaptive sampling
    /// stopped every pixel.
    Finished,
    /// The callback asked to stop; every completed pass is kept.
    Stopped,
    /// The cancel flag aborted a pass; the integrator's state is unspecified.
    Cancelled,
}

/// A render in progress: an integrator, its targets and its render time.
pub struct ProgressiveRender {
    integrator: Box<dyn Integrator>,
    target_passes: Option<u32>,
    time_limit: Option<Duration>,
    elapsed: Duration,
    last_pass: Duration,
}

impl ProgressiveRender {
    /// A fresh render of the integrator `settings` asks for, with its targets.
    pub fn new(settings: &RenderSettings) -> Self {
        Self::with_integrator(integrator::create(settings), settings)
    }

    /// Drives a given integrator (e.g. a preview) to the targets of `settings`.
    pub fn with_integrator(integrator: Box<dyn Integrator>, settings: &RenderSettings) -> Self {
        Self {
            integrator,
            target_passes: settings.samples_per_pixel,
            time_limit: settings.time_limit,
            elapsed: Duration::ZERO,
            last_pass: Duration::ZERO,
        }
    }

    /// Renders one pass. Returns false if `cancel` was raised before it
    /// completed; the integrator's state is then unspecified (start over).
    pub fn step(&mut self, scene: &Scene, camera: &Camera, cancel: &AtomicBool) -> bool {
        if cancel.load(Ordering::Relaxed) {
            return false;
        }
        let start = Instant::now();
        let completed = self.integrator.render_pass(scene, camera, cancel);
        self.last_pass = start.elapsed();
        if completed {
            self.elapsed += self.last_pass;
        }
        completed
    }

    /// Renders passes until the render is finished, `cancel` aborts a pass,
    /// or `on_pass` (called after every completed pass) breaks. At least one
    /// pass is rendered unless cancelled. Runs on the current rayon pool.
    pub fn run(
        &mut self,
        scene: &Scene,
        camera: &Camera,
        cancel: &AtomicBool,
        mut on_pass: impl FnMut(&ProgressiveRender) -> ControlFlow<()>,
    ) -> RunOutcome {
        loop {
            if !self.step(scene, camera, cancel) {
                return RunOutcome::Cancelled;
            }
            if on_pass(self).is_break() {
                return if self.is_finished() {
                    RunOutcome::Finished
                } else {
                    RunOutcome::Stopped
                };
            }
            if self.is_finished() {
                return RunOutcome::Finished;
            }
        }
    }

    /// The pass target or time limit has been reached, or adaptive sampling
    /// has stopped every pixel (further passes would add nothing).
    pub fn is_finished(&self) -> bool {
        self.progress().target_reached() || self.integrator.converged()
    }

    /// Passes, targets and render time.
    pub fn progress(&self) -> Progress {
        Progress {
            passes: self.integrator.passes(),
            target_passes: self.target_passes,
            elapsed: self.elapsed,
            time_limit: self.time_limit,
        }
    }

    /// Render time of the most recent pass.
    pub fn last_pass_time(&self) -> Duration {
        self.last_pass
    }

    /// New targets for the same accumulation: a finished render continues
    /// when they are raised.
    pub fn set_targets(&mut self, passes: Option<u32>, time_limit: Option<Duration>) {
        self.target_passes = passes;
        self.time_limit = time_limit;
    }

    /// The integrator, for its frame, status and views.
    pub fn integrator(&self) -> &dyn Integrator {
        self.integrator.as_ref()
    }

    /// The integrator, for callers that keep it after the render.
    pub fn into_integrator(self) -> Box<dyn Integrator> {
        self.integrator
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{DEFAULT_SCENE, load_scene_str};
    use std::path::Path;

    fn small_settings() -> (crate::scene::LoadedScene, RenderSettings) {
        let loaded = load_scene_str(DEFAULT_SCENE, Path::new("cornell"), Path::new(".")).expect("default scene");
        let settings = RenderSettings {
            width: 8,
            height: 8,
            samples_per_pixel: Some(5),
            ..loaded.settings.clone()
        };
        (loaded, settings)
    }

    #[test]
    fn runs_to_the_pass_target_and_reports_each_pass() {
        let (loaded, settings) = small_settings();
        let mut render = ProgressiveRender::new(&settings);
        let mut seen = Vec::new();
        let cancel = AtomicBool::new(false);
        let outcome = render.run(&loaded.scene, &loaded.camera, &cancel, |r| {
            seen.push(r.progress().passes);
            ControlFlow::Continue(())
        });
        assert_eq!(outcome, RunOutcome::Finished);
        assert_eq!(seen, vec![1, 2, 3, 4, 5]);
        assert!(render.progress().elapsed > Duration::ZERO);
    }

    #[test]
    fn the_callback_stops_between_passes_and_raised_targets_continue() {
        let (loaded, settings) = small_settings();
        let mut render = ProgressiveRender::new(&settings);
        let cancel = AtomicBool::new(false);
        let outcome = render.run(&loaded.scene, &loaded.camera, &cancel, |r| {
            if r.progress().passes == 2 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        });
        assert_eq!(outcome, RunOutcome::Stopped);
        assert_eq!(render.progress().passes, 2);
        let outcome = render.run(&loaded.scene, &loaded.camera, &cancel, |_| ControlFlow::Continue(()));
        assert_eq!((outcome, render.progress().passes), (RunOutcome::Finished, 5));
        render.set_targets(Some(7), None);
        assert!(!render.is_finished());
        render.run(&loaded.scene, &loaded.camera, &cancel, |_| ControlFlow::Continue(()));
        assert_eq!(render.progress().passes, 7);
    }

    #[test]
    fn a_raised_cancel_flag_renders_nothing() {
        let (loaded, settings) = small_settings();
        let mut render = ProgressiveRender::new(&settings);
        let cancel = AtomicBool::new(true);
        let outcome = render.run(&loaded.scene, &loaded.camera, &cancel, |_| ControlFlow::Continue(()));
        assert_eq!((outcome, render.progress().passes), (RunOutcome::Cancelled, 0));
    }

    #[test]
    fn remaining_time_follows_the_pass_rate() {
        let progress = Progress {
            passes: 4,
            target_passes: Some(10),
            elapsed: Duration::from_secs(2),
            time_limit: Some(Duration::from_secs(60)),
        };
        assert_eq!(progress.remaining(), Some(Duration::from_secs(3)));
        assert!((progress.fraction().unwrap_or(0.0) - 0.4).abs() < 1e-12);
    }
}
