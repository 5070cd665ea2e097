//! What a render is asked to do. Every field here is a *sampling* parameter:
//! changing one restarts accumulation but keeps the scene and its BVH.

use crate::sampler::SamplerKind;
use serde::{Deserialize, Serialize};
use std::time::Duration;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Deserialize, Serialize)]
pub enum IntegratorKind {
    /// Path tracing with next-event estimation and MIS.
    #[default]
    #[serde(rename = "pt")]
    PathTracing,
    /// Path tracing that only follows BSDF samples (the original's method).
    #[serde(rename = "pt-bsdf")]
    BsdfOnly,
    /// Stochastic progressive photon mapping.
    #[serde(rename = "sppm")]
    Sppm,
}

impl IntegratorKind {
    pub const ALL: [IntegratorKind; 3] = [IntegratorKind::PathTracing, IntegratorKind::BsdfOnly, IntegratorKind::Sppm];

    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::PathTracing => "pt",
            IntegratorKind::BsdfOnly => "pt-bsdf",
            IntegratorKind::Sppm => "sppm",
        }
    }
}

impl std::fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Parameters of stochastic progressive photon mapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SppmSettings {
    pub photons_per_iteration: u32,
    /// Initial gather radius in scene units; `None` picks it from the pixel footprint.
    pub initial_radius: Option<f64>,
    /// Fraction of new photons kept per iteration (Hachisuka & Jensen 2009), in (0, 1).
    pub alpha: f64,
}

impl Default for SppmSettings {
    fn default() -> Self {
        Self {
            photons_per_iteration: 200_000,
            initial_radius: None,
            alpha: 2.0 / 3.0,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel (path tracing) or iterations (SPPM); `None` = until stopped.
    pub samples_per_pixel: Option<u32>,
    pub time_limit: Option<Duration>,
    pub max_depth: u32,
    pub integrator: IntegratorKind,
    pub sampler: SamplerKind,
    pub seed: u64,
    pub sppm: SppmSettings,
    /// Adaptive sampling: a pixel stops receiving samples once its relative
    /// standard error falls below this (see `render::pass::ADAPTIVE_*`);
    /// `None` samples every pixel every pass.
    pub adaptive_threshold: Option<f64>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            samples_per_pixel: Some(64),
            time_limit: None,
            max_depth: 16,
            integrator: IntegratorKind::PathTracing,
            sampler: SamplerKind::Sobol,
            seed: 0,
            sppm: SppmSettings::default(),
            adaptive_threshold: None,
        }
    }
}

impl RenderSettings {
    pub fn aspect(&self) -> f64 {
        self.width as f64 / self.height as f64
    }

    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }
}
