//! Iterative path tracing (Kajiya 1986) with next-event estimation and
//! multiple importance sampling by the power heuristic (Veach 1997, ch. 9),
//! and Russian roulette; or, in BSDF-only mode, the original's estimator
//! that adds emission only where BSDF-sampled paths happen to hit it.

use super::Integrator;
use crate::camera::Camera;
use crate::color::Color;
use crate::film::{Film, Frame};
use crate::material::{ShadingPoint, Transport};
use crate::math::{Frame as ShadingFrame, Ray, max_component, warp::power_heuristic};
use crate::render::pass;
use crate::render::settings::{IntegratorKind, RenderSettings};
use crate::sampler::{Sampler, SamplerKind};
use crate::scene::Scene;
use glam::DVec2;
use rayon::prelude::*;
use std::sync::atomic::AtomicBool;

/// Bounces before Russian roulette may end a path.
const ROULETTE_START: u32 = 3;

/// Options of the per-sample tracer.
#[derive(Clone, Copy, Debug)]
pub struct PathTracer {
    pub max_depth: u32,
    /// Sample lights directly and weight by MIS (false: BSDF sampling only).
    pub light_sampling: bool,
}

impl PathTracer {
    pub fn from_settings(settings: &RenderSettings) -> Self {
        Self {
            max_depth: settings.max_depth,
            light_sampling: settings.integrator != IntegratorKind::BsdfOnly,
        }
    }

    /// Radiance arriving along `ray` (the Li of the rendering equation).
    pub fn radiance(&self, scene: &Scene, mut ray: Ray, sampler: &mut Sampler) -> Color {
        let mut radiance = Color::ZERO;
        let mut throughput = Color::ONE;
        let mut specular_bounce = true;
        let mut previous_pdf = 0.0;
        let mut previous_point = ray.origin;
        let light_sampling = self.light_sampling && !scene.lights.is_empty();

        for bounce in 0.. {
            let Some(intersection) = scene.intersect(&ray, f64::INFINITY) else {
                radiance += throughput * scene.background;
                break;
            };
            let hit = intersection.hit;
            let material = scene.material_of(intersection.primitive);
            let wo_world = -ray.direction;

            // Emission found by the BSDF sample, weighted against light sampling.
            if material.emission().is_some() {
                let emitted = material.emitted(hit.geometric_normal.dot(wo_world));
                if emitted != Color::ZERO {
                    let weight = match scene.lights.light_of_primitive(intersection.primitive as usize) {
                        Some(light) if light_sampling && !specular_bounce => {
                            let light_pdf = scene.lights.pdf(&scene.primitives, light, previous_point, &hit);
                            power_heuristic(previous_pdf, light_pdf)
                        }
                        _ => 1.0,
                    };
                    radiance += throughput * emitted * weight;
                }
            }
            if !material.scatters() || bounce >= self.max_depth {
                break;
            }

            let frame = ShadingFrame::from_normal(hit.shading_normal);
            let wo = frame.to_local(wo_world);
            let at = ShadingPoint {
                uv: hit.uv,
                point: hit.point,
            };

            // Next-event estimation: one light sample, MIS-weighted.
            if light_sampling && !material.is_specular() {
                let u_select = sampler.next_1d();
                let u_light = sampler.next_2d();
                if let Some(light) = scene.lights.sample(&scene.primitives, hit.point, u_select, u_light) {
                    let wi = frame.to_local(light.wi);
                    let f = material.eval(wo, wi, &at) * wi.z.abs();
                    if f != Color::ZERO {
                        let shadow = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, light.wi);
                        let distance = (light.point - shadow.origin).length();
                        // Stop short of the light by far more than its point error.
                        let t_max = distance * (1.0 - 1e-9) - light.point_error.length();
                        if !scene.occluded(&shadow, t_max) {
                            let weight = power_heuristic(light.pdf, material.pdf(wo, wi));
                            radiance += throughput * f * light.radiance * (weight / light.pdf);
                        }
                    }
                }
            }

            // Continue the path by sampling the BSDF.
            let u = sampler.next_2d();
            let u_lobe = sampler.next_1d();
            let Some(sample) = material.sample(wo, &at, u, u_lobe, Transport::Radiance) else {
                break;
            };
            throughput *= sample.weight;
            if throughput == Color::ZERO {
                break;
            }
            specular_bounce = sample.specular;
            previous_pdf = sample.pdf;
            previous_point = hit.point;
            ray = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, frame.to_world(sample.wi));

