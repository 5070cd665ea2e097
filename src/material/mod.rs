//! Materials: a closed set of BSDFs dispatched by `match`.
//!
//! Conventions (as in pbrt and Nori): `wo` and `wi` are unit vectors in the
//! local shading frame, both pointing away from the surface; the shading
//! normal is +z, so `cos θ = w.z`. `eval` returns the BSDF value f(wo, wi)
//! without the cosine; `sample` returns the Monte Carlo weight
//! f·|cos θi| / pdf directly, which stays finite for specular lobes.

pub mod dielectric;
pub mod diffuse;
pub mod glossy;
pub mod mirror;
pub mod texture;

pub use texture::Texture;

use crate::color::Color;
use crate::spectrum::dispersion::Dispersion;
use crate::spectrum::{Emission, EmissionSpectrum};
use glam::{DVec2, DVec3};
use std::sync::Arc;

/// Which quantity a path carries: radiance from the camera, or importance
/// (photons) from the lights. Refraction scales them differently (Veach 1997, §5.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    /// Radiance carried from the camera (path tracing, SPPM camera paths).
    Radiance,
    /// Importance carried from the lights (SPPM photons).
    Importance,
}

/// Where a BSDF is evaluated, for texture lookups.
#[derive(Clone, Copy, Debug)]
pub struct ShadingPoint {
    /// Surface texture coordinates at the point.
    pub uv: DVec2,
    /// The point in world space (for solid, 3D textures).
    pub point: DVec3,
}

/// A direction drawn from a BSDF.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// The sampled incident direction, local shading frame, unit length.
    pub wi: DVec3,
    /// f·|cos θi| / pdf.
    pub weight: Color,
    /// Density per steradian; for specular lobes the discrete probability of the lobe.
    pub pdf: f64,
    /// The relative index of refraction n_transmitted / n_incident if `wi`
    /// refracted, 1 otherwise. A radiance weight carries 1/η² of it, which
    /// Russian roulette must not mistake for lost energy (pbrt-v4's etaScale).
    pub eta: f64,
    /// Whether `wi` came from a delta lobe (mirror, glass): emission found
    /// along it gets no MIS weight, as light sampling could not have made it.
    pub specular: bool,
}

/// A surface's reflectance and emission. Every variant but `Emissive`
/// scatters; `Mirror` and `Glass` are purely specular.
#[derive(Clone, Debug)]
pub enum Material {
    /// Lambertian reflection (see [`diffuse`]).
    Diffuse {
        /// Reflectance per channel, in [0, 1] (the loader refuses more).
        albedo: Texture,
    },
    /// A perfect mirror (see [`mirror`]).
    Mirror {
        /// Reflectance per channel, non-negative.
        tint: Texture,
    },
    /// Smooth glass (see [`dielectric`]): Fresnel-weighted reflection and
    /// refraction.
    Glass {
        /// Relative index of refraction, inside over outside; the outside is
        /// the side the shading normal points to.
        ior: f64,
        /// Colour multiplying both reflection and transmission.
        tint: Color,
        /// How the index varies with wavelength (`None`: it does not). An
        /// RGB render uses `ior`, the index at the d line; a spectral one
        /// refracts each path's hero wavelength by its own index.
        dispersion: Option<Dispersion>,
    },
    /// A rough conductor, GGX microfacets (see [`glossy`]).
    Glossy {
        /// Reflectance at normal incidence (Schlick's F0) per channel,
        /// non-negative.
        tint: Texture,
        /// GGX α, clamped to [10⁻³, 1]: 0 is a near-mirror, 1 very rough.
        roughness: f64,
    },
    /// A light: emits `radiance` from its front (outward normal) side, or both
    /// sides when `two_sided`; reflects nothing.
    Emissive {
        /// Emitted radiance Le as the film's linear RGB; for a spectral
        /// emitter, its spectrum's RGB (what RGB renders and light
        /// selection use).
        radiance: Color,
        /// Emit from both faces, not just the front.
        two_sided: bool,
        /// The emitter's own spectrum (a named illuminant or a blackbody);
        /// `None`: `radiance`'s uplift, as for every RGB colour.
        spectrum: Option<Arc<EmissionSpectrum>>,
    },
}

impl Material {
    /// True if every lobe is a delta: light sampling cannot help.
    pub fn is_specular(&self) -> bool {
        matches!(self, Material::Mirror { .. } | Material::Glass { .. })
    }

    /// True if no light passes through the surface (everything but glass):
    /// a closed surface of it separates inside from outside.
    pub fn is_opaque(&self) -> bool {
        !matches!(self, Material::Glass { .. })
    }

    /// True if the scattering depends on wavelength (dispersive glass): a
    /// scene with such a material is rendered spectrally.
    pub fn is_dispersive(&self) -> bool {
        matches!(self, Material::Glass { dispersion: Some(_), .. })
    }

