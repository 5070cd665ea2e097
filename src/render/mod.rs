//! Rendering as a process: the one progressive driver that the CLI, the
//! viewer and the benchmarks all use, and the viewer's render session (a
//! render thread steered over a channel).

pub mod progressive;
pub mod session;

pub use crate::settings::{IntegratorKind, RenderSettings, SppmSettings};
pub use progressive::{Progress, ProgressiveRender, RunOutcome};

use crate::camera::Camera;
use crate::integrator::Integrator;
use crate::scene::Scene;
use std::ops::ControlFlow;
use std::sync::atomic::AtomicBool;

/// Renders to completion (the settings' pass target or time limit, or
/// adaptive convergence) on the current rayon pool.
pub fn render_to_completion(scene: &Scene, camera: &Camera, settings: &RenderSettings) -> Box<dyn Integrator> {
    let mut render = ProgressiveRender::new(settings);
    let cancel = AtomicBool::new(false);
    render.run(scene, camera, &cancel, |_| ControlFlow::Continue(()));
    render.into_integrator()
}

/// Renders to completion with `threads` worker threads (all cores if `None`).
pub fn render_with_threads(
    scene: &Scene,
    camera: &Camera,
    settings: &RenderSettings,
    threads: Option<usize>,
) -> Result<Box<dyn Integrator>, rayon::ThreadPoolBuildError> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0)).build()?;
    Ok(pool.install(|| render_to_completion(scene, camera, settings)))
}
