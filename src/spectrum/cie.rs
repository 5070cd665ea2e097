//! The CIE 1931 2° standard observer's colour-matching functions x̄, ȳ, z̄,
//! tabulated every 5 nm from 360 to 830 nm, and their use as piecewise-linear
//! functions of wavelength.
//!
//! Provenance: CIE 018:2019 / ISO 11664-1:2019 ("CIE colorimetry — Part 1:
//! CIE standard colorimetric observers"), the 1931 2° observer as published
//! by the CIE and mirrored by the Colour & Vision Research Laboratory
//! (cvrl.org, `ciexyz31.csv`, 5 nm rows). Values are copied as published,
//! including their odd trailing digits (e.g. 0.006450001).
//!
//! Every spectral quantity in Prism (these functions, the RGB basis spectra,
//! the illuminant D65) is piecewise linear on the same 5 nm grid, so the
//! integral of a product of two of them is computed exactly
//! ([`grid_integral`]), and a Monte Carlo estimate over uniformly sampled
//! wavelengths has exactly that integral as its expectation.

use glam::DVec3;

/// First wavelength of the grid, nanometres.
pub const GRID_START: f64 = 360.0;
/// Grid spacing, nanometres.
pub const GRID_STEP: f64 = 5.0;
/// Points on the grid: 360, 365, …, 830 nm.
pub const GRID_POINTS: usize = 95;

