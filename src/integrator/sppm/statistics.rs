//! Per-pixel SPPM statistics (Hachisuka & Jensen 2009, §4): the accumulated
//! photon count N, the gather radius R and the unnormalised flux τ, shrunk
//! after every photon pass by the progressive radius reduction; and the
//! per-pass photon tally (Φ, M) that photon tracing adds to without locks.
//!
//! Invariant: `tau` is the flux gathered inside the *current* radius, so the
//! radiance estimate is τ / (π R² · photons emitted so far) (paper eq. 11).

use crate::color::Color;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicI64, AtomicU32, Ordering};

/// What one pixel has gathered over all iterations.
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelStatistics {
    /// Current gather radius; 0 until the pixel's first visible point sets it.
    pub radius: f64,
    /// Photons kept so far, N (fractional: α of each pass's M are kept).
    pub photon_count: f64,
    /// Flux τ gathered within `radius`, already weighted by the camera path.
    pub tau: Color,
    /// Sum over iterations of the emission the camera path saw directly or
    /// through specular bounces; its mean is the pixel's emitted radiance.
    pub emitted_sum: Color,
}

impl PixelStatistics {
    /// Folds one photon pass into the statistics: `new_photons` = M photons
    /// landed within the radius, carrying `flux` = Σ f·Φ_p (already multiplied
    /// by the camera throughput). Paper eqs. 6–7 and 10:
    /// N' = N + αM, R'² = R² (N + αM) / (N + M), τ' = (τ + Φ) R'² / R².
    pub fn add_photons(&mut self, flux: Color, new_photons: u32, alpha: f64) {
        if new_photons == 0 {
            return;
        }
        let m = new_photons as f64;
        let kept = self.photon_count + alpha * m;
        let shrink = kept / (self.photon_count + m);
        self.tau = (self.tau + flux) * shrink;
        self.radius *= shrink.sqrt();
        self.photon_count = kept;
    }

    /// The pixel's radiance after `iterations` passes of `photons_per_iteration`
    /// photons each: density estimate plus mean directly seen emission.
    pub fn radiance(&self, iterations: u32, photons_per_iteration: u32) -> Color {
        if iterations == 0 {
            return Color::ZERO;
        }
        let emitted = self.emitted_sum / iterations as f64;
        let photons = iterations as f64 * photons_per_iteration as f64;
        if self.radius <= 0.0 || photons == 0.0 {
            return emitted;
        }
        emitted + self.tau / (PI * self.radius * self.radius * photons)
    }
}

/// One pass's photons at one visible point: flux Φ and count M, added
/// concurrently by photon-tracing threads without locks. Flux is summed in
/// signed 32.32 fixed point relative to a scene-wide unit (the mean photon
/// flux), in atomic integers: two's-complement addition is associative, so
/// the total does not depend on which thread adds first, and the image stays
/// a pure function of the seed. Signed, because a spectral photon's film RGB
/// can have a negative channel (a saturated wavelength lies outside the sRGB
/// gamut); its mean over wavelengths is the right, non-negative value. The rounding error per photon is 2⁻³² units (about 1e-10 of a
/// typical contribution); a pixel would need ~4·10⁹ units in one pass to overflow.
#[derive(Debug, Default)]
pub struct PhotonTally {
    flux: [AtomicI64; 3],
    count: AtomicU32,
}

/// Fixed-point scale: 32 fractional bits.
const FIXED_POINT_ONE: f64 = 4_294_967_296.0;
/// Largest single contribution, in units, so one sum cannot wrap around.
const MAX_UNITS_PER_PHOTON: f64 = 1e6;

impl PhotonTally {
    /// Adds one photon's contribution; `inverse_unit` is 1 / the flux unit.
    #[inline]
    pub fn add(&self, flux: Color, inverse_unit: f64) {
        for (channel, value) in self.flux.iter().zip(flux.to_array()) {
            let units = (value * inverse_unit).clamp(-MAX_UNITS_PER_PHOTON, MAX_UNITS_PER_PHOTON);
            let fixed = round_half_away_from_zero(units * FIXED_POINT_ONE);
            if fixed != 0 {
                channel.fetch_add(fixed, Ordering::Relaxed);
            }
        }
        self.count.fetch_add(1, Ordering::Relaxed);
    }

    /// Returns (Φ, M), Φ in flux (`unit` per unit), and resets the tally.
    pub fn take(&mut self, unit: f64) -> (Color, u32) {
        let flux = self
            .flux
            .each_mut()
            .map(|c| std::mem::take(c.get_mut()) as f64 / FIXED_POINT_ONE * unit);
        (Color::from_array(flux), std::mem::take(self.count.get_mut()))
    }
}

