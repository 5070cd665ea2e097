//! Integrators: how light transport is estimated. Each one renders
//! progressive passes into its own state and hands out `Frame`s, so nothing
//! downstream (viewer, CLI, benchmarks) branches on the algorithm: what a
//! view needs from a particular integrator (SPPM's gather radii, a cheaper
//! preview) comes through the [`Integrator`] trait.
//!
//! - [`bsdf_inputs`]: a BSDF's sample inputs drawn from a sample stream
//!   (shared by path tracing and SPPM);
//! - [`pass`]: the parallel pixel loop that per-pixel integrators share,
//!   with adaptive sampling;
//! - [`path`]: path tracing with light sampling and MIS, or BSDF sampling only;
//! - [`sppm`]: stochastic progressive photon mapping;
//! - [`share`]: which samples and rows a render computes (a whole image, or
//!   one machine's part of a farm render).

pub mod bsdf_inputs;
pub mod pass;
pub mod path;
pub mod share;
pub mod sppm;

pub use share::{RowSet, Share};

use crate::camera::Camera;
use crate::film::{Film, Frame};
use crate::scene::Scene;
use crate::settings::{IntegratorKind, RenderSettings};
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

    /// The exact per-pixel sums behind [`frame`](Self::frame), for
    /// integrators whose passes are independent estimates that add up (so
    /// shares of a render can be merged); `None` for the others (SPPM with
    /// its per-pixel radius update).
    fn film(&self) -> Option<&Film> {
        None
    }

    /// A fresh integrator of the same kind for an image `divisor` times
    /// smaller on each axis, costing about 1/`divisor`² of a pass: the
    /// coarse previews a viewer shows right after a change.
    fn preview(&self, divisor: u32) -> Box<dyn Integrator>;

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

    /// Per-pixel gather radius (row-major, 0 where none yet) for integrators
    /// that estimate density within a radius; `None` for the others.
    fn gather_radii(&self) -> Option<Vec<f32>> {
        None
    }

    /// Whether [`frame`](Integrator::frame) carries a per-pixel noise
    /// estimate (`Frame::noise`): an average of independent samples has one,
    /// a progressive density estimate (whose samples are neither independent
    /// nor identically distributed) has none.
    fn estimates_noise(&self) -> bool {
        true
    }

    /// Samples taken per pixel (row-major) where they differ between pixels
    /// or are not simply the pass count; `None` if unknown.
    fn sample_counts(&self) -> Option<Vec<u32>> {
        None
    }
}

/// The integrator the settings ask for.
pub fn create(settings: &RenderSettings) -> Box<dyn Integrator> {
    create_share(settings, &Share::whole(settings.samples_per_pixel.unwrap_or(0)))
}

/// The integrator the settings ask for, computing only `share`: its passes
/// use the share's sample indices (or iterations) in order and sample only
/// its rows. The caller stops it after [`Share::passes`] passes (or, with
/// adaptive sampling, when it has converged).
pub fn create_share(settings: &RenderSettings, share: &Share) -> Box<dyn Integrator> {
    match settings.integrator {
        IntegratorKind::PathTracing | IntegratorKind::BsdfOnly => Box::new(path::PathIntegrator::with_share(settings, share)),
        IntegratorKind::Sppm => Box::new(sppm::SppmIntegrator::with_share(settings, share)),
    }
}

/// `settings` for an image `divisor` times smaller on each axis (at least one pixel).
pub fn reduced_resolution(settings: &RenderSettings, divisor: u32) -> RenderSettings {
    let divisor = divisor.max(1);
    RenderSettings {
        width: (settings.width / divisor).max(1),
        height: (settings.height / divisor).max(1),
        ..settings.clone()
    }
}