/// x̄, ȳ, z̄ at 360 + 5i nm (CIE 018:2019, see the module doc).
#[rustfmt::skip]
pub const CIE_1931_2DEG: [[f64; 3]; GRID_POINTS] = [
    [0.000129900000, 0.000003917000, 0.000606100000],
    [0.000232100000, 0.000006965000, 0.001086000000],
    [0.000414900000, 0.000012390000, 0.001946000000],
    [0.000741600000, 0.000022020000, 0.003486000000],
    [0.001368000000, 0.000039000000, 0.006450001000],
    [0.002236000000, 0.000064000000, 0.010549990000],
    [0.004243000000, 0.000120000000, 0.020050010000],
    [0.007650000000, 0.000217000000, 0.036210000000],
    [0.014310000000, 0.000396000000, 0.067850010000],
    [0.023190000000, 0.000640000000, 0.110200000000],
    [0.043510000000, 0.001210000000, 0.207400000000],
    [0.077630000000, 0.002180000000, 0.371300000000],
    [0.134380000000, 0.004000000000, 0.645600000000],
    [0.214770000000, 0.007300000000, 1.039050100000],
    [0.283900000000, 0.011600000000, 1.385600000000],
    [0.328500000000, 0.016840000000, 1.622960000000],
    [0.348280000000, 0.023000000000, 1.747060000000],
    [0.348060000000, 0.029800000000, 1.782600000000],
    [0.336200000000, 0.038000000000, 1.772110000000],
    [0.318700000000, 0.048000000000, 1.744100000000],
    [0.290800000000, 0.060000000000, 1.669200000000],
    [0.251100000000, 0.073900000000, 1.528100000000],
    [0.195360000000, 0.090980000000, 1.287640000000],
    [0.142100000000, 0.112600000000, 1.041900000000],
    [0.095640000000, 0.139020000000, 0.812950100000],
    [0.057950010000, 0.169300000000, 0.616200000000],
    [0.032010000000, 0.208020000000, 0.465180000000],
    [0.014700000000, 0.258600000000, 0.353300000000],
    [0.004900000000, 0.323000000000, 0.272000000000],
    [0.002400000000, 0.407300000000, 0.212300000000],
    [0.009300000000, 0.503000000000, 0.158200000000],
    [0.029100000000, 0.608200000000, 0.111700000000],
    [0.063270000000, 0.710000000000, 0.078249990000],
    [0.109600000000, 0.793200000000, 0.057250010000],
    [0.165500000000, 0.862000000000, 0.042160000000],
    [0.225749900000, 0.914850100000, 0.029840000000],
    [0.290400000000, 0.954000000000, 0.020300000000],
    [0.359700000000, 0.980300000000, 0.013400000000],
    [0.433449900000, 0.994950100000, 0.008749999000],
    [0.512050100000, 1.000000000000, 0.005749999000],
    [0.594500000000, 0.995000000000, 0.003900000000],
    [0.678400000000, 0.978600000000, 0.002749999000],
    [0.762100000000, 0.952000000000, 0.002100000000],
    [0.842500000000, 0.915400000000, 0.001800000000],
    [0.916300000000, 0.870000000000, 0.001650001000],
    [0.978600000000, 0.816300000000, 0.001400000000],
    [1.026300000000, 0.757000000000, 0.001100000000],
    [1.056700000000, 0.694900000000, 0.001000000000],
    [1.062200000000, 0.631000000000, 0.000800000000],
    [1.045600000000, 0.566800000000, 0.000600000000],
    [1.002600000000, 0.503000000000, 0.000340000000],
    [0.938400000000, 0.441200000000, 0.000240000000],
    [0.854449900000, 0.381000000000, 0.000190000000],
    [0.751400000000, 0.321000000000, 0.000100000000],
    [0.642400000000, 0.265000000000, 0.000049999990],
    [0.541900000000, 0.217000000000, 0.000030000000],
    [0.447900000000, 0.175000000000, 0.000020000000],
    [0.360800000000, 0.138200000000, 0.000010000000],
    [0.283500000000, 0.107000000000, 0.000000000000],
    [0.218700000000, 0.081600000000, 0.000000000000],
    [0.164900000000, 0.061000000000, 0.000000000000],
    [0.121200000000, 0.044580000000, 0.000000000000],
    [0.087400000000, 0.032000000000, 0.000000000000],
    [0.063600000000, 0.023200000000, 0.000000000000],
    [0.046770000000, 0.017000000000, 0.000000000000],
    [0.032900000000, 0.011920000000, 0.000000000000],
    [0.022700000000, 0.008210000000, 0.000000000000],
    [0.015840000000, 0.005723000000, 0.000000000000],
    [0.011359160000, 0.004102000000, 0.000000000000],
    [0.008110916000, 0.002929000000, 0.000000000000],
    [0.005790346000, 0.002091000000, 0.000000000000],
    [0.004109457000, 0.001484000000, 0.000000000000],
    [0.002899327000, 0.001047000000, 0.000000000000],
    [0.002049190000, 0.000740000000, 0.000000000000],
    [0.001439971000, 0.000520000000, 0.000000000000],
    [0.000999949300, 0.000361100000, 0.000000000000],
    [0.000690078600, 0.000249200000, 0.000000000000],
    [0.000476021300, 0.000171900000, 0.000000000000],
    [0.000332301100, 0.000120000000, 0.000000000000],
    [0.000234826100, 0.000084800000, 0.000000000000],
    [0.000166150500, 0.000060000000, 0.000000000000],
    [0.000117413000, 0.000042400000, 0.000000000000],
    [0.000083075270, 0.000030000000, 0.000000000000],
    [0.000058706520, 0.000021200000, 0.000000000000],
    [0.000041509940, 0.000014990000, 0.000000000000],
    [0.000029353260, 0.000010600000, 0.000000000000],
    [0.000020673830, 0.000007465700, 0.000000000000],
    [0.000014559770, 0.000005257800, 0.000000000000],
    [0.000010253980, 0.000003702900, 0.000000000000],
    [0.000007221456, 0.000002607800, 0.000000000000],
    [0.000005085868, 0.000001836600, 0.000000000000],
    [0.000003581652, 0.000001293400, 0.000000000000],
    [0.000002522525, 0.000000910930, 0.000000000000],
    [0.000001776509, 0.000000641530, 0.000000000000],
    [0.000001251141, 0.000000451810, 0.000000000000],
];

