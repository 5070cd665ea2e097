//! RGB → spectrum: Smits 1999, "An RGB-to-Spectrum Conversion for
//! Reflectances" (Journal of Graphics Tools 4(4)).
//!
//! Smits writes an RGB colour as a non-negative combination of a white, one
//! secondary (cyan, magenta or yellow) and one primary (red, green or blue)
//! basis spectrum, chosen by the order of the channels. Why Smits rather
//! than Jakob & Hanika 2019's sigmoid polynomials:
//! - the map is *linear* within each channel ordering and adds white
//!   exactly (S(a·c + b·white) = a·S(c) + b for a, b ≥ 0), so uplifting a
//!   BSDF value (albedo/π, a Schlick-tinted microfacet term, a tinted
//!   Fresnel weight) gives exactly the BSDF of the uplifted albedo: the
//!   materials keep returning RGB and the path tracer uplifts their values;
//! - it needs seven small tables rather than a 3 × 64³ coefficient table
//!   fitted by an optimiser;
//! - for reflectances in [0, 1] the spectra stay in [0, 1] up to the small
//!   correction below, and one set of tables serves emission too, because
//!   the film's white is the constant spectrum (see [`super::sensor`]).
//!   Jakob & Hanika fit spectra that are smoother and bounded by
//!   construction; Smits' are only piecewise smooth, which nothing here
//!   needs.
//!
//! Smits' basis spectra (his table 1, ten bins over 380–720 nm) were fitted
//! to other matching functions and a different white; here each is linearly
//! interpolated between bin centres, extended flat to 360–830 nm, and then
//! corrected by adding the combination of x̄, ȳ, z̄ that makes its RGB
//! *exactly* the target (1 for its channels, 0 for the others) under this
//! film's [`Sensor`]. Since the map is linear per ordering, every RGB then
//! round-trips exactly (to the f64 rounding of the grid integrals); the
//! test below prints the error before and after the correction.

use super::cie::{GRID_POINTS, GRID_START, GRID_STEP, matching_table};
use super::sensor::Sensor;
use super::{SampledSpectrum, SampledWavelengths};
use crate::color::Color;
use glam::{DMat3, DVec3};
use std::sync::OnceLock;

/// Smits 1999, table 1: cyan, magenta, yellow, red, green, blue at the
/// centres of ten equal bins over 380–720 nm (white is exactly 1 here).
#[rustfmt::skip]
const SMITS_1999: [[f64; 10]; 6] = [
    [0.9710, 0.9426, 1.0007, 1.0007, 1.0007, 1.0007, 0.1564, 0.0000, 0.0000, 0.0000],
    [1.0000, 1.0000, 0.9685, 0.2229, 0.0000, 0.0458, 0.8369, 1.0000, 1.0000, 0.9959],
    [0.0001, 0.0000, 0.1088, 0.6651, 1.0000, 1.0000, 0.9996, 0.9586, 0.9685, 0.9840],
    [0.1012, 0.0515, 0.0000, 0.0000, 0.0000, 0.0000, 0.8325, 1.0149, 1.0149, 1.0149],
    [0.0000, 0.0000, 0.0273, 0.7937, 1.0000, 0.9418, 0.1719, 0.0000, 0.0000, 0.0025],
    [1.0000, 1.0000, 0.8916, 0.3323, 0.0000, 0.0000, 0.0003, 0.0369, 0.0483, 0.0496],
];

/// The RGB each basis spectrum must have.
const TARGETS: [[f64; 3]; 6] = [
    [0.0, 1.0, 1.0],
    [1.0, 0.0, 1.0],
    [1.0, 1.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];

/// Index of each basis in [`Basis::tables`].
const CYAN: usize = 0;
const MAGENTA: usize = 1;
const YELLOW: usize = 2;
const RED: usize = 3;
const GREEN: usize = 4;
const BLUE: usize = 5;

/// The six coloured basis spectra on the spectral grid, corrected to this film.
#[derive(Clone, Debug)]
pub struct Basis {
    /// Cyan, magenta, yellow, red, green, blue.
    pub tables: [[f64; GRID_POINTS]; 6],
}

impl Basis {
    /// The corrected basis, built on first use.
    pub fn get() -> &'static Basis {
        static BASIS: OnceLock<Basis> = OnceLock::new();
        BASIS.get_or_init(|| Basis {
            tables: std::array::from_fn(|k| corrected(&smits_on_grid(k), TARGETS[k])),
        })
    }
}

