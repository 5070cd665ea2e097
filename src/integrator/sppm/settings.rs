//! The parameters only SPPM reads (plain data, gathered into
//! [`RenderSettings`](crate::settings::RenderSettings)).

use serde::{Deserialize, Serialize};

/// Parameters of stochastic progressive photon mapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SppmSettings {
    /// Photons traced per iteration.
    pub photons_per_iteration: u32,
    /// Initial gather radius in scene units; `None` picks it from the pixel footprint.
    pub initial_radius: Option<f64>,
    /// Fraction of new photons kept per iteration (Hachisuka & Jensen 2009), in (0, 1).
    pub alpha: f64,
    /// How the gather radius shrinks from one iteration to the next.
    pub radius_schedule: RadiusSchedule,
}

impl Default for SppmSettings {
    fn default() -> Self {
        Self {
            photons_per_iteration: 200_000,
            initial_radius: None,
            alpha: 2.0 / 3.0,
            radius_schedule: RadiusSchedule::PerPixel,
        }
    }
}

/// How SPPM's gather radius shrinks (see `sppm::radius`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
pub enum RadiusSchedule {
    /// Each pixel shrinks its radius by the photons it has gathered
    /// (Hachisuka & Jensen 2009). Iteration i depends on iterations 0..i, so
    /// the render cannot be split across machines. The default.
    #[default]
    #[serde(rename = "per-pixel")]
    PerPixel,
    /// Every pixel follows the same sequence r²ᵢ₊₁ = r²ᵢ (i + α)/(i + 1)
    /// (Knaus & Zwicker 2011): iterations are independent estimates that
    /// are averaged, so ranges of iterations render anywhere and merge exactly.
    #[serde(rename = "global")]
    Global,
}

impl RadiusSchedule {
    /// Both schedules, for benchmarks that compare them.
    pub const ALL: [RadiusSchedule; 2] = [RadiusSchedule::PerPixel, RadiusSchedule::Global];

    /// The name in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            RadiusSchedule::PerPixel => "per-pixel",
            RadiusSchedule::Global => "global",
        }
    }
}

impl std::fmt::Display for RadiusSchedule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