            // Russian roulette: survive with probability ~ throughput.
            if bounce + 1 >= ROULETTE_START {
                let survival = max_component(throughput).min(0.95);
                if sampler.next_1d() >= survival {
                    break;
                }
                throughput /= survival;
            }
        }
        radiance
    }
}

/// Progressive path tracing into a film, one sample per pixel per pass.
pub struct PathIntegrator {
    tracer: PathTracer,
    sampler: SamplerKind,
    seed: u64,
    film: Film,
    passes: u32,
    adaptive_threshold: Option<f64>,
    /// Every pixel has met the adaptive threshold (see `Integrator::converged`).
    converged: bool,
}

impl PathIntegrator {
    pub fn new(settings: &RenderSettings) -> Self {
        Self {
            tracer: PathTracer::from_settings(settings),
            sampler: settings.sampler,
            seed: settings.seed,
            film: Film::new(settings.width, settings.height),
            passes: 0,
            adaptive_threshold: settings.adaptive_threshold,
            converged: false,
        }
    }

    pub fn film(&self) -> &Film {
        &self.film
    }
}

/// The camera ray of one pixel sample; consumes the sampler's first two
/// dimensions (film position within the pixel: a box filter, and lens).
pub fn camera_ray(camera: &Camera, (width, height): (u32, u32), x: u32, y: u32, sampler: &mut Sampler) -> Ray {
    let jitter = sampler.next_2d();
    let lens = sampler.next_2d();
    let film_point = DVec2::new((x as f64 + jitter.x) / width as f64, (y as f64 + jitter.y) / height as f64);
    camera.generate_ray(film_point, width as f64 / height as f64, lens)
}

impl Integrator for PathIntegrator {
    fn render_pass(&mut self, scene: &Scene, camera: &Camera, cancel: &AtomicBool) -> bool {
        let sample_index = self.passes;
        let (tracer, kind, seed) = (self.tracer, self.sampler, self.seed);
        let size = (self.film.width, self.film.height);
        let completed = pass::add_samples_adaptive(&mut self.film, cancel, self.adaptive_threshold, |x, y| {
            let mut sampler = Sampler::new(kind, y as u64 * size.0 as u64 + x as u64, sample_index, seed);
            let ray = camera_ray(camera, size, x, y, &mut sampler);
            tracer.radiance(scene, ray, &mut sampler)
        });
        if completed {
            self.passes += 1;
            // A stopped pixel stays stopped (its state no longer changes), so
            // once all are, every later pass would be empty.
            self.converged = self
                .adaptive_threshold
                .is_some_and(|threshold| self.film.pixels.par_iter().all(|p| pass::is_converged(p, threshold)));
        }
        completed
    }

    fn converged(&self) -> bool {
        self.converged
    }

    fn passes(&self) -> u32 {
        self.passes
    }

    fn frame(&self) -> Frame {
        self.film.frame()
    }

    fn rejected_samples(&self) -> u64 {
        self.film.rejected_samples
    }

    fn status(&self) -> String {
        match self.adaptive_threshold {
            Some(_) if self.converged => "adaptive: converged, 0% of pixels active".to_string(),
            Some(threshold) => {
                let converged = self.film.pixels.iter().filter(|p| pass::is_converged(p, threshold)).count();
                let active = 100.0 * (1.0 - converged as f64 / self.film.pixels.len().max(1) as f64);
                format!("adaptive: {active:.0}% of pixels active")
            }
            None => String::new(),
        }
    }
}
