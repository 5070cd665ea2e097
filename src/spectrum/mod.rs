//! Spectral light transport: what a path carries when it carries
//! wavelengths instead of RGB.
//!
//! - [`wavelengths`]: hero-wavelength sampling of 4 wavelengths per path;
//! - [`cie`]: the CIE 1931 colour-matching functions on a 5 nm grid;
//! - [`sensor`]: the film's spectrum → XYZ → linear sRGB conversion;
//! - [`dispersion`]: indices of refraction that vary with wavelength;
//! - [`uplift`]: RGB reflectances and emissions as spectra (Smits' 1999 decomposition over basis spectra fitted to multiply as RGB does);
//! - [`illuminant`], [`blackbody`]: emission spectra of their own (CIE D65
//!   and A, Planck's law), and [`emission`]: what a light emits, as RGB or
//!   at sampled wavelengths;
//! - [`radiance`]: the colour type a path tracer is generic over (RGB or a
//!   [`SampledSpectrum`]).
//!
//! Wavelengths are in nanometres throughout.

pub mod blackbody;
pub mod cie;
pub mod dispersion;
pub mod emission;
pub mod illuminant;
pub mod radiance;
pub mod sensor;
pub mod uplift;
pub mod wavelengths;

pub use emission::{Emission, EmissionSpectrum, SpectrumSource};
pub use illuminant::StandardIlluminant;
pub use radiance::Radiance;
pub use sensor::Sensor;
pub use wavelengths::SampledWavelengths;

/// Wavelengths per path (lanes of a [`SampledSpectrum`]).
pub const WAVELENGTHS: usize = 4;
/// Shortest sampled wavelength, nm (where the CIE 1931 table starts).
pub const LAMBDA_MIN: f64 = 360.0;
/// Longest sampled wavelength, nm (where the CIE 1931 table ends).
pub const LAMBDA_MAX: f64 = 830.0;

/// A spectral quantity at a path's [`WAVELENGTHS`] sampled wavelengths (lane
/// i at `SampledWavelengths::lambda[i]`). Plain `DVec4` so arithmetic is free.
pub type SampledSpectrum = glam::DVec4;
