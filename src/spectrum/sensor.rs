//! The film's colour sensor: spectral radiance to CIE XYZ to linear sRGB.
//!
//! XYZ is ∫ L(λ) (x̄, ȳ, z̄)(λ) dλ / ∫ ȳ dλ, so a constant spectrum 1 has
//! Y = 1. Linear sRGB is the IEC 61966-2-1 matrix applied to XYZ, followed by
//! a per-channel scale chosen so that the constant spectrum 1 (the
//! equal-energy white E) maps to RGB (1, 1, 1): Prism's RGB inputs mean
//! "relative to the film's white", and an RGB-white light must stay white
//! (a von Kries-style white balance from E to the sRGB white D65, done in
//! the sRGB primaries).

use super::cie::{GRID_POINTS, grid_integral, matching_table};
use crate::color::Color;
use glam::{DMat3, DVec3};
use std::sync::OnceLock;

/// XYZ (D65-referred) to linear sRGB, IEC 61966-2-1:1999 §5.2 (rows are R, G, B).
pub const XYZ_TO_SRGB: DMat3 = DMat3::from_cols_array(&[
    3.2406, -0.9689, 0.0557, //
    -1.5372, 1.8758, -0.2040, //
    -0.4986, 0.0415, 1.0570,
]);

/// Linear sRGB to XYZ, IEC 61966-2-1:1999 §5.3 (the inverse of [`XYZ_TO_SRGB`]
/// to the standard's four digits).
pub const SRGB_TO_XYZ: DMat3 = DMat3::from_cols_array(&[
    0.4124, 0.2126, 0.0193, //
    0.3576, 0.7152, 0.1192, //
    0.1805, 0.0722, 0.9505,
]);

/// The sRGB white point D65 in CIE xy chromaticity (IEC 61966-2-1).
pub const D65_CHROMATICITY: [f64; 2] = [0.3127, 0.3290];

/// The conversions the film uses, computed once from the CIE table.
#[derive(Clone, Debug)]
pub struct Sensor {
    /// 1 / ∫ ȳ dλ over 360–830 nm.
    pub inverse_y_integral: f64,
    /// XYZ to white-balanced linear RGB: the sRGB matrix, then the diagonal
    /// that maps E to (1, 1, 1).
    pub xyz_to_rgb: DMat3,
}

impl Sensor {
    /// The sensor, built on first use.
    pub fn get() -> &'static Sensor {
        static SENSOR: OnceLock<Sensor> = OnceLock::new();
        SENSOR.get_or_init(Sensor::build)
    }

    fn build() -> Self {
        let ones = [1.0; GRID_POINTS];
        let y_integral = grid_integral(&matching_table(1), &ones);
        let e_xyz = DVec3::from_array(std::array::from_fn(|c| grid_integral(&matching_table(c), &ones))) / y_integral;
        let e_rgb = XYZ_TO_SRGB * e_xyz;
        let balance = DMat3::from_diagonal(DVec3::ONE / e_rgb);
        Self {
            inverse_y_integral: 1.0 / y_integral,
            xyz_to_rgb: balance * XYZ_TO_SRGB,
        }
    }

    /// White-balanced linear RGB of an XYZ value.
    #[inline]
    pub fn rgb(&self, xyz: DVec3) -> Color {
        self.xyz_to_rgb * xyz
    }

    /// XYZ of a spectrum given as a grid table (exact for a piecewise-linear spectrum).
    pub fn xyz_of_table(&self, spectrum: &[f64; GRID_POINTS]) -> DVec3 {
        DVec3::from_array(std::array::from_fn(|c| grid_integral(&matching_table(c), spectrum))) * self.inverse_y_integral
    }

    /// RGB of a spectrum given as a grid table.
    pub fn rgb_of_table(&self, spectrum: &[f64; GRID_POINTS]) -> Color {
        self.rgb(self.xyz_of_table(spectrum))
    }
}

/// CIE xy chromaticity of a white-balanced linear RGB colour, as the film
/// reports it (through [`SRGB_TO_XYZ`], so RGB (1, 1, 1) is D65).
pub fn chromaticity(rgb: Color) -> [f64; 2] {
    let xyz = SRGB_TO_XYZ * rgb;
    let sum = xyz.x + xyz.y + xyz.z;
    [xyz.x / sum, xyz.y / sum]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_equal_energy_spectrum_is_the_films_white() {
        let sensor = Sensor::get();
        let rgb = sensor.rgb_of_table(&[1.0; GRID_POINTS]);
        assert!((rgb - Color::ONE).abs().max_element() < 1e-12, "{rgb}");
        // (1, 1, 1) sits at D65 to the four digits of the standard's matrices.
        let [x, y] = chromaticity(Color::ONE);
        assert!(
            (x - D65_CHROMATICITY[0]).abs() < 1e-4 && (y - D65_CHROMATICITY[1]).abs() < 1e-4,
            "{x} {y}"
        );
    }

    #[test]
    fn the_two_matrices_are_inverses() {
        // To the standard's four printed digits: residuals below 1e-3.
        let product = XYZ_TO_SRGB * SRGB_TO_XYZ;
        let error = (product - DMat3::IDENTITY)
            .to_cols_array()
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(error < 1e-3, "{error}");
    }
}
