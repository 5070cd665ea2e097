//! The CIE standard illuminants D65 (average daylight) and A (incandescent
//! light), as relative spectral power distributions on the spectral grid.
//!
//! Provenance: CIE 015:2018 "Colorimetry", 4th edition, and ISO/CIE
//! 11664-2:2022 ("CIE standard illuminants"). D65 is defined by its table
//! (tabulated in CIE 015:2018 over 300–830 nm at 5 nm; the CIE's 1 nm
//! dataset, doi:10.25039/CIE.DS.hjfjmt59, has the same values at the 5 nm
//! points);
//! here its 360–830 nm part, normalised as published to 100 at 560 nm. A is
//! defined by a formula, Planck's law at 2848 K with the second radiation
//! constant c₂ = 1.435·10⁻² m·K the standard keeps for A: with today's c₂ =
//! 1.438 777·10⁻² m·K that is a blackbody at 2856 K (the colour temperature
//! A is known by).

use super::cie::{GRID_POINTS, GRID_START, GRID_STEP};

/// A CIE standard illuminant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StandardIlluminant {
    /// Average daylight, correlated colour temperature about 6504 K.
    D65,
    /// Incandescent (tungsten) light, a 2856 K blackbody.
    A,
}

impl StandardIlluminant {
    /// Every illuminant with the name a scene file uses for it.
    pub const NAMED: [(&'static str, StandardIlluminant); 2] = [("D65", StandardIlluminant::D65), ("A", StandardIlluminant::A)];

    /// The illuminant a scene file names (`"D65"`, `"A"`), if any.
    pub fn named(name: &str) -> Option<Self> {
        Self::NAMED.iter().find(|(n, _)| *n == name).map(|(_, i)| *i)
    }

    /// Its relative spectral power at every grid point (100 at 560 nm).
    pub fn on_grid(self) -> [f64; GRID_POINTS] {
        match self {
            StandardIlluminant::D65 => CIE_D65,
            StandardIlluminant::A => std::array::from_fn(|i| illuminant_a(GRID_START + GRID_STEP * i as f64)),
        }
    }
}

/// Illuminant A's defining formula (CIE 015:2018; ISO/CIE 11664-2):
/// S_A(λ) = 100 (560/λ)⁵ (e^{c₂/(2848·560 nm)} − 1) / (e^{c₂/(2848·λ)} − 1),
/// c₂ = 1.435·10⁷ nm·K; 100 at 560 nm.
pub fn illuminant_a(lambda_nm: f64) -> f64 {
    const C2_NM_K: f64 = 1.435e7;
    const TEMPERATURE: f64 = 2848.0;
    let planck = |lambda: f64| (C2_NM_K / (TEMPERATURE * lambda)).exp_m1();
    100.0 * (560.0 / lambda_nm).powi(5) * planck(560.0) / planck(lambda_nm)
}

/// CIE standard illuminant D65 at 360, 365, …, 830 nm (CIE 015:2018).
#[rustfmt::skip]
pub const CIE_D65: [f64; GRID_POINTS] = [
    46.6383, 49.3637, 52.0891, 51.0323, // 360–375
    49.9755, 52.3118, 54.6482, 68.7015, 82.7549, 87.1204, 91.4860, 92.4589, // 380–415
    93.4318, 90.0570, 86.6823, 95.7736, 104.865, 110.936, 117.008, 117.410, // 420–455
    117.812, 116.336, 114.861, 115.392, 115.923, 112.367, 108.811, 109.082, // 460–495
    109.354, 108.578, 107.802, 106.296, 104.790, 106.239, 107.689, 106.047, // 500–535
    104.405, 104.225, 104.046, 102.023, 100.000, 98.1671, 96.3342, 96.0611, // 540–575
    95.7880, 92.2368, 88.6856, 89.3459, 90.0062, 89.8026, 89.5991, 88.6489, // 580–615
    87.6987, 85.4936, 83.2886, 83.4939, 83.6992, 81.8630, 80.0268, 80.1207, // 620–655
    80.2146, 81.2462, 82.2778, 80.2810, 78.2842, 74.0027, 69.7213, 70.6652, // 660–695
    71.6091, 72.9790, 74.3490, 67.9765, 61.6040, 65.7448, 69.8856, 72.4863, // 700–735
    75.0870, 69.3398, 63.5927, 55.0054, 46.4182, 56.6118, 66.8054, 65.0941, // 740–775
    63.3828, 63.8434, 64.3040, 61.8779, 59.4519, 55.7054, 51.9590, 54.6998, // 780–815
    57.4406, 58.8765, 60.3125, // 820–830
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::sensor::Sensor;

    fn xy(spectrum: &[f64; GRID_POINTS]) -> [f64; 2] {
        let xyz = Sensor::get().xyz_of_table(spectrum);
        let sum = xyz.x + xyz.y + xyz.z;
        [xyz.x / sum, xyz.y / sum]
    }

    #[test]
    fn names_find_their_illuminants() {
        assert_eq!(StandardIlluminant::named("D65"), Some(StandardIlluminant::D65));
        assert_eq!(StandardIlluminant::named("A"), Some(StandardIlluminant::A));
        assert_eq!(StandardIlluminant::named("d65"), None);
    }

    #[test]
    fn both_are_100_at_560_nm() {
        // The normalisation both definitions share (grid point 40 is 560 nm).
        assert_eq!(GRID_START + GRID_STEP * 40.0, 560.0);
        assert_eq!(CIE_D65[40], 100.0);
        assert!((StandardIlluminant::A.on_grid()[40] - 100.0).abs() < 1e-12);
    }

    #[test]
    fn illuminant_a_has_its_published_values() {
        // CIE 015:2018 tabulates A to six significant digits; the formula
        // must give them to within half a unit of the last printed digit.
        for (lambda, published, half_unit) in [
            (380.0, 9.7951, 5e-5),
            (500.0, 59.8611, 5e-5),
            (600.0, 129.043, 5e-4),
            (780.0, 241.675, 5e-4),
        ] {
            let value = illuminant_a(lambda);
            assert!((value - published).abs() <= half_unit, "{lambda} nm: {value}");
        }
    }

    /// The chromaticities the CIE gives the two illuminants for the 1931
    /// observer, D65 (0.3127, 0.3290) and A (0.4476, 0.4074) (CIE 015:2018:
    /// 0.31272, 0.32903 and 0.44758, 0.40745), computed here
    /// through the 5 nm CIE table the film uses. The tolerance 5·10⁻⁴ allows
    /// for this film's 360–830 nm range and its linear interpolation between
    /// grid points (the CIE sums at 1 nm); a just-noticeable chromaticity
    /// difference is several times larger.
    #[test]
    fn the_chromaticities_are_the_standards() {
        for (illuminant, expected) in [
            (StandardIlluminant::D65, [0.3127, 0.3290]),
            (StandardIlluminant::A, [0.4476, 0.4074]),
        ] {
            let [x, y] = xy(&illuminant.on_grid());
            eprintln!("{illuminant:?}: ({x:.5}, {y:.5})");
            assert!(
                (x - expected[0]).abs() < 5e-4 && (y - expected[1]).abs() < 5e-4,
                "{illuminant:?}: ({x}, {y}) against {expected:?}"
            );
        }
    }
}
