//! The photon pass of SPPM: photons leave the emissive shapes and bounce
//! through the scene, handing their flux to a callback at every
//! non-specular surface they hit (Hachisuka & Jensen 2009, §3; Jensen 2001).
//!
//! Emission: a light is chosen in proportion to its power (`Lights::choose`),
//! a point uniformly on its area, and a direction cosine-weighted about the
//! normal (about either face, with probability ½ each, for two-sided lights),
//! so every photon carries flux Φ = Le·cos θ / (p_select · p_area · p_dir)
//! = π·A·Le·(sides) / p_select.

use crate::color::{Color, luminance};
use crate::geometry::SurfaceHit;
use crate::material::{ShadingPoint, Transport};
use crate::math::{DVec3, Frame as ShadingFrame, Ray, warp};
use crate::sampler::Sampler;
use crate::scene::Scene;

/// A photon leaving a light.
#[derive(Clone, Copy, Debug)]
pub struct Photon {
    pub ray: Ray,
    /// Flux carried, in watts per emitted photon (before dividing by the count).
    pub flux: Color,
}

/// Draws one photon from the scene's lights; `None` if there are none or
/// the sample is degenerate.
pub fn emit(scene: &Scene, sampler: &mut Sampler) -> Option<Photon> {
    let (index, select_probability) = scene.lights.choose(sampler.next_1d())?;
    let light = &scene.lights.lights[index as usize];
    let shape = &scene.primitives[light.primitive as usize].shape;
    let on_light = shape.sample_area(sampler.next_2d());
    let local = warp::square_to_cosine_hemisphere(sampler.next_2d());
    let side = sampler.next_1d();
    let (normal, side_probability) = match light.two_sided {
        true if side < 0.5 => (-on_light.normal, 0.5),
        true => (on_light.normal, 0.5),
        false => (on_light.normal, 1.0),
    };
    let direction_pdf = warp::cosine_hemisphere_pdf(local.z) * side_probability;
    let area_pdf = 1.0 / shape.area();
    if direction_pdf <= 0.0 || !area_pdf.is_finite() || select_probability <= 0.0 {
        return None;
    }
    let direction = ShadingFrame::from_normal(normal).to_world(local);
    let flux = light.radiance * (local.z / (select_probability * area_pdf * direction_pdf));
    Some(Photon {
        ray: Ray::spawn(on_light.point, on_light.point_error, normal, direction),
        flux,
    })
}

/// Follows `photon` for up to `max_depth` surface hits, calling
/// `deposit(hit, towards_light, flux)` at each non-specular one, where
/// `towards_light` is the unit direction the photon arrived from.
/// Scattering samples the BSDF for importance transport and Russian roulette
/// keeps the flux per photon roughly constant (pbrt-v3 §16.2.3).
pub fn trace(
    scene: &Scene,
    photon: Photon,
    sampler: &mut Sampler,
    max_depth: u32,
    mut deposit: impl FnMut(&SurfaceHit, DVec3, Color),
) {
    let Photon { mut ray, mut flux } = photon;
    for depth in 1..=max_depth {
        let Some(intersection) = scene.intersect(&ray, f64::INFINITY) else {
            return;
        };
        let hit = intersection.hit;
        let material = scene.material_of(intersection.primitive);
        if !material.scatters() {
            return;
        }
        let towards_light = -ray.direction;
        if !material.is_specular() {
            deposit(&hit, towards_light, flux);
        }
        if depth == max_depth {
            return;
        }

        // Scatter. In importance transport wo points back to the light.
        let frame = ShadingFrame::from_normal(hit.shading_normal);
        let at = ShadingPoint {
            uv: hit.uv,
            point: hit.point,
        };
        let u = sampler.next_2d();
        let u_lobe = sampler.next_1d();
        let Some(sample) = material.sample(frame.to_local(towards_light), &at, u, u_lobe, Transport::Importance) else {
            return;
        };
        let direction = frame.to_world(sample.wi);
        let scattered = flux * sample.weight * shading_normal_correction(&hit, towards_light, direction);

        // Russian roulette: continue with probability of the luminance ratio,
        // so surviving photons keep about the flux they had.
        let continue_probability = (luminance(scattered) / luminance(flux)).min(1.0);
        if continue_probability.is_nan() || continue_probability <= 0.0 || sampler.next_1d() >= continue_probability {
            return;
        }
        flux = scattered / continue_probability;
        ray = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, direction);
    }
}

