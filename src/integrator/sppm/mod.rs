//! Stochastic progressive photon mapping (Hachisuka & Jensen 2009).
//!
//! Each iteration (one `render_pass`):
//! 1. camera pass: one jittered path per pixel through specular bounces to a
//!    visible point ([`visible_point`]);
//! 2. a hash grid over the visible points' gather spheres ([`grid`]);
//! 3. photon pass: photons from the lights, each adding its BSDF-weighted
//!    flux to every visible point whose sphere contains it ([`photon`]);
//! 4. per-pixel progressive radius reduction ([`statistics`]).
//!
//! The image is τ / (π R² · photons emitted) plus the emission camera paths
//! saw along their specular chains, averaged over iterations (with a few
//! extra camera paths per iteration for that cheap term). All light
//! reflected diffusely (direct lighting included) comes from photons: the
//! classic form, consistent as R → 0. A non-black background is a light
//! like any other: seen directly and through glass by camera paths, and a
//! source of photons from every direction ([`photon::PhotonSources`]).
//!
//! Every sample is seeded by (pixel or photon index, iteration, seed), so the
//! image does not depend on which thread traced what, up to the summation
//! order of the lock-free flux tallies.

pub mod grid;
pub mod photon;
pub mod settings;
pub mod statistics;
pub mod visible_point;

pub use settings::SppmSettings;

use super::Integrator;
use super::path::camera_ray;
use crate::camera::Camera;
use crate::film::Frame;
use crate::math::DVec3;
use crate::sampler::{Sampler, SamplerKind};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use grid::VisiblePointGrid;
use photon::PhotonSources;
use rayon::prelude::*;
use statistics::{PhotonTally, PixelStatistics};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};
use visible_point::{VisiblePoint, trace_camera_path};

/// Mixed into the seed of photon streams so they never share a stream with
/// the camera paths of the same index and iteration.
const PHOTON_SEED: u64 = 0x5eed_0f94_0705_eed1;

/// Camera paths per pixel and iteration for the emitted term (lights seen
/// directly or through glass and mirrors). Only the first leaves a visible
/// point; the others are cheap (they stop at the first diffuse surface) and
/// cut the noise of small, bright light images, which would otherwise get
/// only one sample per photon pass.
const EMISSION_SAMPLES: u32 = 4;

/// Mixed into the seed of the extra emission paths' streams.
const EMISSION_SEED: u64 = 0xe4e5_5101_7a11_c0de;

/// Automatic initial radius, in pixel footprints at the visible point: about
/// π·1.5² ≈ 7 pixels' worth of surface, enough photons per gather at the
/// default photon count to keep the first iterations from being blotchy.
const INITIAL_RADIUS_PIXELS: f64 = 1.5;

/// Least cosine between the geometric normals of a visible point and a photon
/// hit for the photon to count: rejects photons on another surface that
/// happens to lie within the radius (the far side of a thin wall, the other
/// wall at a corner). Smooth surfaces agree ever better as the radius shrinks.
const NORMAL_AGREEMENT: f64 = 0.5;

/// The scale photon tallies count in: the total emitted power (shapes and
/// sky), about one photon's flux, so fixed-point sums keep the same relative
/// precision in any scene's units.
fn flux_unit(sources: &PhotonSources) -> f64 {
    sources.total_power().max(f64::MIN_POSITIVE)
}

/// The radius a pixel starts with: the absolute setting, or a few pixel
/// footprints at the distance its first camera path travelled.
struct InitialRadius {
    absolute: Option<f64>,
    /// Angle one pixel subtends (small-angle approximation of its footprint).
    pixel_angle: f64,
}

impl InitialRadius {
    fn new(parameters: &SppmSettings, camera: &Camera, height: u32) -> Self {
        Self {
            absolute: parameters.initial_radius,
            pixel_angle: 2.0 * (camera.fov_y_degrees.to_radians() * 0.5).tan() / height as f64,
        }
    }

    fn at_distance(&self, path_length: f64) -> f64 {
        self.absolute
            .unwrap_or((INITIAL_RADIUS_PIXELS * self.pixel_angle * path_length).max(1e-9))
    }
}

/// Progressive SPPM into per-pixel statistics.
pub struct SppmIntegrator {
    settings: RenderSettings,
    parameters: SppmSettings,
    max_depth: u32,
    sampler: SamplerKind,
    seed: u64,
    width: u32,
    height: u32,
    pixels: Vec<PixelStatistics>,
    tallies: Vec<PhotonTally>,
    iterations: u32,
    rejected: u64,
    photon_time: Duration,
    total_time: Duration,
}

