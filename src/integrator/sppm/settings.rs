//! The parameters only SPPM reads (plain data, gathered into
//! [`RenderSettings`](crate::settings::RenderSettings)).

/// Parameters of stochastic progressive photon mapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SppmSettings {
    /// Photons traced per iteration.
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