/// The adjoint BSDF's correction for shading normals (Veach 1997, eq. 5.19):
/// |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|), 1 where shading and geometry agree.
fn shading_normal_correction(hit: &SurfaceHit, wo: DVec3, wi: DVec3) -> f64 {
    if hit.shading_normal == hit.geometric_normal {
        return 1.0;
    }
    let denominator = wo.dot(hit.geometric_normal).abs() * wi.dot(hit.shading_normal).abs();
    if denominator == 0.0 {
        return 0.0;
    }
    wo.dot(hit.shading_normal).abs() * wi.dot(hit.geometric_normal).abs() / denominator
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::SamplerKind;
    use crate::scene::load_scene_str;
    use std::path::Path;

    fn scene(text: &str) -> Scene {
        load_scene_str(text, Path::new("<test>"), Path::new("."))
            .map(|l| l.scene)
            .expect("test scene parses")
    }

    const TWO_LIGHTS: &str = r#"
        [camera]
        position = [0, 0, -5]
        look_at = [0, 0, 0]
        [materials.warm]
        type = "emissive"
        radiance = [4, 2, 1]
        [materials.cold]
        type = "emissive"
        radiance = [1, 1, 3]
        two_sided = true
        [[objects]]
        type = "sphere"
        center = [0, 0, 0]
        radius = 0.5
        material = "warm"
        [[objects]]
        type = "quad"
        corner = [2, 0, 0]
        edge_u = [1, 0, 0]
        edge_v = [0, 2, 0]
        material = "cold"
    "#;

    /// The mean emitted flux per photon is the scene's total emitted power
    /// Σ π·A·Le·(sides), whatever the selection probabilities.
    #[test]
    fn photons_carry_the_total_power_on_average() {
        let scene = scene(TWO_LIGHTS);
        let n = 20_000;
        let mut sum = Color::ZERO;
        for i in 0..n {
            let mut sampler = Sampler::new(SamplerKind::Sobol, i, 0, 11);
            if let Some(p) = emit(&scene, &mut sampler) {
                assert!((p.ray.direction.length() - 1.0).abs() < 1e-9);
                sum += p.flux;
            }
        }
        let pi = std::f64::consts::PI;
        let sphere = pi * (4.0 * pi * 0.25) * Color::new(4.0, 2.0, 1.0);
        let quad = pi * 2.0 * 2.0 * Color::new(1.0, 1.0, 3.0);
        let expected = sphere + quad;
        let mean = sum / n as f64;
        // Light choice is the only random factor in the flux (cos/p_dir is
        // constant). Blue varies most: a two-point variable with relative
        // σ ≈ 0.84 per photon, so ≈ 0.6% over 20 000 photons; allow 5σ = 3%.
        for c in 0..3 {
            assert!((mean[c] / expected[c] - 1.0).abs() < 0.03, "{mean} vs {expected}");
        }
    }

    /// A two-sided quad light sends photons to both sides equally; a one-sided
    /// sphere only outwards.
    #[test]
    fn photons_leave_from_the_emitting_sides() {
        let scene = scene(TWO_LIGHTS);
        let (mut front, mut back) = (0i64, 0i64);
        for i in 0..4000 {
            let mut sampler = Sampler::new(SamplerKind::Random, i, 0, 5);
            let Some(p) = emit(&scene, &mut sampler) else {
                continue;
            };
            if p.ray.origin.x > 1.5 {
                if p.ray.direction.z < 0.0 { front += 1 } else { back += 1 }
            } else {
                assert!(p.ray.direction.dot(p.ray.origin) > 0.0, "sphere photon goes inwards");
            }
        }
        // Binomial with n ≈ 2000, p = ½: σ ≈ 22; allow 5σ.
        assert!(front + back > 1000 && (front - back).abs() < 5 * 23, "{front} {back}");
    }
}