impl SppmIntegrator {
    pub fn new(settings: &RenderSettings) -> Self {
        let count = settings.pixel_count();
        Self {
            settings: settings.clone(),
            parameters: settings.sppm,
            max_depth: settings.max_depth,
            sampler: settings.sampler,
            seed: settings.seed,
            width: settings.width,
            height: settings.height,
            pixels: vec![PixelStatistics::default(); count],
            tallies: (0..count).map(|_| PhotonTally::default()).collect(),
            iterations: 0,
            rejected: 0,
            photon_time: Duration::ZERO,
            total_time: Duration::ZERO,
        }
    }

    /// Current gather radius per pixel, row-major (0 where no visible point
    /// has been found yet), for a heatmap.
    pub fn radii(&self) -> Vec<f32> {
        self.pixels.iter().map(|p| p.radius as f32).collect()
    }

    /// Mean radius over pixels that have one.
    pub fn mean_radius(&self) -> f64 {
        let (sum, count) = self
            .pixels
            .iter()
            .filter(|p| p.radius > 0.0)
            .fold((0.0, 0usize), |(s, n), p| (s + p.radius, n + 1));
        if count == 0 { 0.0 } else { sum / count as f64 }
    }

    /// Photons traced per second of photon pass, and iterations per second
    /// of whole passes, so far.
    pub fn throughput(&self) -> (f64, f64) {
        let photons = self.iterations as f64 * self.parameters.photons_per_iteration as f64;
        (
            photons / self.photon_time.as_secs_f64().max(1e-9),
            self.iterations as f64 / self.total_time.as_secs_f64().max(1e-9),
        )
    }

    /// Step 1: one camera path per pixel; records emission and returns the
    /// visible points. Pixels get their initial radius at their first one.
    fn camera_pass(&mut self, scene: &Scene, camera: &Camera, cancel: &AtomicBool) -> Vec<Option<VisiblePoint>> {
        let (kind, seed, iteration, max_depth) = (self.sampler, self.seed, self.iterations, self.max_depth);
        let size = (self.width, self.height);
        let initial_radius = InitialRadius::new(&self.parameters, camera, self.height);
        let sampled = self.settings.sampled_pixels();
        let rejected = AtomicU64::new(0);
        let visible: Vec<Option<VisiblePoint>> = self
            .pixels
            .par_iter_mut()
            .enumerate()
            .map(|(index, pixel)| {
                if cancel.load(Ordering::Relaxed) {
                    return None;
                }
                let (x, y) = (index as u32 % size.0, index as u32 / size.0);
                if !sampled.contains(x, y) {
                    return None;
                }
                let mut sampler = Sampler::new(kind, index as u64, iteration, seed);
                let ray = camera_ray(camera, size, x, y, &mut sampler);
                let path = trace_camera_path(scene, ray, &mut sampler, max_depth);
                // The emitted term: this path and a few more, from their own
                // Sobol' stream so each stream stays stratified over iterations.
                let mut emitted = path.emitted;
                for extra in 0..EMISSION_SAMPLES - 1 {
                    let mut sampler = Sampler::new(
                        kind,
                        index as u64,
                        iteration * (EMISSION_SAMPLES - 1) + extra,
                        seed ^ EMISSION_SEED,
                    );
                    let ray = camera_ray(camera, size, x, y, &mut sampler);
                    emitted += trace_camera_path(scene, ray, &mut sampler, max_depth).emitted;
                }
                let emitted = emitted / EMISSION_SAMPLES as f64;
                if emitted.is_finite() {
                    pixel.emitted_sum += emitted;
                } else {
                    rejected.fetch_add(1, Ordering::Relaxed);
                }
                let visible_point = path.visible_point.filter(|vp| vp.throughput.is_finite());
                if pixel.radius == 0.0 {
                    pixel.radius = visible_point
                        .as_ref()
                        .map_or(0.0, |vp| initial_radius.at_distance(vp.path_length));
                }
                visible_point
            })
            .collect();
        self.rejected += rejected.into_inner();
        visible
    }

