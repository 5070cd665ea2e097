//! Blackbody emission: Planck's law for the spectral radiance of a body in
//! thermal equilibrium at temperature T,
//!
//!   B(λ, T) = 2hc² / λ⁵ · 1 / (e^{hc/(λ k T)} − 1),
//!
//! in W·m⁻²·sr⁻¹ per metre of wavelength, with the CODATA 2018 values of h,
//! c and k (exact since the 2019 SI). A scene's blackbody emitter is scaled
//! to a luminance, so only the shape of B matters to rendering; the absolute
//! value is kept right anyway, and checked against the Stefan–Boltzmann law.

use super::cie::{GRID_POINTS, GRID_START, GRID_STEP};

/// Planck constant h, J·s (CODATA 2018, exact).
pub const PLANCK: f64 = 6.626_070_15e-34;
/// Speed of light in vacuum c, m/s (exact).
pub const SPEED_OF_LIGHT: f64 = 299_792_458.0;
/// Boltzmann constant k, J/K (CODATA 2018, exact).
pub const BOLTZMANN: f64 = 1.380_649e-23;
/// Wien's displacement constant b, m·K (CODATA 2018): B(λ, T) peaks at λ = b/T.
pub const WIEN_DISPLACEMENT: f64 = 2.897_771_955e-3;

/// Second radiation constant c₂ = hc/k, m·K (1.438 777…·10⁻²).
const C2: f64 = PLANCK * SPEED_OF_LIGHT / BOLTZMANN;
/// First radiation constant for spectral radiance c₁L = 2hc², W·m²·sr⁻¹.
const C1L: f64 = 2.0 * PLANCK * SPEED_OF_LIGHT * SPEED_OF_LIGHT;

/// Lowest temperature a scene may give a blackbody emitter, kelvin. Below
/// about 800 K (the Draper point) a blackbody does not glow visibly; at 500 K
/// its visible radiance is still a representable, if tiny, number, which the
/// emitter's luminance then scales up.
pub const TEMPERATURE_MIN: f64 = 500.0;
/// Highest temperature a scene may give, kelvin: far beyond any star's
/// photosphere, where the visible spectrum has long reached its limiting
/// (Rayleigh–Jeans) shape λ⁻⁴.
pub const TEMPERATURE_MAX: f64 = 1.0e6;

/// Spectral radiance B(λ, T) of a blackbody, W·m⁻²·sr⁻¹·m⁻¹, at
/// `lambda_nm` nanometres and `kelvin`.
pub fn planck(lambda_nm: f64, kelvin: f64) -> f64 {
    let lambda = lambda_nm * 1e-9;
    C1L / lambda.powi(5) / (C2 / (lambda * kelvin)).exp_m1()
}

