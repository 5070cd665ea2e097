//! The photon pass of SPPM: photons leave the emissive shapes and the sky
//! and bounce through the scene, handing their flux to a callback at every
//! non-specular surface they hit (Hachisuka & Jensen 2009, §3; Jensen 2001).
//!
//! Emission: a source is chosen in proportion to its power, then
//! - from an emissive shape (`Lights::choose`): a point uniformly on its
//!   area and a direction cosine-weighted about the normal (about either
//!   face, with probability ½ each, for two-sided lights), so every photon
//!   carries flux Φ = Le·cos θ / (p_select · p_area · p_dir)
//!   = π·A·Le·(sides) / p_select;
//! - from the sky (a constant background radiance L, arriving from every
//!   direction): a direction ω uniformly on the sphere, and a point uniformly
//!   on the disc of the scene's bounding sphere (radius R) that faces ω, the
//!   photon travelling along −ω (pbrt-v4 §12.5, `UniformInfiniteLight::SampleLe`).
//!   Every photon crossing the bounding sphere is reachable this way, and it
//!   carries Φ = L / (p_select · p_ω · p_disc) = 4π · πR² · L / p_select.
//!
//! A photon carries RGB flux, or in spectral mode the flux at its own
//! sampled wavelengths (drawn from a side stream of its sampler, so its
//! other draws are those of an RGB photon); a dispersive interface sends it
//! on at its hero wavelength only, as for camera paths.

use crate::color::{Color, luminance};
use crate::geometry::SurfaceHit;
use crate::integrator::bsdf_inputs::bsdf_inputs_drawn;
use crate::light::EmitterSource;
use crate::material::{ShadingPoint, Transport};
use crate::math::{DVec3, Frame as ShadingFrame, Ray, warp};
use crate::sampler::Sampler;
use crate::scene::Scene;
use crate::spectrum::Radiance;
use std::f64::consts::PI;

/// A photon leaving a light, carrying RGB or spectral flux `C`.
#[derive(Clone, Copy, Debug)]
pub struct Photon<C: Radiance = Color> {
    /// Where it starts (offset off the light's surface, or on a disc outside
    /// the scene for sky photons) and which way it travels.
    pub ray: Ray,
    /// Flux carried, in watts per emitted photon (before dividing by the count).
    pub flux: C,
    /// Its wavelengths (nothing in RGB).
    pub wavelengths: C::Wavelengths,
}

/// A constant, non-black background as a photon source.
#[derive(Clone, Copy, Debug)]
struct Sky {
    radiance: Color,
    /// Bounding sphere of the scene's geometry.
    center: DVec3,
    radius: f64,
    /// Luminance of the power it sends into the bounding sphere, 4π · πR² · L.
    power: f64,
}

/// Everything that emits photons: the emissive shapes and, if the
/// background is not black, the sky.
#[derive(Clone, Copy, Debug)]
pub struct PhotonSources {
    sky: Option<Sky>,
    /// Probability of emitting from the sky rather than from a shape.
    sky_probability: f64,
    total_power: f64,
}

impl PhotonSources {
    /// The scene's photon sources: its emissive shapes, plus the sky if the
    /// background is not black and the scene has finite, non-empty bounds.
    pub fn new(scene: &Scene) -> Self {
        let bounds = scene.bounds();
        let radius = 0.5 * bounds.extent().length();
        let sky = (luminance(scene.background) > 0.0 && !bounds.is_empty() && radius.is_finite() && radius > 0.0).then(|| {
            // Slightly larger, so photons start outside every surface.
            let radius = radius * (1.0 + 1e-6);
            Sky {
                radiance: scene.background,
                center: bounds.centroid(),
                radius,
                power: 4.0 * PI * PI * radius * radius * luminance(scene.background),
            }
        });
        let sky_power = sky.map_or(0.0, |s| s.power);
        let total_power = scene.lights.total_power + sky_power;
        Self {
            sky,
            sky_probability: if total_power > 0.0 { sky_power / total_power } else { 0.0 },
            total_power,
        }
    }

    /// Luminance of the total emitted power: the scale of one photon's flux.
    pub fn total_power(&self) -> f64 {
        self.total_power
    }