/// Smits' basis `k` on the grid: linear between his bin centres, flat beyond.
pub fn smits_on_grid(k: usize) -> [f64; GRID_POINTS] {
    let (first_centre, bin) = (380.0 + 17.0, 34.0);
    std::array::from_fn(|i| {
        let lambda = GRID_START + GRID_STEP * i as f64;
        let x = ((lambda - first_centre) / bin).clamp(0.0, 9.0);
        let j = (x as usize).min(8);
        let t = x - j as f64;
        SMITS_1999[k][j] * (1.0 - t) + SMITS_1999[k][j + 1] * t
    })
}

/// `spectrum` plus the combination of x̄, ȳ, z̄ that gives it RGB `target`.
fn corrected(spectrum: &[f64; GRID_POINTS], target: [f64; 3]) -> [f64; GRID_POINTS] {
    let sensor = Sensor::get();
    let matching: [[f64; GRID_POINTS]; 3] = std::array::from_fn(matching_table);
    // Column c of `response` is the RGB of matching function c.
    let response = DMat3::from_cols_array_2d(&matching.map(|m| sensor.rgb_of_table(&m).to_array()));
    let coefficients = response.inverse() * (DVec3::from(target) - sensor.rgb_of_table(spectrum));
    std::array::from_fn(|i| {
        spectrum[i] + coefficients.x * matching[0][i] + coefficients.y * matching[1][i] + coefficients.z * matching[2][i]
    })
}

/// Smits' decomposition of `rgb`: the white weight and two (basis, weight)
/// pairs, all weights non-negative for non-negative input.
#[inline]
pub fn smits_weights(rgb: Color) -> (f64, [(usize, f64); 2]) {
    let (r, g, b) = (rgb.x, rgb.y, rgb.z);
    if r <= g && r <= b {
        if g <= b {
            (r, [(CYAN, g - r), (BLUE, b - g)])
        } else {
            (r, [(CYAN, b - r), (GREEN, g - b)])
        }
    } else if g <= r && g <= b {
        if r <= b {
            (g, [(MAGENTA, r - g), (BLUE, b - r)])
        } else {
            (g, [(MAGENTA, b - g), (RED, r - b)])
        }
    } else if r <= g {
        (b, [(YELLOW, r - b), (GREEN, g - r)])
    } else {
        (b, [(YELLOW, g - b), (RED, r - g)])
    }
}

/// The spectrum of an RGB colour at the sampled wavelengths. Exact in RGB:
/// the film sees `rgb` again. A grey is a constant spectrum, read from no table.
#[inline]
pub fn spectrum_of_rgb(rgb: Color, wavelengths: &SampledWavelengths) -> SampledSpectrum {
    let (white, [(k1, w1), (k2, w2)]) = smits_weights(rgb);
    let mut spectrum = SampledSpectrum::splat(white);
    let tables = &Basis::get().tables;
    for (k, w) in [(k1, w1), (k2, w2)] {
        if w != 0.0 {
            spectrum += SampledSpectrum::from_array(wavelengths.grid.map(|p| p.read(&tables[k]))) * w;
        }
    }
    spectrum
}

/// The same spectrum as a whole grid table, from the given basis tables
/// (the corrected [`Basis`], or Smits' own to measure what the correction does).
pub fn spectrum_table_of_rgb(rgb: Color, tables: &[[f64; GRID_POINTS]; 6]) -> [f64; GRID_POINTS] {
    let (white, pairs) = smits_weights(rgb);
    std::array::from_fn(|i| white + pairs.iter().map(|&(k, w)| w * tables[k][i]).sum::<f64>())
}

#[cfg(test)]
mod tests;