/// B(λ, T) at every grid point, relative to its largest value there (so that
/// every temperature in range gives numbers near 1, whatever its absolute
/// radiance).
pub fn relative_on_grid(kelvin: f64) -> [f64; GRID_POINTS] {
    let table: [f64; GRID_POINTS] = std::array::from_fn(|i| planck(GRID_START + GRID_STEP * i as f64, kelvin));
    let peak = table.iter().fold(0.0f64, |m, &v| m.max(v));
    table.map(|v| v / peak)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::sensor::Sensor;

    /// The wavelength where B(·, T) peaks, by golden-section search on
    /// [λ_lo, λ_hi] nm (B is unimodal in λ).
    fn peak_wavelength(kelvin: f64, mut lo: f64, mut hi: f64) -> f64 {
        let ratio = (5f64.sqrt() - 1.0) / 2.0;
        while hi - lo > 1e-9 * hi {
            let (a, b) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
            if planck(a, kelvin) < planck(b, kelvin) {
                lo = a;
            } else {
                hi = b;
            }
        }
        0.5 * (lo + hi)
    }

    #[test]
    fn the_constants_give_the_published_second_radiation_constant() {
        // CODATA 2018: c₂ = 1.438 776 877…·10⁻² m·K.
        assert!((C2 / 1.438_776_877e-2 - 1.0).abs() < 1e-9, "{C2}");
    }

    /// Wien's displacement law: the peak found by searching B itself lies at
    /// b/T, b from CODATA (it is hc/(k·x), x = 4.965… the root of
    /// x = 5(1 − e⁻ˣ), so this checks the exponent and the constants
    /// together). The search is exact to 10⁻⁹ relative; 10⁻⁶ leaves room for
    /// the flat top's rounding.
    #[test]
    fn the_peak_obeys_wiens_displacement_law() {
        for kelvin in [1000.0, 1900.0, 2856.0, 5772.0, 6500.0, 10000.0] {
            let expected = WIEN_DISPLACEMENT / kelvin * 1e9;
            let found = peak_wavelength(kelvin, 0.2 * expected, 5.0 * expected);
            eprintln!("{kelvin} K: peak {found:.4} nm, b/T {expected:.4} nm");
            assert!(
                (found / expected - 1.0).abs() < 1e-6,
                "{kelvin} K: {found} nm against {expected} nm"
            );
        }
    }

    /// The Stefan–Boltzmann law: π ∫ B dλ = σT⁴, σ = 5.670 374 419·10⁻⁸
    /// W·m⁻²·K⁻⁴ (CODATA 2018), by Simpson's rule in x = hc/(λkT) over
    /// [10⁻³, 60] (the tails beyond hold less than 10⁻⁹ of the total). A
    /// check of B's absolute scale, 10⁻⁶.
    #[test]
    fn the_total_radiance_obeys_stefan_boltzmann() {
        let sigma = 5.670_374_419e-8;
        let kelvin = 3000.0;
        // λ = C2/(xT), dλ = C2/(x²T) dx.
        let integrand = |x: f64| {
            let lambda_nm = C2 / (x * kelvin) * 1e9;
            planck(lambda_nm, kelvin) * C2 / (x * x * kelvin)
        };
        let (a, b, n) = (1e-3, 60.0, 20_000);
        let h = (b - a) / n as f64;
        let sum: f64 = (0..=n)
            .map(|i| {
                let weight = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                weight * integrand(a + h * i as f64)
            })
            .sum();
        let exitance = std::f64::consts::PI * sum * h / 3.0;
        let expected = sigma * kelvin.powi(4);
        assert!((exitance / expected - 1.0).abs() < 1e-6, "{exitance} against {expected}");
    }

    /// Chromaticities of blackbodies against the Planckian locus as
    /// published for the CIE 1931 observer, to four decimals (J. Walker,
    /// "Colour Rendering of Spectra", fourmilab.ch, whose table agrees with
    /// Wyszecki & Stiles, "Color Science", 2nd ed., 1982). Tolerance 10⁻³:
    /// the published values' rounding (5·10⁻⁵) plus this film's 5 nm grid
    /// and 360–830 nm range against the 1–5 nm sums of the sources.
    #[test]
    fn chromaticities_lie_on_the_published_planckian_locus() {
        let sensor = Sensor::get();
        for (kelvin, expected) in [
            (1500.0, [0.5857, 0.3931]),
            (2000.0, [0.5267, 0.4133]),
            (3000.0, [0.4369, 0.4041]),
            (4000.0, [0.3805, 0.3768]),
            (5000.0, [0.3451, 0.3516]),
            (6500.0, [0.3135, 0.3237]),
            (10000.0, [0.2807, 0.2884]),
        ] {
            let xyz = sensor.xyz_of_table(&relative_on_grid(kelvin));
            let sum = xyz.x + xyz.y + xyz.z;
            let (x, y) = (xyz.x / sum, xyz.y / sum);
            eprintln!("{kelvin} K: ({x:.5}, {y:.5}) against {expected:?}");
            assert!(
                (x - expected[0]).abs() < 1e-3 && (y - expected[1]).abs() < 1e-3,
                "{kelvin} K: ({x}, {y}) against {expected:?}"
            );
        }
    }

    #[test]
    fn the_relative_table_peaks_at_one_across_the_allowed_range() {
        for kelvin in [TEMPERATURE_MIN, 1900.0, 6500.0, TEMPERATURE_MAX] {
            let table = relative_on_grid(kelvin);
            let peak = table.iter().fold(0.0f64, |m, &v| m.max(v));
            assert_eq!(peak, 1.0, "{kelvin} K");
            assert!(table.iter().all(|v| v.is_finite() && *v > 0.0), "{kelvin} K");
        }
    }
}