/// Where a wavelength falls on the grid: the segment's first point and the
/// fraction of the way to the next, so that several tables can be read at
/// one wavelength for the price of one division.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridPosition {
    /// Index of the grid point at or below the wavelength, at most `GRID_POINTS - 2`.
    pub index: usize,
    /// Position within the segment, in [0, 1].
    pub fraction: f64,
}

impl GridPosition {
    /// The position of `lambda_nm`, clamped to the grid's ends.
    #[inline]
    pub fn of(lambda_nm: f64) -> Self {
        let x = ((lambda_nm - GRID_START) / GRID_STEP).clamp(0.0, (GRID_POINTS - 1) as f64);
        let index = (x as usize).min(GRID_POINTS - 2);
        Self {
            index,
            fraction: x - index as f64,
        }
    }

    /// Linear interpolation of `table` (one value per grid point) here.
    #[inline]
    pub fn read(&self, table: &[f64; GRID_POINTS]) -> f64 {
        let (a, b) = (table[self.index], table[self.index + 1]);
        a + (b - a) * self.fraction
    }
}

/// (x̄, ȳ, z̄) at `lambda_nm`, linearly interpolated; zero outside 360–830 nm.
pub fn matching(lambda_nm: f64) -> DVec3 {
    if !(GRID_START..=GRID_START + GRID_STEP * (GRID_POINTS - 1) as f64).contains(&lambda_nm) {
        return DVec3::ZERO;
    }
    let at = GridPosition::of(lambda_nm);
    let (a, b) = (CIE_1931_2DEG[at.index], CIE_1931_2DEG[at.index + 1]);
    DVec3::from(a).lerp(DVec3::from(b), at.fraction)
}

/// One colour-matching function as a grid table (0: x̄, 1: ȳ, 2: z̄).
pub fn matching_table(channel: usize) -> [f64; GRID_POINTS] {
    std::array::from_fn(|i| CIE_1931_2DEG[i][channel])
}

/// ∫ a(λ) b(λ) dλ over 360–830 nm for two functions linear between grid
/// points: exact, segment by segment, ∫₀ʰ (a₀ + Δa t/h)(b₀ + Δb t/h) dt =
/// h (a₀b₀/3 + a₀b₁/6 + a₁b₀/6 + a₁b₁/3).
pub fn grid_integral(a: &[f64; GRID_POINTS], b: &[f64; GRID_POINTS]) -> f64 {
    (0..GRID_POINTS - 1)
        .map(|i| {
            let (a0, a1, b0, b1) = (a[i], a[i + 1], b[i], b[i + 1]);
            GRID_STEP * (a0 * b0 / 3.0 + (a0 * b1 + a1 * b0) / 6.0 + a1 * b1 / 3.0)
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_has_the_published_landmarks() {
        // ȳ peaks at exactly 1 at 555 nm (the photopic luminosity function's
        // definition); x̄'s long-wave peak is 1.0622 at 600 nm.
        assert_eq!(matching(555.0).y, 1.0);
        assert_eq!(matching(600.0).x, 1.0622);
        // Halfway between grid points is the mean of the two.
        assert!((matching(557.5).y - 0.9975).abs() < 1e-12);
        assert_eq!(matching(300.0), DVec3::ZERO);
    }

    #[test]
    fn the_matching_functions_have_equal_areas() {
        // The CIE normalised x̄, ȳ, z̄ so the equal-energy spectrum E has
        // X = Y = Z; on the 5 nm table the three integrals (about 106.86 nm)
        // agree to the table's rounding, well within 0.05%.
        let ones = [1.0; GRID_POINTS];
        let area: Vec<f64> = (0..3).map(|c| grid_integral(&matching_table(c), &ones)).collect();
        assert!((area[0] / area[1] - 1.0).abs() < 5e-4, "{area:?}");
        assert!((area[2] / area[1] - 1.0).abs() < 5e-4, "{area:?}");
        assert!((area[1] - 106.86).abs() < 0.05, "{area:?}");
    }
}