    /// Step 3: traces this iteration's photons in parallel, adding to the
    /// tallies of the visible points they land near. Returns false if cancelled.
    fn photon_pass(
        &self,
        scene: &Scene,
        sources: &PhotonSources,
        visible: &[Option<VisiblePoint>],
        grid: &VisiblePointGrid,
        cancel: &AtomicBool,
    ) -> bool {
        let (kind, iteration, max_depth) = (self.sampler, self.iterations, self.max_depth);
        let seed = self.seed ^ PHOTON_SEED;
        let inverse_unit = 1.0 / flux_unit(sources);
        (0..self.parameters.photons_per_iteration)
            .into_par_iter()
            .with_min_len(64)
            .for_each(|index| {
                if cancel.load(Ordering::Relaxed) {
                    return;
                }
                let mut sampler = Sampler::new(kind, index as u64, iteration, seed);
                let Some(emitted) = sources.emit(scene, &mut sampler) else {
                    return;
                };
                photon::trace(scene, emitted, &mut sampler, max_depth, |hit, towards_light, flux| {
                    for &pixel in grid.candidates(hit.point) {
                        let Some(vp) = &visible[pixel as usize] else {
                            continue;
                        };
                        let radius = self.pixels[pixel as usize].radius;
                        if (vp.point - hit.point).length_squared() > radius * radius
                            || vp.geometric_normal.dot(hit.geometric_normal) < NORMAL_AGREEMENT
                            || towards_light.dot(vp.geometric_normal).signum() != vp.side()
                        {
                            continue;
                        }
                        let material = &scene.materials[vp.material as usize];
                        let f = material.eval(vp.wo, vp.frame.to_local(towards_light), &vp.at);
                        self.tallies[pixel as usize].add(flux * f, inverse_unit);
                    }
                });
            });
        !cancel.load(Ordering::Relaxed)
    }

    /// Step 4: folds each pixel's tally into its statistics.
    fn update_statistics(&mut self, sources: &PhotonSources, visible: &[Option<VisiblePoint>]) {
        let alpha = self.parameters.alpha;
        let unit = flux_unit(sources);
        let rejected = AtomicU64::new(0);
        self.pixels
            .par_iter_mut()
            .zip(self.tallies.par_iter_mut())
            .zip(visible.par_iter())
            .for_each(|((pixel, tally), vp)| {
                let (flux, count) = tally.take(unit);
                let Some(vp) = vp else { return };
                let flux = vp.throughput * flux;
                if flux.is_finite() {
                    pixel.add_photons(flux, count, alpha);
                } else {
                    rejected.fetch_add(1, Ordering::Relaxed);
                }
            });
        self.rejected += rejected.into_inner();
    }

    fn clear_tallies(&mut self) {
        self.tallies.par_iter_mut().for_each(|t| {
            t.take(1.0);
        });
    }
}

impl Integrator for SppmIntegrator {
    fn render_pass(&mut self, scene: &Scene, camera: &Camera, cancel: &AtomicBool) -> bool {
        let start = Instant::now();
        let visible = self.camera_pass(scene, camera, cancel);
        if cancel.load(Ordering::Relaxed) {
            return false;
        }
        let points: Vec<(u32, DVec3, f64)> = visible
            .par_iter()
            .enumerate()
            .filter_map(|(index, vp)| vp.as_ref().map(|vp| (index as u32, vp.point, self.pixels[index].radius)))
            .collect();
        let grid = VisiblePointGrid::build(&points);
        let photons_start = Instant::now();
        let sources = PhotonSources::new(scene);
        if !self.photon_pass(scene, &sources, &visible, &grid, cancel) {
            self.clear_tallies();
            return false;
        }
        self.photon_time += photons_start.elapsed();
        self.update_statistics(&sources, &visible);
        self.iterations += 1;
        self.total_time += start.elapsed();
        true
    }

    fn passes(&self) -> u32 {
        self.iterations
    }

    fn frame(&self) -> Frame {
        let (iterations, photons) = (self.iterations, self.parameters.photons_per_iteration);
        Frame {
            width: self.width,
            height: self.height,
            pixels: self
                .pixels
                .iter()
                .map(|p| p.radiance(iterations, photons).as_vec3().to_array())
                .collect(),
            noise: Vec::new(),
        }
    }

    fn rejected_samples(&self) -> u64 {
        self.rejected
    }

    /// An iteration costs its photons whatever the resolution, so a preview
    /// scales them with the pixels (keeping at least a thousand).
    fn preview(&self, divisor: u32) -> Box<dyn Integrator> {
        let mut settings = super::reduced_resolution(&self.settings, divisor);
        settings.sppm.photons_per_iteration = (settings.sppm.photons_per_iteration / (divisor * divisor).max(1)).max(1000);
        Box::new(Self::new(&settings))
    }

    fn gather_radii(&self) -> Option<Vec<f32>> {
        Some(self.radii())
    }

    fn estimates_noise(&self) -> bool {
        false
    }

    fn status(&self) -> String {
        let (photons_per_second, iterations_per_second) = self.throughput();
        format!(
            "mean radius {:.3e}, {:.2} Mphotons/s, {:.2} iterations/s",
            self.mean_radius(),
            photons_per_second / 1e6,
            iterations_per_second
        )
    }
}