    /// Draws one photon; `None` if nothing emits or the sample is degenerate.
    /// Without a sky, the samples drawn are exactly those of a scene whose
    /// only sources are its shapes.
    pub fn emit<C: Radiance>(&self, scene: &Scene, sampler: &mut Sampler) -> Option<Photon<C>> {
        let wavelengths = C::sample_wavelengths(sampler);
        let u_select = sampler.next_1d();
        let Some(sky) = self.sky else {
            return emit_from_shape(scene, u_select, 1.0, sampler, wavelengths);
        };
        let p_sky = self.sky_probability;
        if u_select < p_sky {
            return emit_from_sky(&sky, p_sky, sampler, wavelengths);
        }
        // Reuse the selection sample: it is uniform on [p_sky, 1) here.
        let u_shape = ((u_select - p_sky) / (1.0 - p_sky)).min(1.0 - f64::EPSILON / 2.0);
        emit_from_shape(scene, u_shape, 1.0 - p_sky, sampler, wavelengths)
    }
}

/// The 2D draws of a photon from a shape, computed together when its
/// stream starts ([`crate::sampler::Sampler::draw_ahead`]): the point on the
/// light (dimension 2, after the light's choice) and the direction from it
/// (3), then, after the side's draw, the first two bounces' directions (5
/// and 8; each bounce draws direction, lobe and roulette).
pub const DIMENSIONS_DRAWN_AHEAD: [u32; 4] = [2, 3, 5, 8];

/// A photon from the emissive shapes, chosen by `u_select`, which is itself
/// chosen with probability `shape_probability`.
fn emit_from_shape<C: Radiance>(
    scene: &Scene,
    u_select: f64,
    shape_probability: f64,
    sampler: &mut Sampler,
    wavelengths: C::Wavelengths,
) -> Option<Photon<C>> {
    let (index, light_probability) = scene.lights.choose(u_select)?;
    let select_probability = light_probability * shape_probability;
    let light = &scene.lights.lights[index as usize];
    let emitter = scene.emitter(light.primitive);
    let on_light = emitter.sample_area(sampler.next_2d());
    let local = warp::square_to_cosine_hemisphere(sampler.next_2d());
    // The side is drawn for one-sided lights too (so the draws after it
    // keep their dimensions), but only computed for two-sided ones.
    let side = match light.two_sided {
        true => sampler.next_1d(),
        false => {
            sampler.skip();
            0.5
        }
    };
    let (normal, side_probability) = match light.two_sided {
        true if side < 0.5 => (-on_light.normal, 0.5),
        true => (on_light.normal, 0.5),
        false => (on_light.normal, 1.0),
    };
    let direction_pdf = warp::cosine_hemisphere_pdf(local.z) * side_probability;
    let area_pdf = 1.0 / emitter.area();
    if direction_pdf <= 0.0 || !area_pdf.is_finite() || select_probability <= 0.0 {
        return None;
    }
    let direction = ShadingFrame::from_normal(normal).to_world(local);
    let flux = C::emission(light.emission(), &wavelengths) * (local.z / (select_probability * area_pdf * direction_pdf));
    Some(Photon {
        ray: Ray::spawn(on_light.point, on_light.point_error, normal, direction),
        flux,
        wavelengths,
    })
}

/// A photon from the sky, which was chosen with probability `select_probability`.
fn emit_from_sky<C: Radiance>(
    sky: &Sky,
    select_probability: f64,
    sampler: &mut Sampler,
    wavelengths: C::Wavelengths,
) -> Option<Photon<C>> {
    let towards_sky = warp::square_to_uniform_sphere(sampler.next_2d());
    let disc = sky.radius * warp::square_to_concentric_disk(sampler.next_2d());
    let frame = ShadingFrame::from_normal(towards_sky);
    let origin = sky.center + sky.radius * towards_sky + frame.to_world(DVec3::new(disc.x, disc.y, 0.0));
    let disc_pdf = 1.0 / (PI * sky.radius * sky.radius);
    if select_probability <= 0.0 || !disc_pdf.is_finite() {
        return None;
    }
    let flux = C::from_rgb(sky.radiance, &wavelengths) / (select_probability * warp::UNIFORM_SPHERE_PDF * disc_pdf);
    Some(Photon {
        ray: Ray::new(origin, -towards_sky),
        flux,
        wavelengths,
    })
}

