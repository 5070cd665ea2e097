//! Caustics by light tracing: paths that leave a light, are reflected or
//! refracted by mirrors and glass, and then reach a diffuse or glossy
//! surface the camera sees, are traced from the light and connected to the
//! lens (the light-tracing strategy of bidirectional path tracing, Veach
//! 1997 §10.2, with t = 1), instead of being found by camera paths.
//!
//! A camera path can only find such light by hitting the light through the
//! glass at random, since a shadow ray cannot pass a specular surface: a
//! small light behind a glass ball makes a caustic of rare, bright samples.
//! From the light the same paths are easy: every photon that enters the
//! ball comes out focused, and the caustic it makes is connected straight
//! to the camera.
//!
//! The two strategies split path space between them, so the sum is unbiased
//! with no weights to compute. Take a camera path x₀ (lens), x₁, …, xₖ, xₖ₊₁
//! (on a light). Light tracing takes it exactly if
//! - x₁, the surface the camera sees, is not specular (a connection to the
//!   lens needs a BSDF that can be evaluated), and
//! - xₖ, the last surface before the light, is specular (a mirror or glass),
//!   and
//! - the light is one of the scene's emissive shapes (the sky is left to
//!   the camera paths);
//!
//! and the path tracer ([`super::tracer`]) drops the emission it would have
//! found along such a path (which it weighted 1, as light sampling cannot
//! produce it). A light path is the reverse: a photon from a light whose
//! first surface is specular, connected to the lens at each later
//! non-specular surface it reaches within the path-length limit. Photons
//! are aimed at the specular surfaces ([`super::caustic_emission`]), as
//! no other photon can start such a path.