    /// True if shading reads a hit's texture coordinates: some texture of
    /// the material varies over the surface. Hits on other materials may
    /// skip computing them (a sphere's cost an atan2 and an acos).
    pub fn reads_uv(&self) -> bool {
        match self {
            Material::Diffuse { albedo: texture }
            | Material::Mirror { tint: texture }
            | Material::Glossy { tint: texture, .. } => !texture.is_constant(),
            Material::Glass { .. } | Material::Emissive { .. } => false,
        }
    }

    /// True if the material scatters light at all.
    pub fn scatters(&self) -> bool {
        !matches!(self, Material::Emissive { .. })
    }

    /// Emitted radiance towards a direction making `cos_theta` with the
    /// geometric normal.
    pub fn emitted(&self, cos_theta: f64) -> Color {
        match self {
            Material::Emissive { radiance, two_sided, .. } if *two_sided || cos_theta > 0.0 => *radiance,
            _ => Color::ZERO,
        }
    }

    /// What this light emits towards a direction making `cos_theta` with
    /// the geometric normal, in the form [`Radiance::emission`] takes;
    /// `None` if it emits nothing that way (or is no light).
    ///
    /// [`Radiance::emission`]: crate::spectrum::Radiance::emission
    #[inline]
    pub fn emission_towards(&self, cos_theta: f64) -> Option<Emission<'_>> {
        match self {
            Material::Emissive {
                radiance,
                two_sided,
                spectrum,
            } if (*two_sided || cos_theta > 0.0) && *radiance != Color::ZERO => Some(Emission {
                rgb: *radiance,
                spectrum: spectrum.as_deref(),
            }),
            _ => None,
        }
    }

    /// The emitted radiance (film RGB) if this is a light, whatever the direction.
    pub fn emission(&self) -> Option<Color> {
        match self {
            Material::Emissive { radiance, .. } => Some(*radiance),
            _ => None,
        }
    }

    /// BSDF value f(wo, wi), without the cosine; zero for purely specular
    /// materials (their delta lobes are reached only by `sample`).
    pub fn eval(&self, wo: DVec3, wi: DVec3, at: &ShadingPoint) -> Color {
        match self {
            Material::Diffuse { albedo } => diffuse::eval(albedo.evaluate(at), wo, wi),
            Material::Glossy { tint, roughness } => glossy::eval(tint.evaluate(at), *roughness, wo, wi),
            Material::Mirror { .. } | Material::Glass { .. } | Material::Emissive { .. } => Color::ZERO,
        }
    }

    /// Solid-angle density with which `sample` draws `wi` given `wo`; zero
    /// for purely specular materials.
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        match self {
            Material::Diffuse { .. } => diffuse::pdf(wo, wi),
            Material::Glossy { roughness, .. } => glossy::pdf(*roughness, wo, wi),
            Material::Mirror { .. } | Material::Glass { .. } | Material::Emissive { .. } => 0.0,
        }
    }

    /// Which of [`Material::sample`]'s random inputs it reads: the 2D
    /// direction sample `u`, the 1D lobe choice `u_lobe`. A path draws only
    /// these, so a mirror bounce costs no draws and a diffuse one no lobe draw.
    pub fn sample_inputs(&self) -> (bool, bool) {
        match self {
            Material::Diffuse { .. } | Material::Glossy { .. } => (true, false),
            Material::Glass { .. } => (false, true),
            Material::Mirror { .. } | Material::Emissive { .. } => (false, false),
        }
    }

    /// Draws `wi` for the given `wo`; `u` picks the direction, `u_lobe` the lobe.
    // Always inlined: compiled into each copy of the path loop (baseline,
    // AVX2: `accel::kernel`) rather than called from it in baseline code.
    #[inline(always)]
    pub fn sample(&self, wo: DVec3, at: &ShadingPoint, u: DVec2, u_lobe: f64, transport: Transport) -> Option<BsdfSample> {
        match self {
            Material::Diffuse { albedo } => diffuse::sample(albedo.evaluate(at), wo, u),
            Material::Glossy { tint, roughness } => glossy::sample(tint.evaluate(at), *roughness, wo, u),
            Material::Mirror { tint } => mirror::sample(tint.evaluate(at), wo),
            Material::Glass { ior, tint, .. } => dielectric::sample(*ior, *tint, wo, u_lobe, transport),
            Material::Emissive { .. } => None,
        }
    }
}

impl Material {
    /// [`sample`](Self::sample) for light of wavelength `lambda_nm`: a
    /// dispersive glass refracts by its index there; everything else
    /// ignores the wavelength.
    pub fn sample_at_wavelength(
        &self,
        wo: DVec3,
        at: &ShadingPoint,
        u: DVec2,
        u_lobe: f64,
        transport: Transport,
        lambda_nm: f64,
    ) -> Option<BsdfSample> {
        match self {
            Material::Glass {
                tint,
                dispersion: Some(dispersion),
                ..
            } => dielectric::sample(dispersion.ior(lambda_nm), *tint, wo, u_lobe, transport),
            _ => self.sample(wo, at, u, u_lobe, transport),
        }
    }
}

/// Mirror direction about the local normal (+z).
pub fn reflect(wo: DVec3) -> DVec3 {
    DVec3::new(-wo.x, -wo.y, wo.z)
}

#[cfg(test)]
mod sampling_tests;
