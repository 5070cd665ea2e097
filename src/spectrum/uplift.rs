//! RGB → spectrum: Smits' decomposition (Smits 1999, "An RGB-to-Spectrum
//! Conversion for Reflectances", Journal of Graphics Tools 4(4)) with basis
//! spectra fitted so that spectra multiply as RGB does.
//!
//! Smits writes an RGB colour as a non-negative combination of a white, one
//! secondary (cyan, magenta or yellow) and one primary (red, green or blue)
//! basis spectrum, chosen by the order of the channels. Why this rather
//! than Jakob & Hanika 2019's sigmoid polynomials:
//! - the map is *linear* within each channel ordering and adds white
//!   exactly (S(a·c + b·white) = a·S(c) + b for a, b ≥ 0), so uplifting a
//!   BSDF value (albedo/π, a Schlick-tinted microfacet term, a tinted
//!   Fresnel weight) gives exactly the BSDF of the uplifted albedo: the
//!   materials keep returning RGB and the path tracer uplifts their values;
//! - for reflectances in [0, 1] the spectra stay in [0, 1], and one set of
//!   tables serves emission too, because the film's white is the constant
//!   spectrum (see [`super::sensor`]).
//!
//! **Which basis.** Linearity also says what decides how far a spectral
//! render strays from an RGB one. The product of two uplifted colours is a
//! sum of products of basis spectra, so the RGB of *every* such product
//! equals the product of the RGBs exactly when the basis has RGB's
//! multiplication table: RGB(Sᵢ·Sⱼ) = tᵢ∘tⱼ, with tᵢ the RGB basis i
//! stands for (red (1, 0, 0), cyan (0, 1, 1), …). Spectra in [0, 1] cannot
//! meet it exactly: RGB(S²) = RGB(S) forces S to be 0 or 1 everywhere,
//! and since the matching functions overlap no such box has an RGB of
//! exactly (1, 0, 0). Smits' table, fitted for other goals, misses it by
//! 0.062 RMS over the 21 pairs (after the round-trip correction below): a
//! warm light on the Cornell box's red wall then keeps 5% of its RGB
//! product's blue, and the image's blue mean loses 3.5%. So the basis here
//! is fitted, from Smits' table as a start, to minimise that defect subject
//! to an exact round trip and to staying in [0, 1]
//! (`benches/spectral/fit_uplift_basis.py`, exact integrals, tables in
//! [`fitted_basis`]); it reaches 0.013. The
//! spectra come out as near-boxes with a few narrow features where the
//! round trip needs them.
//!
//! Each table is printed to six digits; adding the combination of x̄, ȳ, z̄
//! that makes its RGB *exactly* the target under this film's [`Sensor`]
//! removes that rounding, so every RGB round-trips exactly (to the f64
//! rounding of the grid integrals). The same correction applied to Smits'
//! own table ([`Basis::smits`]) is what the tests compare against.

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

/// Six coloured basis spectra on the spectral grid, corrected to this film.
#[derive(Clone, Debug)]
pub struct Basis {
    /// Cyan, magenta, yellow, red, green, blue.
    pub tables: [[f64; GRID_POINTS]; 6],
}

impl Basis {
    /// The fitted basis the renderer uses, built on first use.
    pub fn get() -> &'static Basis {
        static BASIS: OnceLock<Basis> = OnceLock::new();
        BASIS.get_or_init(|| Basis {
            tables: std::array::from_fn(|k| corrected(&fitted_basis::FITTED_BASIS[k], TARGETS[k])),
        })
    }

    /// Smits' own table, corrected to round-trip on this film in the same
    /// way: the starting point of the fit, kept to measure what it gained.
    pub fn smits() -> Basis {
        Basis {
            tables: std::array::from_fn(|k| corrected(&smits_on_grid(k), TARGETS[k])),
        }
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
/// (a corrected [`Basis`], or Smits' raw table to measure what the correction does).
pub fn spectrum_table_of_rgb(rgb: Color, tables: &[[f64; GRID_POINTS]; 6]) -> [f64; GRID_POINTS] {
    let (white, pairs) = smits_weights(rgb);
    std::array::from_fn(|i| white + pairs.iter().map(|&(k, w)| w * tables[k][i]).sum::<f64>())
}

mod fitted_basis;

#[cfg(test)]
mod tests;