use super::caustic_emission::CausticEmission;
use super::lens_connection::LensView;
use crate::camera::Camera;
use crate::color::Color;
use crate::film::Film;
use crate::integrator::bsdf_inputs::bsdf_inputs;
use crate::integrator::sppm::photon::shading_normal_correction;
use crate::material::{ShadingPoint, Transport};
use crate::math::{Frame as ShadingFrame, Ray};
use crate::sampler::{Sampler, SamplerKind};
use crate::scene::Scene;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Light paths traced per parallel job (one job each, not rayon's default
/// of a few large pieces; see `integrator::pass`): a few hundred
/// microseconds of tracing, which the scheduling does not notice, and
/// small enough that a pass's light paths balance across two to many
/// threads (at 1,024 a 256 × 192 image had six jobs).
const PATHS_PER_CHUNK: u64 = 128;

/// Mixed into the seed of light paths, so their sample streams are not the
/// camera samples of the pixel with the same index.
const LIGHT_PATH_STREAM: u64 = 0x6c69_6768_7420_7061;

/// Mixed into the seed of lens connections, for the same reason.
const LENS_CONNECTION_STREAM: u64 = 0x6c65_6e73_2062_616c;

/// One lens connection off mirror balls is made per this many light paths.
/// Measured at equal time on the depth-of-field scene (one thread, 4 s at
/// 128 × 96 and 8 s at 512 × 320, noise against one per light path): one
/// per 2, 4 and 8 light paths gave 1.007 / 1.022, 1.036 / 1.046 and
/// 1.030 / 1.055 times less noise (the time saved goes to camera rays).
const LIGHT_PATHS_PER_LENS_CONNECTION: u64 = 4;

/// Whether light tracing can find anything in `scene`: it has a shape
/// light and specular surfaces to focus its light.
pub fn scene_has_caustics(scene: &Scene) -> bool {
    !scene.lights.is_empty() && scene.materials.iter().any(|m| m.is_specular())
}

/// Light paths per pass for `pixels` sampled pixels: one per eight camera
/// samples. Measured at equal time (4 s, two threads, 256 wide), with
/// photons aimed at the casters: on the Cornell box the error against the
/// reference was flat from 1/16 to 1/4 per pixel, and the run-to-run noise
/// of a small glass ball under a large light was 0.0037 at 1/8, 0.0039 at
/// 1/4 and 0.0043 at 1/2: past that the camera paths, which get fewer
/// passes, dominate.
pub fn paths_per_pass(pixels: usize) -> u64 {
    (pixels as u64).div_ceil(8)
}

/// Traces `film.light`'s paths per pass, aimed by `emission` and at most
/// `max_depth` surfaces long (light path i uses the sample stream
/// (i, `sample_index`)), and adds their connections to the lens that
/// land on pixels (x, y) where `keep(x, y)` to `film.light` (nothing if it
/// is `None`); with `lens`, lens connections off mirror balls
/// ([`LensView::connect`]) too, one per [`LIGHT_PATHS_PER_LENS_CONNECTION`]
/// light paths. False if cancelled, leaving the film unchanged.
#[allow(clippy::too_many_arguments)]
pub fn add_pass(
    film: &mut Film,
    scene: &Scene,
    camera: &Camera,
    (emission, max_depth): (&CausticEmission, u32),
    lens: Option<&LensView>,
    keep: impl Fn(u32, u32) -> bool + Sync,
    (kind, seed, sample_index): (SamplerKind, u64, u32),
    cancel: &AtomicBool,
) -> bool {
    let (width, height) = (film.width, film.height);
    let Some(light) = film.light.as_mut() else {
        return true;
    };
    let paths = light.paths_per_pass;
    let chunks = paths.div_ceil(PATHS_PER_CHUNK);
    // The film divides every splat by the light paths per pass.
    let lens_scale = paths as f64 / paths.div_ceil(LIGHT_PATHS_PER_LENS_CONNECTION) as f64;
    let splats: Option<Vec<Vec<(usize, Color)>>> = (0..chunks as usize)
        .into_par_iter()
        .with_max_len(1)
        .map(|chunk| {
            let chunk = chunk as u64;
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            let mut splats = Vec::new();
            let mut push = |x: u32, y: u32, value: Color| {
                if keep(x, y) {
                    splats.push((y as usize * width as usize + x as usize, value));
                }
            };
            for index in chunk * PATHS_PER_CHUNK..((chunk + 1) * PATHS_PER_CHUNK).min(paths) {
                let mut sampler = Sampler::new(kind, index, sample_index, seed ^ LIGHT_PATH_STREAM);
                trace(scene, emission, camera, (width, height), max_depth, &mut sampler, &mut push);
                if let Some(view) = lens.filter(|_| index % LIGHT_PATHS_PER_LENS_CONNECTION == 0) {
                    let connection = index / LIGHT_PATHS_PER_LENS_CONNECTION;
                    let mut sampler = Sampler::new(kind, connection, sample_index, seed ^ LENS_CONNECTION_STREAM);
                    view.connect(scene, &mut sampler, |x, y, value| push(x, y, value * lens_scale));
                }
            }
            Some(splats)
        })
        .collect();
    let Some(splats) = splats else {
        return false;
    };
    // Integer sums: the same bits whatever order the chunks finished in.
    let mut rejected = 0;
    for (pixel, value) in splats.into_iter().flatten() {
        if !light.add(pixel, value) {
            rejected += 1;
        }
    }
    film.rejected_samples += rejected;
    true
}

/// Traces one light path and calls `splat(x, y, value)` for each connection
/// to the lens that is unoccluded: `value` is its contribution to pixel
/// (x, y) if one light path were traced for the whole image (divide by the
/// number traced).
pub fn trace(
    scene: &Scene,
    emission: &CausticEmission,
    camera: &Camera,
    (width, height): (u32, u32),
    max_depth: u32,
    sampler: &mut Sampler,
    mut splat: impl FnMut(u32, u32, Color),
) {
    let Some((mut ray, mut flux)) = emission.emit(scene, sampler) else {
        return;
    };
    let aspect = width as f64 / height as f64;
    let pixel_count = width as f64 * height as f64;
    for depth in 1..=max_depth {
        let Some(intersection) = scene.intersect(&ray, f64::INFINITY) else {
            return;
        };
        let hit = intersection.hit;
        let material = scene.material_of(intersection.primitive);
        let specular = material.is_specular();
        // Only paths whose first surface is specular are light tracing's.
        if !material.scatters() || (depth == 1 && !specular) {
            return;
        }
        let towards_light = -ray.direction;
        let frame = ShadingFrame::from_normal(hit.shading_normal);
        let at = ShadingPoint {
            uv: hit.uv,
            point: hit.point,
        };
        let wo = frame.to_local(towards_light);
        if !specular {
            let lens = sampler.next_2d();
            if let Some(connection) = camera.connect(hit.point, aspect, lens) {
                let wi = connection.towards_lens;
                // f · |wi·ns| times the adjoint's shading-normal correction
                // (Veach 1997, eq. 5.19): what the photon's flux becomes
                // as radiance leaving towards the lens, per unit area.
                let f = material.eval(wo, frame.to_local(wi), &at);
                let cosine = wi.dot(hit.shading_normal).abs() * shading_normal_correction(&hit, towards_light, wi);
                let value = flux * f * (cosine * connection.weight * pixel_count);
                if value != Color::ZERO {
                    let shadow = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, wi);
                    let clear = connection.clear_distance * (1.0 - 1e-9) - hit.point_error.length();
                    if clear > 0.0 && !scene.occluded(&shadow, clear) {
                        let x = ((connection.film.x * width as f64) as u32).min(width - 1);
                        let y = ((connection.film.y * height as f64) as u32).min(height - 1);
                        splat(x, y, value);
                    }
                }
            }
        }
        if depth == max_depth {
            return;
        }
        let (u, u_lobe) = bsdf_inputs(material, sampler);
        let Some(sample) = material.sample(wo, &at, u, u_lobe, Transport::Importance) else {
            return;
        };
        let direction = frame.to_world(sample.wi);
        let scattered = flux * sample.weight * shading_normal_correction(&hit, towards_light, direction);
        // Russian roulette on the luminance ratio, as for photons.
        let continue_probability = (scattered.max_element() / flux.max_element()).min(1.0);
        if continue_probability.is_nan() || continue_probability <= 0.0 || sampler.next_1d() >= continue_probability {
            return;
        }
        flux = scattered / continue_probability;
        ray = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, direction);
    }
}
