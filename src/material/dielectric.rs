//! Smooth dielectric (glass): exact unpolarised Fresnel reflectance, Snell
//! refraction, total internal reflection; reflection or refraction is chosen
//! with probability equal to its Fresnel weight, so the weight is the tint.

use super::{BsdfSample, Transport, reflect};
use crate::color::Color;
use glam::DVec3;

/// Fresnel reflectance of a smooth dielectric boundary for light arriving at
/// `cos_theta_i` (positive on the outside) with relative index `ior` = n_inside / n_outside.
/// Exact average of the s- and p-polarised terms (pbrt-v4 eq. 9.6).
pub fn fresnel_dielectric(cos_theta_i: f64, ior: f64) -> f64 {
    let (cos_i, eta) = if cos_theta_i < 0.0 {
        (-cos_theta_i, 1.0 / ior)
    } else {
        (cos_theta_i, ior)
    };
    let cos_i = cos_i.min(1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0; // total internal reflection
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)
}

/// Reflects with probability F (Fresnel) and refracts by Snell's law
/// otherwise, so the weight is the tint (divided by η² for radiance,
/// η = n_transmitted / n_incident). `pdf` is the lobe's discrete
/// probability.
pub fn sample(ior: f64, tint: Color, wo: DVec3, u_lobe: f64, transport: Transport) -> Option<BsdfSample> {
    if wo.z == 0.0 {
        return None;
    }
    let reflectance = fresnel_dielectric(wo.z, ior);
    if u_lobe < reflectance {
        return Some(BsdfSample {
            wi: reflect(wo),
            weight: tint,
            pdf: reflectance,
            eta: 1.0,
            specular: true,
        });
    }
    // Refract: eta is the ratio n_transmitted / n_incident seen from wo's side.
    let entering = wo.z > 0.0;
    let eta = if entering { ior } else { 1.0 / ior };
    let cos_i = wo.z.abs();
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let wi = DVec3::new(-wo.x / eta, -wo.y / eta, if entering { -cos_t } else { cos_t });
    // Radiance is compressed into the denser medium by 1/η² (Veach 1997, §5.2);
    // importance is not.
    let scale = match transport {
        Transport::Radiance => 1.0 / (eta * eta),
        Transport::Importance => 1.0,
    };
    Some(BsdfSample {
        wi: wi.normalize(),
        weight: tint * scale,
        pdf: 1.0 - reflectance,
        eta,
        specular: true,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_matches_known_values() {
        // Normal incidence: ((n-1)/(n+1))² = 0.04 for n = 1.5.
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-12);
        // Brewster angle: p-polarised reflection vanishes, so R = R_s / 2.
        let brewster = 1.5_f64.atan();
        let r = fresnel_dielectric(brewster.cos(), 1.5);
        let (ci, ct) = (brewster.cos(), (1.0 - (brewster.sin() / 1.5).powi(2)).sqrt());
        let rs = ((ci - 1.5 * ct) / (ci + 1.5 * ct)).powi(2);
        assert!((r - 0.5 * rs).abs() < 1e-12);
        // Inside, beyond the critical angle asin(1/1.5): total internal reflection.
        assert_eq!(fresnel_dielectric(-0.5, 1.5), 1.0);
        assert!(fresnel_dielectric(-0.9, 1.5) < 1.0);
    }

    #[test]
    fn refraction_obeys_snell() {
        let wo = DVec3::new(0.6, 0.0, 0.8);
        // Pick the refraction lobe with u_lobe = 0.999 (Fresnel is ~5%).
        let s = sample(1.5, Color::ONE, wo, 0.999, Transport::Importance).map(|s| s.wi);
        let wi = s.unwrap_or(DVec3::ZERO);
        let sin_i = 0.6;
        let sin_t = (wi.x * wi.x + wi.y * wi.y).sqrt();
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-12 && wi.z < 0.0 && wi.x < 0.0);
    }
}
