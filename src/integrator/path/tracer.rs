//! Iterative path tracing (Kajiya 1986) with next-event estimation and
//! multiple importance sampling by the power heuristic (Veach 1997, ch. 9),
//! and Russian roulette (Arvo & Kirk 1990); or, in BSDF-only mode, the original's estimator
//! that adds emission only where BSDF-sampled paths happen to hit it.
//!
//! This file is the per-sample tracer; [`super`] drives it over the film.

use super::ball_connection::{Departure, Passage, radiance_by_balls};
use super::lens_connection::LensView;
use crate::accel::{Portable, Traversal};
use crate::color::Color;
use crate::geometry::{Bounce, SurfaceHit};
use crate::integrator::bsdf_inputs::bsdf_inputs_drawn;
use crate::material::{ShadingPoint, Transport};
use crate::math::{Frame as ShadingFrame, Ray, ray::offset_ray_origin, warp::power_heuristic};
use crate::sampler::{Deferred1d, Sampler};
use crate::scene::{Leaving, Scene};
use crate::settings::{IntegratorKind, RenderSettings};
use crate::spectrum::{Radiance, SampledSpectrum, SampledWavelengths};
use glam::DVec2;

/// Bounces before Russian roulette may end a path.
pub(super) const ROULETTE_START: u32 = 3;

/// The probability that Russian roulette lets a path go on, from the
/// largest component of its throughput β: √β, at most 0.95 (Blender
/// Cycles' rule). Survival in proportion to β itself (Arvo & Kirk 1990)
/// ends a path whose weight has fallen to β = 1/4 three times in four and
/// gives the survivors weight 1, so in scenes where light arrives after
/// many bounces the roulette's variance outgrows the time it saves; with
/// √β that path survives half the time with weight 1/2. Paths that go on
/// get no heavier than before (β/√β = √β ≤ 1), so no new fireflies.
/// Measured on every shipped path-traced scene: 3–19% less squared error
/// per sample for 0–8% more time per sample (docs/performance.md,
/// "Russian roulette by the throughput's square root").
#[inline(always)]
pub(super) fn survival_probability(largest_throughput: f64) -> f64 {
    largest_throughput.sqrt().min(0.95)
}

/// One bounce's draws from the sampler. Every bounce takes the same five
/// dimensions in the same order (light choice, point on the light, BSDF
/// direction, BSDF lobe, then the roulette's at the bounce's end), whatever
/// surface it meets, so they can be drawn before the surface is known: at
/// the top of the bounce, where their hash chains (tens of dependent
/// multiplications) overlap the ray's traversal instead of following it.
/// The two 2D draws, which nearly every surface reads, are computed then;
/// the 1D draws only where read ([`Sampler::defer_1d`]). The first
/// bounce's point on the light is the sampler's joint dimension: one
/// four-dimensional Sobol' point with the film position
/// ([`crate::sampler::JOINT_DIMENSION`]).
struct BounceDraws {
    /// `None` with one light or none: nothing to choose.
    light_choice: Option<Deferred1d>,
    /// Zero without light sampling (never read).
    light_point: DVec2,
    direction: DVec2,
    lobe: Deferred1d,
}

impl BounceDraws {
    // Always inlined, with the sampler's `next_2d`, so the draws are
    // compiled into each copy of the path loop (AVX2's included).
    #[inline(always)]
    fn new(sampler: &mut Sampler, light_sampling: bool, several_lights: bool) -> Self {
        let light_choice = match several_lights {
            true => Some(sampler.defer_1d()),
            false => {
                sampler.skip();
                None
            }
        };
        let light_point = match light_sampling {
            true => sampler.next_2d(),
            false => {
                sampler.skip();
                DVec2::ZERO
            }
        };
        Self {
            light_choice,
            light_point,
            direction: sampler.next_2d(),
            lobe: sampler.defer_1d(),
        }
    }
}