/// Follows `photon` for up to `max_depth` surface hits, calling
/// `deposit(hit, towards_light, flux, wavelengths)` at each non-specular
/// one, where `towards_light` is the unit direction the photon arrived from.
/// Scattering samples the BSDF for importance transport and Russian roulette
/// keeps the flux per photon roughly constant (pbrt-v3 §16.2.3).
pub fn trace<C: Radiance>(
    scene: &Scene,
    photon: Photon<C>,
    sampler: &mut Sampler,
    max_depth: u32,
    mut deposit: impl FnMut(&SurfaceHit, DVec3, C, &C::Wavelengths),
) {
    let Photon {
        mut ray,
        mut flux,
        mut wavelengths,
    } = photon;
    for depth in 1..=max_depth {
        // This bounce's draws (direction, lobe, roulette: the dimensions
        // `bsdf_inputs` and the roulette take), made before the traversal,
        // which they do not depend on, so their hash chains overlap it. The
        // direction, which most surfaces read, is computed now; the rest
        // only where read.
        let u_direction = sampler.next_2d();
        let (u_lobe, u_roulette) = (sampler.defer_1d(), sampler.defer_1d());
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
            deposit(&hit, towards_light, flux, &wavelengths);
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
        let (u, u_lobe) = bsdf_inputs_drawn(material, u_direction, u_lobe, sampler);
        let wo = frame.to_local(towards_light);
        let Some(sample) = C::sample_bsdf(material, wo, &at, u, u_lobe, Transport::Importance, &mut wavelengths) else {
            return;
        };
        let direction = frame.to_world(sample.wi);
        let scattered =
            flux * C::from_rgb(sample.weight, &wavelengths) * shading_normal_correction(&hit, towards_light, direction);

        // Russian roulette: continue with probability of the luminance ratio,
        // so surviving photons keep about the flux they had.
        let continue_probability = (scattered.brightness() / flux.brightness()).min(1.0);
        if continue_probability.is_nan() || continue_probability <= 0.0 || sampler.draw_1d(u_roulette) >= continue_probability {
            return;
        }
        flux = scattered / continue_probability;
        ray = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, direction);
    }
}

/// The adjoint BSDF's correction for shading normals (Veach 1997, eq. 5.19):
/// |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|), 1 where shading and geometry agree.
pub fn shading_normal_correction(hit: &SurfaceHit, wo: DVec3, wi: DVec3) -> f64 {
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

    fn emit(scene: &Scene, sampler: &mut Sampler) -> Option<Photon> {
        PhotonSources::new(scene).emit::<Color>(scene, sampler)
    }

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

    /// With a sky as well, the mean flux per photon is the shapes' power plus
    /// the sky's 4π · πR² · L (R: the bounding sphere's radius), and every sky
    /// photon starts on the bounding sphere's tangent disc, aimed into it.
    #[test]
    fn sky_photons_carry_the_sky_power_into_the_bounding_sphere() {
        let text = format!("background = [0.2, 0.1, 0.05]\n{TWO_LIGHTS}");
        let scene = scene(&text);
        let bounds = scene.bounds();
        let (center, radius) = (bounds.centroid(), 0.5 * bounds.extent().length());
        let n = 40_000;
        let mut sum = Color::ZERO;
        let mut from_sky = 0;
        for i in 0..n {
            let mut sampler = Sampler::new(SamplerKind::Sobol, i, 0, 11);
            let Some(p) = emit(&scene, &mut sampler) else { continue };
            sum += p.flux;
            let offset = p.ray.origin - center;
            if offset.length() > 1.0001 * radius {
                from_sky += 1;
                // Outside the sphere, heading in, passing within R of the centre.
                assert!(offset.dot(p.ray.direction) < 0.0);
                let miss_distance = (offset - offset.dot(p.ray.direction) * p.ray.direction).length();
                assert!(miss_distance <= radius * (1.0 + 1e-5), "{miss_distance} > {radius}");
            }
        }
        let pi = std::f64::consts::PI;
        let shapes = pi * (4.0 * pi * 0.25) * Color::new(4.0, 2.0, 1.0) + pi * 2.0 * 2.0 * Color::new(1.0, 1.0, 3.0);
        let sky = 4.0 * pi * pi * radius * radius * Color::new(0.2, 0.1, 0.05);
        let expected = shapes + sky;
        let mean = sum / n as f64;
        assert!(from_sky > n / 10, "only {from_sky} sky photons");
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
