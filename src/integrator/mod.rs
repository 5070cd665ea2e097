//! Integrators: how light transport is estimated. Each one renders
//! progressive passes into its own state and hands out `Frame`s, so nothing
//! downstream (viewer, CLI, benchmarks) branches on the algorithm.

pub mod path;
pub mod sppm;

use crate::camera::Camera;
use crate::film::Frame;
use crate::render::settings::RenderSettings;
use crate::scene::Scene;
use std::sync::atomic::AtomicBool;

/// A progressive renderer of one image.
pub trait Integrator: Send {
    /// Adds one pass: one sample per pixel, or one SPPM iteration. Returns
    /// false if `cancel` was raised before the pass completed (the state is
    /// then unspecified and the caller starts over).
    fn render_pass(&mut self, scene: &Scene, camera: &Camera, cancel: &AtomicBool) -> bool;

    /// Completed passes.
    fn passes(&self) -> u32;

    /// The current estimate.
    fn frame(&self) -> Frame;

    /// Samples that were NaN or infinite and were dropped (must stay 0).
    fn rejected_samples(&self) -> u64 {
        0
    }

    /// Adaptive sampling has stopped every pixel, so further passes would
    /// add nothing: progressive drivers stop here, before any sample or time
    /// target.
    fn converged(&self) -> bool {
        false
    }

    /// A short status, e.g. the SPPM radius; empty by default.
    fn status(&self) -> String {
        String::new()
    }
}

/// The integrator the settings ask for.
pub fn create(settings: &RenderSettings) -> Box<dyn Integrator> {
    use crate::render::settings::IntegratorKind;
    match settings.integrator {
        IntegratorKind::PathTracing | IntegratorKind::BsdfOnly => Box::new(path::PathIntegrator::new(settings)),
        IntegratorKind::Sppm => Box::new(sppm::SppmIntegrator::new(settings)),
    }
}