/// Options of the per-sample tracer.
#[derive(Clone, Copy, Debug)]
pub struct PathTracer {
    /// Most scattering events per path: at 1, direct lighting only (emission
    /// is still gathered at the vertex after the last scattering).
    pub max_depth: u32,
    /// Sample lights directly and weight by MIS (false: BSDF sampling only).
    pub light_sampling: bool,
    /// Leave caustics seen on the first surface to light paths: drop the
    /// emission of a shape light reached through a specular surface after
    /// a non-specular first surface (see [`super::caustic_paths`]).
    pub caustics_by_light_paths: bool,
    /// Lights seen in mirror balls are also reached by lens connections
    /// ([`super::lens_connection`]): weight emission found by a camera ray
    /// reflected off a mirror ball by the camera's share.
    pub lens_connections: Option<LensView>,
}

impl PathTracer {
    /// The tracer `settings` ask for: NEE with MIS, or BSDF sampling only for
    /// [`IntegratorKind::BsdfOnly`].
    pub fn from_settings(settings: &RenderSettings) -> Self {
        Self {
            max_depth: settings.max_depth,
            light_sampling: settings.integrator != IntegratorKind::BsdfOnly,
            caustics_by_light_paths: false,
            lens_connections: None,
        }
    }

    /// Radiance arriving along `ray` (the Li of the rendering equation), in RGB.
    pub fn radiance(&self, scene: &Scene, ray: Ray, sampler: &mut Sampler) -> Color {
        self.trace::<Color>(scene, ray, sampler, &mut ())
    }

    /// The same by hero-wavelength spectral sampling: draws the path's
    /// wavelengths (from a side stream of the pixel sample, so the path's
    /// own draws are those of the RGB tracer), traces them, and returns the
    /// film's RGB of the estimate.
    pub fn spectral_radiance(&self, scene: &Scene, ray: Ray, sampler: &mut Sampler) -> Color {
        let mut wavelengths = SampledSpectrum::sample_wavelengths(sampler);
        self.radiance_at(scene, ray, sampler, &mut wavelengths)
    }

    /// Spectral radiance at given wavelengths, as film RGB (for measurements
    /// at fixed wavelengths; [`spectral_radiance`](Self::spectral_radiance) samples them).
    pub fn radiance_at(&self, scene: &Scene, ray: Ray, sampler: &mut Sampler, wavelengths: &mut SampledWavelengths) -> Color {
        let radiance: SampledSpectrum = self.trace(scene, ray, sampler, wavelengths);
        radiance.to_rgb(wavelengths)
    }

    /// The path tracer proper, over either colour type (see [`Radiance`]):
    /// RGB values from materials enter through `C::from_rgb`, emission through
    /// `C::emission` (an emitter may have a spectrum of its own).
    fn trace<C: Radiance>(&self, scene: &Scene, ray: Ray, sampler: &mut Sampler, wavelengths: &mut C::Wavelengths) -> C {
        let light_sampling = self.light_sampling && !scene.lights.is_empty();
        match (light_sampling && !scene.specular_balls().is_empty(), scene.bvh().avx2()) {
            (true, _) => self.trace_with::<C, true>(Portable, scene, ray, sampler, wavelengths),
            // The loop compiled for AVX2 with its traversals inside (the
            // BVH's kernel: see `accel::kernel`).
            (false, Some(avx2)) => avx2.run(
                #[inline(always)]
                || self.trace_with::<C, false>(avx2, scene, ray, sampler, wavelengths),
            ),
            (false, _) => self.trace_with::<C, false>(Portable, scene, ray, sampler, wavelengths),
        }
    }

