//! The BSDF's sample inputs taken from a sample stream: the direction's 2D
//! draw and the lobe's 1D draw, computed only where the material reads them.
//! Camera paths, light paths and photons all scatter this way, so they
//! share these helpers.

use crate::material::Material;
use crate::math::DVec2;
use crate::sampler::{Deferred1d, Sampler};

/// [`bsdf_inputs`] for draws made ahead, before the surface was known: the
/// direction drawn, and the lobe reserved and computed here only if the
/// BSDF reads it.
#[inline]
pub fn bsdf_inputs_drawn(material: &Material, direction: DVec2, lobe: Deferred1d, sampler: &Sampler) -> (DVec2, f64) {
    let (uses_direction, uses_lobe) = material.sample_inputs();
    let u = if uses_direction { direction } else { DVec2::ZERO };
    let u_lobe = if uses_lobe { sampler.draw_1d(lobe) } else { 0.5 };
    (u, u_lobe)
}

/// The direction and lobe samples for scattering off `material`, drawn as
/// two dimensions of `sampler` always (a 2D and a 1D draw, so the stream's
/// later draws do not depend on the material), but computed only where
/// [`Material::sample_inputs`] says the BSDF reads them; the rest are
/// placeholders it ignores. The values it reads are those plain draws give.
#[inline]
pub fn bsdf_inputs(material: &Material, sampler: &mut Sampler) -> (DVec2, f64) {
    let (uses_direction, uses_lobe) = material.sample_inputs();
    let u = if uses_direction {
        sampler.next_2d()
    } else {
        sampler.skip();
        DVec2::ZERO
    };
    let u_lobe = if uses_lobe {
        sampler.next_1d()
    } else {
        sampler.skip();
        0.5
    };
    (u, u_lobe)
}