/// `x.round() as i64` for |x| < 2⁶³, without `round`'s library call (the
/// x86-64 baseline has no SSE4.1 rounding instruction), in a loop that runs
/// for every photon a visible point gathers. The cast truncates; `x - t` is
/// exact (t is x with its fraction bits cleared, or x itself beyond 2⁵²), so
/// comparing it with ±½ rounds halves away from zero exactly as `round` does.
#[inline]
fn round_half_away_from_zero(x: f64) -> i64 {
    let truncated = x as i64;
    let fraction = x - truncated as f64;
    if fraction >= 0.5 {
        truncated + 1
    } else if fraction <= -0.5 {
        truncated - 1
    } else {
        truncated
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same integers as `f64::round`, at halves, next to halves, at
    /// large magnitudes and at zero (the tally's clamp keeps |x| ≤ 2⁵²).
    #[test]
    fn rounding_matches_the_standard_library() {
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            -2.5,
            0.49999999999999994,
            -0.49999999999999994,
        ];
        values.extend([
            1e6 * FIXED_POINT_ONE,
            -1e6 * FIXED_POINT_ONE,
            4503599627370495.5,
            -4503599627370495.5,
        ]);
        let mut state = 0x1234_5678_9abc_def0u64;
        for _ in 0..100_000 {
            state = crate::sampler::mix64(state);
            // Magnitudes from 2⁻¹⁰ to 2⁵² and both signs.
            let scale = 2f64.powi((state % 63) as i32 - 10);
            let x = ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2.0 * scale;
            values.extend([x, x.trunc() + 0.5, x.trunc() - 0.5]);
        }
        for x in values {
            let expected = x.round() as i64;
            assert_eq!(round_half_away_from_zero(x), expected, "{x:e}");
            let nudged = [x.next_up(), x.next_down()];
            for y in nudged {
                assert_eq!(round_half_away_from_zero(y), y.round() as i64, "{y:e}");
            }
        }
    }

    #[test]
    fn radius_shrinks_by_the_paper_ratio_and_tau_follows_the_area() {
        let mut p = PixelStatistics {
            radius: 2.0,
            photon_count: 10.0,
            tau: Color::splat(4.0),
            emitted_sum: Color::ZERO,
        };
        p.add_photons(Color::splat(2.0), 20, 0.5);
        // N' = 10 + 0.5·20 = 20; R'² = 4 · 20/30; τ' = 6 · 20/30.
        assert!((p.photon_count - 20.0).abs() < 1e-12);
        assert!((p.radius * p.radius - 4.0 * 20.0 / 30.0).abs() < 1e-12);
        assert!((p.tau - Color::splat(4.0)).length() < 1e-12);
    }

    #[test]
    fn a_uniform_photon_density_is_estimated_exactly() {
        // Each pass lands ρπR² photon-flux units inside the radius. By
        // induction τ = kρπR² after k passes whatever the shrinkage, so
        // τ/(πR²·k) must return ρ (one photon "emitted" per pass).
        let density = 50.0;
        let mut p = PixelStatistics {
            radius: 1.0,
            ..Default::default()
        };
        for _ in 0..40 {
            let m = density * PI * p.radius * p.radius;
            // Round M and scale the flux to match, as real photons would.
            let count = m.round().max(1.0) as u32;
            p.add_photons(Color::splat(count as f64), count, 2.0 / 3.0);
        }
        let estimate = p.radiance(40, 1).x;
        // Rounding M to an integer each pass perturbs the area by < 1/M ≈ 2%.
        assert!((estimate / density - 1.0).abs() < 0.05, "{estimate}");
        assert!(p.radius < 0.5);
    }

    #[test]
    fn no_photons_changes_nothing() {
        let mut p = PixelStatistics {
            radius: 1.0,
            photon_count: 3.0,
            tau: Color::ONE,
            emitted_sum: Color::ZERO,
        };
        p.add_photons(Color::ZERO, 0, 0.7);
        assert_eq!((p.radius, p.photon_count, p.tau), (1.0, 3.0, Color::ONE));
    }

    #[test]
    fn tally_sums_across_threads() {
        let mut tally = PhotonTally::default();
        let unit = 8.0;
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| {
                    for _ in 0..1000 {
                        tally.add(Color::new(0.5, 0.25, 1.0), 1.0 / unit);
                    }
                });
            }
        });
        let (flux, count) = tally.take(unit);
        assert_eq!(count, 4000);
        assert_eq!(flux, Color::new(2000.0, 1000.0, 4000.0));
        assert_eq!(tally.take(unit), (Color::ZERO, 0));
    }

    /// Fixed-point sums do not depend on the order of the additions (f64
    /// sums do): the same contributions in two orders give identical bits.
    #[test]
    fn tally_is_independent_of_addition_order() {
        let values: Vec<Color> = (0..1000).map(|i| Color::splat(1.0 / (1.0 + i as f64 * 0.37))).collect();
        let (mut forward, mut backward) = (PhotonTally::default(), PhotonTally::default());
        for v in &values {
            forward.add(*v, 1.0 / 3.0);
        }
        for v in values.iter().rev() {
            backward.add(*v, 1.0 / 3.0);
        }
        let (a, b) = (forward.take(3.0), backward.take(3.0));
        assert_eq!(a, b);
        let exact: f64 = values.iter().map(|v| v.x).sum();
        assert!((a.0.x - exact).abs() < 1e-6 * exact);
    }
}