    /// [`trace`](Self::trace), compiled three times: scenes without
    /// specular balls (`BALLS` false) carry none of the connections'
    /// bookkeeping, and their loop is compiled for each kernel, with the
    /// nearest-hit traversal (`traversal`) inside it.
    #[inline(always)]
    fn trace_with<C: Radiance, const BALLS: bool>(
        &self,
        traversal: impl Traversal,
        scene: &Scene,
        mut ray: Ray,
        sampler: &mut Sampler,
        wavelengths: &mut C::Wavelengths,
    ) -> C {
        let mut radiance = C::ZERO;
        let mut throughput = C::ONE;
        let mut specular_bounce = true;
        // The product of η² over the refractions so far: the throughput
        // times this is what the path still carries, as radiance entering
        // glass is compressed by 1/η² and expands again on leaving.
        let mut eta_scale = 1.0;
        let mut previous_pdf = 0.0;
        let mut previous_point = ray.origin;
        let light_sampling = self.light_sampling && !scene.lights.is_empty();
        // The first surface is not specular: a light then reached through a
        // specular bounce is a caustic that light paths bring in.
        let mut first_surface_not_specular = false;
        // Against the connections by way of specular balls (see `ball_connection`).
        let mut passage = Passage::None;
        let balls = BALLS;
        // Every surface so far was a mirror or glass: the camera sees the
        // current one only through them.
        let mut specular_chain = true;
        // The surface the current ray leaves, which it cannot hit again.
        let mut leaving = Leaving::Nothing;
        // The mirror ball the camera ray reflected off, and that ray, while
        // lens connections may reach what it finds next.
        let mut off_ball_from_lens: Option<(usize, Ray)> = None;

        for bounce in 0.. {
            let draws = BounceDraws::new(sampler, light_sampling, scene.lights.len() > 1);
            let found = match balls {
                true => scene.intersect_leaving(&ray, f64::INFINITY, leaving),
                false => scene.intersect_leaving_inlined(traversal, &ray, f64::INFINITY, leaving),
            };
            let Some(intersection) = found else {
                radiance += throughput * C::from_rgb(scene.background, wavelengths);
                break;
            };
            let hit = intersection.hit;
            let material = scene.material_of(intersection.primitive);
            let wo_world = -ray.direction;

            // Emission found by the BSDF sample, weighted against light sampling.
            if let Some(emitted) = material.emission_towards(hit.geometric_normal.dot(wo_world)) {
                let weight = match scene.lights.light_of_primitive(intersection.primitive) {
                    Some(_) if self.caustics_by_light_paths && specular_bounce && first_surface_not_specular => 0.0,
                    Some(_) if passage.claims(scene, hit.point) => 0.0,
                    Some(light) if light_sampling && !specular_bounce => {
                        let light_pdf = scene
                            .lights
                            .pdf(scene, light, previous_point, hit.point, hit.geometric_normal);
                        power_heuristic(previous_pdf, light_pdf)
                    }
                    Some(light) if balls && bounce == 1 => self.camera_share(scene, off_ball_from_lens, light, &hit),
                    _ => 1.0,
                };
                radiance += throughput * C::emission(emitted, wavelengths) * weight;
            }
            if !material.scatters() || bounce >= self.max_depth {
                break;
            }
            if bounce == 0 {
                first_surface_not_specular = !material.is_specular();
                if balls && self.lens_connections.is_some() {
                    let off_ball = scene
                        .specular_balls()
                        .iter()
                        .position(|ball| ball.primitive == intersection.primitive && ball.bounce == Bounce::Off);
                    off_ball_from_lens = off_ball.map(|ball| (ball, ray));
                }
            }

            let here = scene.leaving(intersection.primitive);
            let frame = ShadingFrame::from_normal(hit.shading_normal);
            let wo = frame.to_local(wo_world);
            let at = ShadingPoint {
                uv: hit.uv,
                point: hit.point,
            };

            // The BSDF sample that continues the path, made before the light
            // sample: it does not depend on it, so its arithmetic overlaps
            // the shadow ray's traversal instead of following it.
            let (u, u_lobe) = bsdf_inputs_drawn(material, draws.direction, draws.lobe, sampler);
            let bsdf_sample = C::sample_bsdf(material, wo, &at, u, u_lobe, Transport::Radiance, wavelengths);

            // Next-event estimation: one light sample, MIS-weighted.
            let mut connected_by_balls = false;
            if light_sampling && !material.is_specular() {
                // With one light there is nothing to select: no draw.
                let u_select = draws.light_choice.map_or(0.5, |draw| sampler.draw_1d(draw));
                let u_light = draws.light_point;
                // And through glass balls and off mirror balls, with the
                // same numbers, at the first surface that is not specular
                // (where the rest of the path is most often light focused
                // by a ball), unless
                // that is the first surface and light paths bring in its
                // caustics, or the path's depth leaves no room for the
                // vertices it adds.
                let first_diffuse = specular_chain && !(self.caustics_by_light_paths && bounce == 0);
                if balls && first_diffuse && bounce + 3 <= self.max_depth {
                    connected_by_balls = true;
                    let through: C = radiance_by_balls(scene, &hit, &frame, material, wo, &at, (u_select, u_light), wavelengths);
                    radiance += throughput * through;
                }
                if let Some(light) = scene.lights.sample(scene, hit.point, u_select, u_light) {
                    let wi = frame.to_local(light.wi);
                    let f = material.eval(wo, wi, &at) * wi.z.abs();
                    if f != Color::ZERO {
                        // The light sample's direction is unit already (to within the
                        // point's error over its distance): normalising it again
                        // (`Ray::spawn`) would put a square root and a division
                        // between the sample and the shadow ray's traversal, and
                        // along it the point lies at t = `light.distance`.
                        let shadow = Ray {
                            origin: offset_ray_origin(hit.point, hit.point_error, hit.geometric_normal, light.wi),
                            direction: light.wi,
                        };
                        // Stop short of the light by far more than its point error,
                        // from the light sample's own distance less the origin's
                        // offset: both bounded by 1-norms, which are no smaller
                        // than lengths and need no square root. So the segment
                        // ends no later than |light − origin| − |error| would.
                        let offset = (shadow.origin - hit.point).abs().element_sum();
                        let t_max = light.distance * (1.0 - 1e-9) - light.point_error.abs().element_sum() - offset;
                        let to = scene.leaving(light.primitive);
                        let occluded = match balls {
                            true => scene.occluded_between(&shadow, t_max, here, to),
                            false => scene.occluded_between_inlined(traversal, &shadow, t_max, here, to),
                        };
                        if !occluded {
                            let weight = power_heuristic(light.pdf, material.pdf(wo, wi));
                            let f = C::from_rgb(f, wavelengths);
                            radiance += throughput * f * C::emission(light.emission, wavelengths) * (weight / light.pdf);
                        }
                    }
                }
            }

            specular_chain &= material.is_specular();

            // Continue the path by the BSDF sample.
            let Some(sample) = bsdf_sample else {
                break;
            };
            throughput *= C::from_rgb(sample.weight, wavelengths);
            if throughput == C::ZERO {
                break;
            }
            specular_bounce = sample.specular;
            eta_scale *= sample.eta * sample.eta;
            previous_pdf = sample.pdf;
            previous_point = hit.point;
            let direction = frame.to_world(sample.wi);
            ray = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, direction);
            leaving = here;
            if balls {
                passage = match connected_by_balls {
                    true => Passage::Left(Departure {
                        from: hit.point,
                        direction: ray.direction,
                    }),
                    false => passage.after(
                        scene,
                        intersection.primitive,
                        wo_world.dot(hit.geometric_normal) > 0.0,
                        sample.eta != 1.0,
                    ),
                };
            }

            // Russian roulette on the throughput, not counting glass's 1/η²
            // (Veach 1997 §5.2): inside a ball a third of the paths would die
            // for the rest to come out with 1.5 times the weight.
            if bounce + 1 < ROULETTE_START {
                sampler.skip(); // the roulette's dimension, unused
            } else {
                let survival = survival_probability(throughput.max_component() * eta_scale);
                if sampler.next_1d_independent() >= survival {
                    break;
                }
                throughput /= survival;
            }
        }
        radiance
    }

    /// The weight of emission from `light` found at `hit` by a camera ray
    /// that reflected off the mirror ball `off_ball` (with the camera ray),
    /// against the lens connections; 1 for every other path.
    fn camera_share(&self, scene: &Scene, off_ball: Option<(usize, Ray)>, light: u32, hit: &SurfaceHit) -> f64 {
        match (&self.lens_connections, off_ball) {
            (Some(view), Some((ball, ray))) => view.camera_share(
                scene,
                &scene.specular_balls()[ball],
                &ray,
                light,
                hit.point,
                hit.geometric_normal,
            ),
            _ => 1.0,
        }
    }
}
