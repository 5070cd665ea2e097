//! The quantity a path carries, as a type the path tracer is generic over:
//! linear RGB ([`Color`]) or radiance at a path's sampled wavelengths
//! ([`SampledSpectrum`]). The tracer is written once; the choice is made
//! once per render, and the RGB instance compiles to the RGB tracer as it
//! was (its uplift is the identity and it carries no wavelengths).

use super::cie::CIE_1931_2DEG;
use super::emission::Emission;
use super::sensor::Sensor;
use super::uplift::spectrum_of_rgb;
use super::{SampledSpectrum, SampledWavelengths, WAVELENGTHS};
use crate::color::Color;
use crate::material::{BsdfSample, Material, ShadingPoint, Transport};
use crate::sampler::Sampler;
use glam::{DVec2, DVec3};
use std::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign};

/// Salt of the side stream a spectral path draws its wavelengths from.
const WAVELENGTH_STREAM: u64 = 0x5eec_7a1f_a3e1_0000;

/// Radiance, throughput or a BSDF value as a path carries it.
pub trait Radiance:
    Copy
    + PartialEq
    + Add<Output = Self>
    + AddAssign
    + Mul<Output = Self>
    + MulAssign
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + DivAssign<f64>
{
    /// What the path carries besides (its sampled wavelengths, or nothing).
    type Wavelengths: Copy;
    /// No light.
    const ZERO: Self;
    /// Unit throughput.
    const ONE: Self;

    /// An RGB quantity (reflectance, BSDF value, emission) in this form.
    fn from_rgb(rgb: Color, wavelengths: &Self::Wavelengths) -> Self;

    /// Draws what a new path carries besides (its wavelengths) from a side
    /// stream of `sampler`, so the path's own draws are those of an RGB path.
    fn sample_wavelengths(sampler: &Sampler) -> Self::Wavelengths;

    /// Whether the path was narrowed to its hero wavelength (it crossed a
    /// dispersive interface), so its throughput is valid at that λ only.
    fn is_dispersed(wavelengths: &Self::Wavelengths) -> bool;

    /// Emitted radiance in this form: the film RGB, or the emitter's own
    /// spectrum (an RGB emitter's uplift) at the wavelengths. Every place
    /// emission enters a path takes it through here.
    fn emission(emission: Emission<'_>, wavelengths: &Self::Wavelengths) -> Self;

    /// The largest component (for Russian roulette).
    fn max_component(self) -> f64;

    /// A brightness for ratios (photon Russian roulette): luminance in RGB,
    /// the mean over the lanes for a spectrum.
    fn brightness(self) -> f64;

    /// The film's RGB of this estimate.
    fn to_rgb(self, wavelengths: &Self::Wavelengths) -> Color;

    /// Samples `material`'s BSDF; a material whose scattering depends on
    /// wavelength samples it at the hero wavelength and ends the others.
    fn sample_bsdf(
        material: &Material,
        wo: DVec3,
        at: &ShadingPoint,
        u: DVec2,
        u_lobe: f64,
        transport: Transport,
        wavelengths: &mut Self::Wavelengths,
    ) -> Option<BsdfSample>;
}

impl Radiance for Color {
    type Wavelengths = ();
    const ZERO: Self = Color::ZERO;
    const ONE: Self = Color::ONE;

    #[inline(always)]
    fn from_rgb(rgb: Color, _: &()) -> Self {
        rgb
    }

    #[inline(always)]
    fn sample_wavelengths(_: &Sampler) {}

    #[inline(always)]
    fn is_dispersed(_: &()) -> bool {
        false
    }

    #[inline(always)]
    fn emission(emission: Emission<'_>, _: &()) -> Self {
        emission.rgb
    }

    #[inline(always)]
    fn max_component(self) -> f64 {
        crate::math::max_component(self)
    }

    #[inline(always)]
    fn brightness(self) -> f64 {
        crate::color::luminance(self)
    }

    #[inline(always)]
    fn to_rgb(self, _: &()) -> Color {
        self
    }

    #[inline(always)]
    fn sample_bsdf(
        material: &Material,
        wo: DVec3,
        at: &ShadingPoint,
        u: DVec2,
        u_lobe: f64,
        transport: Transport,
        _: &mut (),
    ) -> Option<BsdfSample> {
        material.sample(wo, at, u, u_lobe, transport)
    }
}

impl Radiance for SampledSpectrum {
    type Wavelengths = SampledWavelengths;
    const ZERO: Self = SampledSpectrum::ZERO;
    const ONE: Self = SampledSpectrum::ONE;

    #[inline]
    fn from_rgb(rgb: Color, wavelengths: &SampledWavelengths) -> Self {
        spectrum_of_rgb(rgb, wavelengths)
    }

    fn sample_wavelengths(sampler: &Sampler) -> SampledWavelengths {
        SampledWavelengths::sample_uniform(sampler.side_stream(WAVELENGTH_STREAM).next_1d())
    }

    fn is_dispersed(wavelengths: &SampledWavelengths) -> bool {
        wavelengths.secondary_terminated()
    }

    #[inline]
    fn emission(emission: Emission<'_>, wavelengths: &SampledWavelengths) -> Self {
        emission.sample(wavelengths)
    }

    #[inline]
    fn max_component(self) -> f64 {
        self.max_element()
    }

    #[inline]
    fn brightness(self) -> f64 {
        self.element_sum() / WAVELENGTHS as f64
    }

    /// XYZ = (1/N) Σᵢ L(λᵢ) (x̄, ȳ, z̄)(λᵢ) / p(λᵢ) / ∫ȳ over the live lanes
    /// (Wilkie et al. 2014, eq. 7), then the sensor's matrix.
    fn to_rgb(self, wavelengths: &SampledWavelengths) -> Color {
        let mut xyz = DVec3::ZERO;
        for i in 0..WAVELENGTHS {
            let pdf = wavelengths.pdf[i];
            if pdf > 0.0 && self[i] != 0.0 {
                let p = wavelengths.grid[i];
                let (a, b) = (DVec3::from(CIE_1931_2DEG[p.index]), DVec3::from(CIE_1931_2DEG[p.index + 1]));
                xyz += a.lerp(b, p.fraction) * (self[i] / pdf);
            }
        }
        let sensor = Sensor::get();
        sensor.rgb(xyz * (sensor.inverse_y_integral / WAVELENGTHS as f64))
    }

    fn sample_bsdf(
        material: &Material,
        wo: DVec3,
        at: &ShadingPoint,
        u: DVec2,
        u_lobe: f64,
        transport: Transport,
        wavelengths: &mut SampledWavelengths,
    ) -> Option<BsdfSample> {
        if material.is_dispersive() {
            // The direction now depends on λ: only the hero's path is this one.
            wavelengths.terminate_secondary();
            material.sample_at_wavelength(wo, at, u, u_lobe, transport, wavelengths.hero())
        } else {
            material.sample(wo, at, u, u_lobe, transport)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_spectrum_averages_to_the_films_white() {
        // One sample of 4 stratified wavelengths is noisy in colour; the
        // mean over a sweep of the hero's position (a quadrature of the
        // estimator's expectation, 4000 points per quarter of the range)
        // must be the white (1, 1, 1): the estimator is unbiased.
        let n = 4000;
        let mean = (0..n)
            .map(|k| SampledSpectrum::ONE.to_rgb(&SampledWavelengths::sample_uniform((k as f64 + 0.5) / n as f64)))
            .sum::<Color>()
            / n as f64;
        assert!((mean - Color::ONE).abs().max_element() < 1e-4, "{mean}");
        // With the secondaries terminated the hero alone is still unbiased.
        let mean = (0..n)
            .map(|k| {
                let mut w = SampledWavelengths::sample_uniform((k as f64 + 0.5) / n as f64);
                w.terminate_secondary();
                SampledSpectrum::ONE.to_rgb(&w)
            })
            .sum::<Color>()
            / n as f64;
        assert!((mean - Color::ONE).abs().max_element() < 1e-3, "{mean}");
    }
}
