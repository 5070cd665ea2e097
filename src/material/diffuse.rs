//! Lambertian reflection f = albedo / π, sampled by the cosine-weighted
//! hemisphere on the side `wo` lies on (so both faces of a wall reflect).

use crate::color::Color;
use crate::math::warp;
use glam::{DVec2, DVec3};
use std::f64::consts::FRAC_1_PI;

use super::BsdfSample;

/// f = albedo / π when `wo` and `wi` lie on the same side, else 0.
pub fn eval(albedo: Color, wo: DVec3, wi: DVec3) -> Color {
    if wo.z * wi.z <= 0.0 { Color::ZERO } else { albedo * FRAC_1_PI }
}

/// cos θi / π on `wo`'s side, else 0.
pub fn pdf(wo: DVec3, wi: DVec3) -> f64 {
    if wo.z * wi.z <= 0.0 {
        0.0
    } else {
        warp::cosine_hemisphere_pdf(wi.z.abs())
    }
}

/// A cosine-weighted direction on `wo`'s side; the weight is the albedo.
/// `None` for grazing `wo` (cos θo = 0).
// Always inlined: compiled into each copy of the path loop (baseline,
// AVX2: `accel::kernel`) rather than called from it in baseline code.
#[inline(always)]
pub fn sample(albedo: Color, wo: DVec3, u: DVec2) -> Option<BsdfSample> {
    if wo.z == 0.0 {
        return None;
    }
    let mut wi = warp::square_to_cosine_hemisphere(u);
    if wo.z < 0.0 {
        wi.z = -wi.z;
    }
    let pdf = warp::cosine_hemisphere_pdf(wi.z.abs());
    (pdf > 0.0).then_some(BsdfSample {
        wi,
        // f cos / pdf = (albedo/π) cos / (cos/π).
        weight: albedo,
        pdf,
        eta: 1.0,
        specular: false,
    })
}
