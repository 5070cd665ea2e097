//! The wavelengths one path carries: hero-wavelength sampling (Wilkie,
//! Nawaz, Droske, Weidlich & Hanika 2014, "Hero Wavelength Spectral
//! Sampling"). The hero λ₀ is uniform over 360–830 nm; the others are the
//! hero rotated by equal strides of the range, λᵢ = λ₀ + i·Δ/N wrapped into
//! the range, so each is also uniform and together they stratify it. The
//! estimator is the average over the lanes of f(λᵢ)/p(λᵢ) (their eq. 7 with
//! the balance heuristic, which for a uniform p is a plain average).

use super::cie::GridPosition;
use super::{LAMBDA_MAX, LAMBDA_MIN, WAVELENGTHS};

/// The wavelengths of one path, in nanometres, with their densities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledWavelengths {
    /// λ of each lane; lane 0 is the hero.
    pub lambda: [f64; WAVELENGTHS],
    /// Density of each lane's λ per nanometre; 0 once a lane is terminated.
    pub pdf: [f64; WAVELENGTHS],
    /// Each λ's place on the spectral grid, for table lookups.
    pub grid: [GridPosition; WAVELENGTHS],
}

impl SampledWavelengths {
    /// The hero at `u` ∈ [0, 1) of the range, the others at equal strides after it.
    pub fn sample_uniform(u: f64) -> Self {
        let range = LAMBDA_MAX - LAMBDA_MIN;
        let lambda = std::array::from_fn(|i| {
            let offset = (u + i as f64 / WAVELENGTHS as f64).fract();
            LAMBDA_MIN + offset * range
        });
        Self::with_lambda(lambda, [1.0 / range; WAVELENGTHS])
    }

    /// Every lane at one wavelength, with density 1: the estimator then
    /// returns the monochromatic value times the matching functions there
    /// (for measurements at a fixed wavelength, such as the prism test).
    pub fn fixed(lambda_nm: f64) -> Self {
        Self::with_lambda([lambda_nm; WAVELENGTHS], [1.0; WAVELENGTHS])
    }

    fn with_lambda(lambda: [f64; WAVELENGTHS], pdf: [f64; WAVELENGTHS]) -> Self {
        Self {
            lambda,
            pdf,
            grid: lambda.map(GridPosition::of),
        }
    }

    /// The hero wavelength.
    pub fn hero(&self) -> f64 {
        self.lambda[0]
    }

    /// Drops every lane but the hero, whose density is divided by the lane
    /// count so that it alone carries the whole estimate (pbrt-v4's
    /// `SampledWavelengths::TerminateSecondary`): needed where the path's
    /// direction depends on λ, as at a dispersive interface, since the path
    /// is then valid for the hero only.
    pub fn terminate_secondary(&mut self) {
        if self.secondary_terminated() {
            return;
        }
        for pdf in &mut self.pdf[1..] {
            *pdf = 0.0;
        }
        self.pdf[0] /= WAVELENGTHS as f64;
    }

    /// Whether [`terminate_secondary`](Self::terminate_secondary) has run.
    pub fn secondary_terminated(&self) -> bool {
        self.pdf[1..].iter().all(|&p| p == 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_are_equal_strides_of_the_range_and_stay_inside_it() {
        let range = LAMBDA_MAX - LAMBDA_MIN;
        for k in 0..100 {
            let w = SampledWavelengths::sample_uniform(k as f64 / 100.0);
            let mut sorted = w.lambda;
            sorted.sort_by(f64::total_cmp);
            for pair in sorted.windows(2) {
                assert!((pair[1] - pair[0] - range / WAVELENGTHS as f64).abs() < 1e-9);
            }
            assert!(w.lambda.iter().all(|l| (LAMBDA_MIN..LAMBDA_MAX).contains(l)));
        }
    }

    #[test]
    fn terminating_secondaries_keeps_the_total_weight() {
        // Σ 1/pdf over live lanes divided by N is the range either way.
        let mut w = SampledWavelengths::sample_uniform(0.3);
        let weight =
            |w: &SampledWavelengths| w.pdf.iter().filter(|&&p| p > 0.0).map(|p| 1.0 / p).sum::<f64>() / WAVELENGTHS as f64;
        let before = weight(&w);
        w.terminate_secondary();
        w.terminate_secondary();
        assert!((weight(&w) - before).abs() < 1e-9 && w.secondary_terminated());
        assert_eq!(w.pdf[0], 1.0 / (4.0 * 470.0));
    }
}
