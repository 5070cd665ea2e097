//! What a light emits, in both of the forms a path may carry: the film's
//! RGB, and radiance at a path's sampled wavelengths.
//!
//! An RGB emitter's spectrum is its uplift (see [`super::uplift`]). A
//! spectral emitter (a named illuminant or a blackbody) has its own
//! spectrum, tabulated on the 5 nm grid and scaled to a luminance, and its
//! RGB is that spectrum seen through the film's [`Sensor`], computed once
//! when the scene loads. Both forms have the same expectation: the spectral
//! estimator (1/N) Σ L(λᵢ) x̄(λᵢ)/p(λᵢ) of a piecewise-linear L is, on
//! average, exactly the grid integral the RGB is made of. So an RGB render
//! (path tracing or SPPM) shows a spectral emitter in the mean as a
//! spectral render does; only what it lights through coloured surfaces
//! differs, as products of spectra differ from products of RGBs.
//!
//! Every place emission enters a path goes through [`Emission`] and
//! [`Radiance::emission`](super::Radiance::emission).

use super::blackbody;
use super::cie::GRID_POINTS;
use super::illuminant::StandardIlluminant;
use super::sensor::Sensor;
use super::uplift::spectrum_of_rgb;
use super::{SampledSpectrum, SampledWavelengths};
use crate::color::Color;

/// Where an emitter's spectrum comes from, before scaling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpectrumSource {
    /// A CIE standard illuminant.
    Illuminant(StandardIlluminant),
    /// A blackbody at this temperature, kelvin (Planck's law).
    Blackbody {
        /// Temperature, kelvin.
        kelvin: f64,
    },
}

impl SpectrumSource {
    /// Its relative spectral power at every grid point.
    fn on_grid(self) -> [f64; GRID_POINTS] {
        match self {
            SpectrumSource::Illuminant(illuminant) => illuminant.on_grid(),
            SpectrumSource::Blackbody { kelvin } => blackbody::relative_on_grid(kelvin),
        }
    }
}

/// An emitter's spectral radiance: a [`SpectrumSource`] scaled so that its CIE Y is
/// `luminance` times that of the constant spectrum 1 (the film's white),
/// i.e. as bright, photometrically, as the RGB emitter
/// `radiance = [luminance; 3]`.
#[derive(Clone, PartialEq)]
pub struct EmissionSpectrum {
    source: SpectrumSource,
    luminance: f64,
    /// Radiance at every grid point, linear in between.
    table: [f64; GRID_POINTS],
    /// The film's RGB of `table`.
    rgb: Color,
}

impl EmissionSpectrum {
    /// `source` scaled to `luminance` (≥ 0, finite: the scene loader checks).
    pub fn new(source: SpectrumSource, luminance: f64) -> Self {
        let sensor = Sensor::get();
        let relative = source.on_grid();
        let y = sensor.xyz_of_table(&relative).y;
        let table = relative.map(|v| v * (luminance / y));
        Self {
            source,
            luminance,
            rgb: sensor.rgb_of_table(&table),
            table,
        }
    }

    /// What it was made from.
    pub fn source(&self) -> SpectrumSource {
        self.source
    }

    /// Its CIE Y relative to the film's white.
    pub fn luminance(&self) -> f64 {
        self.luminance
    }

    /// Spectral radiance at every grid point.
    pub fn table(&self) -> &[f64; GRID_POINTS] {
        &self.table
    }

    /// The film's linear RGB of this spectrum: what an RGB render emits.
    pub fn rgb(&self) -> Color {
        self.rgb
    }

    /// Radiance at a path's wavelengths.
    #[inline]
    pub fn sample(&self, wavelengths: &SampledWavelengths) -> SampledSpectrum {
        SampledSpectrum::from_array(wavelengths.grid.map(|p| p.read(&self.table)))
    }
}

/// The source and scale say everything; the table would fill a screen.
impl std::fmt::Debug for EmissionSpectrum {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EmissionSpectrum")
            .field("source", &self.source)
            .field("luminance", &self.luminance)
            .finish()
    }
}

/// Emitted radiance as a path meets it: the film RGB, and the spectrum for
/// a spectral emitter (`None`: the RGB's uplift).
#[derive(Clone, Copy, Debug)]
pub struct Emission<'a> {
    /// The film's linear RGB (for a spectral emitter, its spectrum's).
    pub rgb: Color,
    /// The emitter's own spectrum, if it has one.
    pub spectrum: Option<&'a EmissionSpectrum>,
}

impl Emission<'_> {
    /// No light.
    pub const NONE: Emission<'static> = Emission {
        rgb: Color::ZERO,
        spectrum: None,
    };

    /// Radiance at a path's wavelengths.
    #[inline]
    pub fn sample(&self, wavelengths: &SampledWavelengths) -> SampledSpectrum {
        match self.spectrum {
            Some(spectrum) => spectrum.sample(wavelengths),
            None => spectrum_of_rgb(self.rgb, wavelengths),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::Radiance;

    #[test]
    fn the_luminance_is_the_cie_y_of_the_spectrum() {
        let sensor = Sensor::get();
        for source in [
            SpectrumSource::Illuminant(StandardIlluminant::D65),
            SpectrumSource::Illuminant(StandardIlluminant::A),
            SpectrumSource::Blackbody { kelvin: 1900.0 },
        ] {
            let spectrum = EmissionSpectrum::new(source, 7.5);
            let y = sensor.xyz_of_table(spectrum.table()).y;
            assert!((y - 7.5).abs() < 1e-12, "{source:?}: Y {y}");
        }
    }

    /// The RGB an RGB render uses is the mean of what a spectral render
    /// gets: sweeping the hero wavelength over the range (4000 points a
    /// quarter, a quadrature of the estimator's expectation) reproduces it.
    /// The quadrature of a piecewise-linear product is exact to about 10⁻⁷
    /// of the largest channel at this resolution; 10⁻⁵ is the bound.
    #[test]
    fn the_spectral_estimate_averages_to_the_rgb() {
        let n = 4000;
        for source in [
            SpectrumSource::Illuminant(StandardIlluminant::D65),
            SpectrumSource::Illuminant(StandardIlluminant::A),
            SpectrumSource::Blackbody { kelvin: 1900.0 },
        ] {
            let spectrum = EmissionSpectrum::new(source, 3.0);
            let emission = Emission {
                rgb: spectrum.rgb(),
                spectrum: Some(&spectrum),
            };
            let mean = (0..n)
                .map(|k| {
                    let wavelengths = SampledWavelengths::sample_uniform((k as f64 + 0.5) / n as f64);
                    SampledSpectrum::emission(emission, &wavelengths).to_rgb(&wavelengths)
                })
                .sum::<Color>()
                / n as f64;
            let error = (mean - spectrum.rgb()).abs().max_element() / spectrum.rgb().max_element();
            eprintln!("{source:?}: RGB {} spectral mean {mean}", spectrum.rgb());
            assert!(error < 1e-5, "{source:?}: {mean} against {}", spectrum.rgb());
        }
    }

    #[test]
    fn an_rgb_emission_is_its_uplift() {
        let rgb = Color::new(17.0, 12.0, 4.0);
        let wavelengths = SampledWavelengths::sample_uniform(0.37);
        let emission = Emission { rgb, spectrum: None };
        assert_eq!(emission.sample(&wavelengths), spectrum_of_rgb(rgb, &wavelengths));
        assert_eq!(Color::emission(emission, &()), rgb);
    }
}
