//! SPPM's gather radius: where it starts, and how it shrinks.
//!
//! - Start: the absolute `initial_radius` setting, or a few pixel footprints
//!   at the distance the camera path travelled to the visible point.
//! - Per-pixel schedule (Hachisuka & Jensen 2009, eqs. 6–7): each pixel
//!   shrinks by the photons it gathered (`statistics::PixelStatistics`),
//!   starting from its first visible point.
//! - Global schedule (Knaus & Zwicker 2011, "Progressive Photon Mapping: A
//!   Probabilistic Approach", eq. 20): iteration i (counted from 1) gathers
//!   within rᵢ, where r²ᵢ₊₁ = r²ᵢ (i + α)/(i + 1), the same factor for every
//!   pixel. Each iteration is then an independent density estimate and the
//!   image their average; the variance of iteration i grows like 1/r²ᵢ and
//!   its bias like r²ᵢ, and this sequence balances the two (both vanish in the
//!   average for 0 < α < 1). Here r₁ is the start radius of the iteration's
//!   own visible point, so no iteration reads another's state.

use super::settings::SppmSettings;
use crate::camera::Camera;

/// Automatic initial radius, in pixel footprints at the visible point: about
/// π·1.5² ≈ 7 pixels' worth of surface, enough photons per gather at the
/// default photon count to keep the first iterations from being blotchy.
const INITIAL_RADIUS_PIXELS: f64 = 1.5;

/// The radius a pixel starts with: the absolute setting, or a few pixel
/// footprints at the distance its camera path travelled.
pub struct InitialRadius {
    absolute: Option<f64>,
    /// Angle one pixel subtends (small-angle approximation of its footprint).
    pixel_angle: f64,
}

impl InitialRadius {
    /// The start radius for a render at `height` pixels with `camera`'s
    /// vertical field of view.
    pub fn new(parameters: &SppmSettings, camera: &Camera, height: u32) -> Self {
        Self {
            absolute: parameters.initial_radius,
            pixel_angle: 2.0 * (camera.fov_y_degrees.to_radians() * 0.5).tan() / height as f64,
        }
    }

    /// The start radius of a visible point whose camera path travelled
    /// `path_length` (scene units): the absolute setting if given, else
    /// `INITIAL_RADIUS_PIXELS` pixel footprints at that distance.
    pub fn at_distance(&self, path_length: f64) -> f64 {
        self.absolute
            .unwrap_or((INITIAL_RADIUS_PIXELS * self.pixel_angle * path_length).max(1e-9))
    }
}

/// r²ᵢ / r²₁ of the global schedule at zero-based `iteration`, where
/// i = `iteration` + 1: the product of (k + α)/(k + 1) for k = 1 …
/// `iteration`. Computed from scratch in the same order wherever it is
/// needed, so every machine of a farm gets the same bits for an iteration.
pub fn global_area_scale(iteration: u32, alpha: f64) -> f64 {
    let mut scale = 1.0;
    for k in 1..=iteration {
        let k = k as f64;
        scale *= (k + alpha) / (k + 1.0);
    }
    scale
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The recurrence itself, and its asymptote: the product is
    /// Γ(i + α) / (Γ(1 + α) Γ(i + 1)) ~ i^(α−1) / Γ(1 + α), so
    /// scale(i) · i^(1−α) tends to 1/Γ(1 + α); for α = 1/2, 1/Γ(3/2) = 2/√π.
    #[test]
    fn global_schedule_follows_knaus_and_zwicker() {
        let alpha = 2.0 / 3.0;
        assert_eq!(global_area_scale(0, alpha), 1.0);
        assert_eq!(global_area_scale(1, alpha), (1.0 + alpha) / 2.0);
        for i in 1..50u32 {
            let ratio = global_area_scale(i + 1, alpha) / global_area_scale(i, alpha);
            let expected = (i as f64 + 1.0 + alpha) / (i as f64 + 2.0);
            // One rounding in each product: a few ulps.
            assert!((ratio - expected).abs() < 1e-14, "{i}: {ratio} vs {expected}");
        }
        let n = 100_000u32;
        let limit = global_area_scale(n, 0.5) * (n as f64 + 1.0).sqrt();
        let expected = 2.0 / std::f64::consts::PI.sqrt();
        // The ratio of Gammas approaches the power law with relative error O(1/n).
        assert!((limit / expected - 1.0).abs() < 1e-4, "{limit} vs {expected}");
    }
}
