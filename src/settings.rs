//! What a render is asked to do: plain data at the bottom of the layers,
//! read by the scene loader, the integrators, the progressive driver and the
//! viewer alike. Every field is a *sampling* parameter: changing one restarts
//! accumulation but keeps the scene and its BVH. Settings that only one
//! integrator reads are defined beside it (as plain data with no imports of
//! their own) and gathered here. Their one validation, shared by the scene
//! file and the command line, is in [`validate`].

pub mod validate;

pub use crate::integrator::sppm::settings::SppmSettings;
use crate::sampler::SamplerKind;
use serde::{Deserialize, Serialize};
use std::time::Duration;
pub use validate::{Setting, SettingError, SettingsPatch};

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
    /// standard error falls below this (see `integrator::pass::ADAPTIVE_*`);
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
