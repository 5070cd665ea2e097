//! Stochastic progressive photon mapping (Hachisuka & Jensen 2009).
//!
//! Each iteration (one `render_pass`):
//! 1. camera pass: one jittered path per pixel through specular bounces to a
//!    visible point ([`visible_point`]);
//! 2. a hash grid over the visible points' gather spheres ([`grid`]);
//! 3. photon pass: photons from the lights, each adding its BSDF-weighted
//!    flux to every visible point whose sphere contains it ([`photon`]);
//! 4. the estimate: by default, per-pixel progressive radius reduction
//!    ([`statistics`]); with the global radius schedule ([`radius`]), the
//!    iteration's own estimate added to a film.
//!
//! With the per-pixel schedule (Hachisuka & Jensen) the image is
//! τ / (π R² · photons emitted) plus the emission camera paths saw along
//! their specular chains, averaged over iterations (with a few extra camera
//! paths per iteration for that cheap term, in the pixels that may see
//! emission: [`emission_paths`]). With the global schedule
//! (Knaus & Zwicker 2011) every iteration i is a complete estimate, emission
//! plus Φᵢ / (π rᵢ² · photons per iteration), and the image is their mean:
//! iterations are independent, so a range of them renders on any machine and
//! the ranges' films merge exactly (`crate::farm`). All light
//! reflected diffusely (direct lighting included) comes from photons: the
//! classic form, consistent as R → 0. A non-black background is a light
//! like any other: seen directly and through glass by camera paths, and a
//! source of photons from every direction ([`photon::PhotonSources`]).
//!
//! Every sample is seeded by (pixel or photon index, iteration, seed), so the
//! image does not depend on which thread traced what; the lock-free flux
//! tallies add in fixed point, so their order does not matter either.
//!
//! Spectral mode (asked for, or forced by dispersive glass) is the same
//! algorithm over [`SampledSpectrum`]: every camera path and every photon
//! draws its own hero wavelengths, and a photon's contribution at a visible
//! point (flux times the visible point's BSDF, both at the photon's
//! wavelengths) enters the pixel's tally as film RGB.

pub mod emission_paths;
pub mod grid;
pub mod photon;
pub mod radius;
pub mod settings;
pub mod statistics;
pub mod visible_point;

pub use settings::{RadiusSchedule, SppmSettings};

use super::path::camera_ray;
use super::{Integrator, Share};
use crate::accel::Avx2;
use crate::camera::Camera;
use crate::color::Color;
use crate::film::{Film, Frame};
use crate::sampler::{Sampler, SamplerKind};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::spectrum::{Radiance, SampledSpectrum};
use grid::{GridPoint, VisiblePointGrid};
use photon::PhotonSources;
use radius::{InitialRadius, global_area_scale};
use rayon::prelude::*;
use statistics::{PhotonTally, PixelStatistics};
use std::f64::consts::PI;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};
use visible_point::{VisiblePoint, trace_camera_path, trace_emission_path};

/// Mixed into the seed of photon streams so they never share a stream with
/// the camera paths of the same index and iteration.
const PHOTON_SEED: u64 = 0x5eed_0f94_0705_eed1;

/// Camera paths per pixel and iteration for the emitted term (lights seen
/// directly or through glass and mirrors) where a pixel may see emission
/// ([`emission_paths`]; elsewhere one). Only the first leaves a visible
/// point; the others are cheap (they stop at the first diffuse surface) and
/// cut the noise of small, bright light images, which would otherwise get
/// only one sample per photon pass.
const EMISSION_SAMPLES: u32 = 4;

/// Mixed into the seed of the extra emission paths' streams.
const EMISSION_SEED: u64 = 0xe4e5_5101_7a11_c0de;

/// Most camera paths (pixels) and photons one parallel job traces, so a
/// pass does not end on one thread's long last piece (see
/// `integrator::pass`): pixels behind glass, and photons through it, cost
/// many times the rest.
const PIXELS_PER_JOB: usize = 256;
const PHOTONS_PER_JOB: usize = 1024;

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

/// What the iterations have gathered, by radius schedule.
enum Estimate {
    /// Per-pixel schedule: Hachisuka & Jensen's statistics (N, R, τ).
    Progressive(Vec<PixelStatistics>),
    /// Global schedule: each iteration's estimate, one sample per pixel, and
    /// the radii of the latest iteration (for the heatmap).
    Independent { film: Film, radii: Vec<f64> },
}

/// One pixel's camera pass: its visible point, and the emission its camera
/// paths saw (`None` if that came out NaN or infinite); pixels outside the
/// sampled region (the viewer's region render) are not sampled at all.
#[derive(Clone, Copy, Debug)]
struct CameraSample {
    sampled: bool,
    visible: Option<VisiblePoint>,
    emitted: Option<Color>,
}

impl CameraSample {
    const SKIPPED: CameraSample = CameraSample {
        sampled: false,
        visible: None,
        emitted: None,
    };
}

/// Progressive SPPM.
pub struct SppmIntegrator {
    settings: RenderSettings,
    parameters: SppmSettings,
    max_depth: u32,
    sampler: SamplerKind,
    seed: u64,
    width: u32,
    height: u32,
    estimate: Estimate,
    tallies: Vec<PhotonTally>,
    /// The camera pass's results, one per pixel, kept between iterations so
    /// that each pass overwrites them instead of allocating.
    samples: Vec<CameraSample>,
    /// The grid over the gather spheres, rebuilt in place every iteration.
    grid: VisiblePointGrid,
    /// Per pixel, whether its footprint may see emission, so that it traces
    /// `EMISSION_SAMPLES` camera paths for the emitted term rather than one;
    /// found at the first iteration (a new camera starts a new render).
    may_see_emission: Vec<bool>,
    /// Index of the first iteration (a farm share may start past 0).
    first_iteration: u32,
    iterations: u32,
    rejected: u64,
    photon_time: Duration,
    total_time: Duration,
}

impl SppmIntegrator {
    /// An SPPM render of the whole image, iterations from 0.
    pub fn new(settings: &RenderSettings) -> Self {
        Self::with_share(settings, &Share::whole(settings.samples_per_pixel.unwrap_or(0)))
    }

    /// Renders iterations `share.samples` (SPPM samples whole images, so the
    /// share's rows are not used: a farm splits SPPM by iterations).
    pub fn with_share(settings: &RenderSettings, share: &Share) -> Self {
        let count = settings.pixel_count();
        let estimate = match settings.sppm.radius_schedule {
            RadiusSchedule::PerPixel => Estimate::Progressive(vec![PixelStatistics::default(); count]),
            RadiusSchedule::Global => Estimate::Independent {
                film: Film::new(settings.width, settings.height),
                radii: vec![0.0; count],
            },
        };
        Self {
            settings: settings.clone(),
            parameters: settings.sppm,
            max_depth: settings.max_depth,
            sampler: settings.sampler,
            seed: settings.seed,
            width: settings.width,
            height: settings.height,
            estimate,
            tallies: (0..count).map(|_| PhotonTally::default()).collect(),
            samples: vec![CameraSample::SKIPPED; count],
            grid: VisiblePointGrid::default(),
            may_see_emission: Vec::new(),
            first_iteration: share.samples.start,
            iterations: 0,
            rejected: 0,
            photon_time: Duration::ZERO,
            total_time: Duration::ZERO,
        }
    }

    /// Current gather radius per pixel, row-major (0 where no visible point
    /// has been found yet), for a heatmap.
    pub fn radii(&self) -> Vec<f32> {
        match &self.estimate {
            Estimate::Progressive(pixels) => pixels.iter().map(|p| p.radius as f32).collect(),
            Estimate::Independent { radii, .. } => radii.iter().map(|&r| r as f32).collect(),
        }
    }

    /// Mean radius over pixels that have one.
    pub fn mean_radius(&self) -> f64 {
        let (sum, count) = self
            .radii()
            .into_iter()
            .filter(|&r| r > 0.0)
            .fold((0.0, 0usize), |(s, n), r| (s + r as f64, n + 1));
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

    /// The index of the iteration being rendered (seeds its samples).
    fn iteration(&self) -> u32 {
        self.first_iteration + self.iterations
    }

    /// Step 1: one camera path per pixel (and a few more for the emitted
    /// term) from the iteration's sample streams, into `samples` (one per pixel).
    fn camera_pass<C: Radiance>(&self, scene: &Scene, camera: &Camera, cancel: &AtomicBool, samples: &mut [CameraSample]) {
        let (kind, seed, iteration, max_depth) = (self.sampler, self.seed, self.iteration(), self.max_depth);
        let size = (self.width, self.height);
        let sampled = self.settings.sampled_pixels();
        let sample_pixel = |index: usize| {
            let (x, y) = (index as u32 % size.0, index as u32 / size.0);
            if cancel.load(Ordering::Relaxed) || !sampled.contains(x, y) {
                return CameraSample::SKIPPED;
            }
            let mut sampler = Sampler::new(kind, index as u64, iteration, seed);
            let ray = camera_ray(camera, size, x, y, &mut sampler);
            let path = trace_camera_path::<C>(scene, ray, &mut sampler, max_depth);
            // The emitted term: this path and a few more, from their own
            // Sobol' stream so each stream stays stratified over iterations.
            let mut emitted = path.emitted;
            let paths = match self.may_see_emission.get(index) {
                Some(false) => 1,
                _ => EMISSION_SAMPLES,
            };
            for extra in 0..paths - 1 {
                let mut sampler = Sampler::new(
                    kind,
                    index as u64,
                    iteration * (EMISSION_SAMPLES - 1) + extra,
                    seed ^ EMISSION_SEED,
                );
                let ray = camera_ray(camera, size, x, y, &mut sampler);
                emitted += trace_emission_path::<C>(scene, ray, &mut sampler, max_depth);
            }
            let emitted = emitted / paths as f64;
            CameraSample {
                sampled: true,
                visible: path.visible_point.filter(|vp| vp.throughput.is_finite()),
                emitted: emitted.is_finite().then_some(emitted),
            }
        };
        samples
            .par_iter_mut()
            .enumerate()
            .with_max_len(PIXELS_PER_JOB)
            .for_each(|(index, slot)| *slot = sample_pixel(index));
    }

    /// Step 1, continued: each pixel's gather radius for this iteration. The
    /// per-pixel schedule records the emission and starts a pixel's radius at
    /// its first visible point; the global one scales each visible point's
    /// start radius by the iteration's factor.
    fn radii_for_iteration(&mut self, camera: &Camera, samples: &[CameraSample]) -> Vec<f64> {
        let initial_radius = InitialRadius::new(&self.parameters, camera, self.height);
        let linear_scale = global_area_scale(self.iteration(), self.parameters.alpha).sqrt();
        match &mut self.estimate {
            Estimate::Progressive(pixels) => {
                // Sampled pixels whose emitted term was not finite (the global
                // schedule counts them as it adds to its film).
                self.rejected += samples.par_iter().filter(|s| s.sampled && s.emitted.is_none()).count() as u64;
                pixels
                    .par_iter_mut()
                    .zip(samples.par_iter())
                    .map(|(pixel, sample)| {
                        if let Some(emitted) = sample.emitted {
                            pixel.emitted_sum += emitted;
                        }
                        if pixel.radius == 0.0 {
                            pixel.radius = sample
                                .visible
                                .as_ref()
                                .map_or(0.0, |vp| initial_radius.at_distance(vp.path_length));
                        }
                        pixel.radius
                    })
                    .collect()
            }
            Estimate::Independent { .. } => samples
                .par_iter()
                .map(|sample| {
                    sample
                        .visible
                        .as_ref()
                        .map_or(0.0, |vp| initial_radius.at_distance(vp.path_length) * linear_scale)
                })
                .collect(),
        }
    }

    /// Step 3: traces this iteration's photons in parallel, adding to the
    /// tallies of the visible points they land near. Returns false if cancelled.
    fn photon_pass<C: Radiance>(
        &self,
        scene: &Scene,
        sources: &PhotonSources,
        visible: &[CameraSample],
        cancel: &AtomicBool,
    ) -> bool {
        let grid = &self.grid;
        let (kind, iteration, max_depth) = (self.sampler, self.iteration(), self.max_depth);
        let seed = self.seed ^ PHOTON_SEED;
        let inverse_unit = 1.0 / flux_unit(sources);
        let avx2 = Avx2::detect();
        (0..self.parameters.photons_per_iteration)
            .into_par_iter()
            .with_min_len(64)
            .with_max_len(PHOTONS_PER_JOB)
            .for_each(|index| {
                if cancel.load(Ordering::Relaxed) {
                    return;
                }
                let mut sampler = Sampler::new(kind, index as u64, iteration, seed);
                if let Some(avx2) = avx2 {
                    sampler.draw_ahead(avx2, photon::DIMENSIONS_DRAWN_AHEAD);
                }
                let Some(emitted) = sources.emit::<C>(scene, &mut sampler) else {
                    return;
                };
                photon::trace(
                    scene,
                    emitted,
                    &mut sampler,
                    max_depth,
                    |hit, towards_light, flux, wavelengths| {
                        for candidate in grid.candidates(hit.point) {
                            if (candidate.center - hit.point).length_squared() > candidate.radius_squared
                                || candidate.normal.dot(hit.geometric_normal) < NORMAL_AGREEMENT
                                || towards_light.dot(candidate.normal).signum() != f64::from(candidate.side)
                            {
                                continue;
                            }
                            let pixel = candidate.pixel;
                            let Some(vp) = &visible[pixel as usize].visible else {
                                continue;
                            };
                            let material = &scene.materials[vp.material as usize];
                            let f = material.eval(vp.wo, vp.frame.to_local(towards_light), &vp.at);
                            let contribution = (flux * C::from_rgb(f, wavelengths)).to_rgb(wavelengths);
                            self.tallies[pixel as usize].add(contribution, inverse_unit);
                        }
                    },
                );
            });
        !cancel.load(Ordering::Relaxed)
    }

    /// Step 4: folds each pixel's tally into the estimate: the per-pixel
    /// statistics, or this iteration's estimate added to the film.
    fn update_estimate(&mut self, sources: &PhotonSources, visible: &[CameraSample], radii: Vec<f64>) {
        let alpha = self.parameters.alpha;
        let unit = flux_unit(sources);
        // Photons emitted this iteration: the density estimate's denominator.
        let photons = self.parameters.photons_per_iteration as f64;
        let rejected = AtomicU64::new(0);
        match &mut self.estimate {
            Estimate::Progressive(pixels) => pixels
                .par_iter_mut()
                .zip(self.tallies.par_iter_mut())
                .zip(visible.par_iter())
                .for_each(|((pixel, tally), sample)| {
                    let (flux, count) = tally.take(unit);
                    let Some(vp) = &sample.visible else { return };
                    let flux = vp.throughput * flux;
                    if flux.is_finite() {
                        pixel.add_photons(flux, count, alpha);
                    } else {
                        rejected.fetch_add(1, Ordering::Relaxed);
                    }
                }),
            Estimate::Independent { film, radii: latest } => {
                film.pixels
                    .par_iter_mut()
                    .zip(self.tallies.par_iter_mut())
                    .zip(visible.par_iter().zip(radii.par_iter()))
                    .for_each(|((pixel, tally), (sample, &radius))| {
                        let (flux, _) = tally.take(unit);
                        if !sample.sampled {
                            return;
                        }
                        let Some(emitted) = sample.emitted else {
                            rejected.fetch_add(1, Ordering::Relaxed);
                            return;
                        };
                        let gathered = match &sample.visible {
                            Some(vp) if radius > 0.0 => vp.throughput * flux / (PI * radius * radius * photons),
                            _ => Color::ZERO,
                        };
                        if !pixel.add(emitted + gathered) {
                            rejected.fetch_add(1, Ordering::Relaxed);
                        }
                    });
                *latest = radii;
            }
        }
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
        // RGB or spectral, chosen once per pass: each is its own compiled loop.
        let spectral = self.settings.spectral || scene.has_dispersion();
        if self.may_see_emission.is_empty() {
            let size = (self.width, self.height);
            self.may_see_emission =
                emission_paths::pixels_that_may_see_emission(scene, camera, size, self.settings.sampled_pixels(), self.max_depth);
        }
        let mut visible = std::mem::take(&mut self.samples);
        match spectral {
            true => self.camera_pass::<SampledSpectrum>(scene, camera, cancel, &mut visible),
            false => self.camera_pass::<Color>(scene, camera, cancel, &mut visible),
        }
        if cancel.load(Ordering::Relaxed) {
            self.samples = visible;
            return false;
        }
        // Step 2: the grid over the gather spheres.
        let radii = self.radii_for_iteration(camera, &visible);
        self.grid.rebuild(|points| {
            points.extend(
                visible
                    .iter()
                    .zip(&radii)
                    .enumerate()
                    .filter_map(|(pixel, (sample, &radius))| {
                        sample.visible.as_ref().map(|vp| GridPoint {
                            center: vp.point,
                            radius_squared: radius * radius,
                            normal: vp.geometric_normal,
                            side: vp.side() as f32,
                            pixel: pixel as u32,
                        })
                    }),
            )
        });
        let photons_start = Instant::now();
        let sources = PhotonSources::new(scene);
        let completed = match spectral {
            true => self.photon_pass::<SampledSpectrum>(scene, &sources, &visible, cancel),
            false => self.photon_pass::<Color>(scene, &sources, &visible, cancel),
        };
        if !completed {
            self.clear_tallies();
            self.samples = visible;
            return false;
        }
        self.photon_time += photons_start.elapsed();
        self.update_estimate(&sources, &visible, radii);
        self.samples = visible;
        self.iterations += 1;
        self.total_time += start.elapsed();
        true
    }

    fn passes(&self) -> u32 {
        self.iterations
    }

    fn frame(&self) -> Frame {
        let (iterations, photons) = (self.iterations, self.parameters.photons_per_iteration);
        match &self.estimate {
            Estimate::Progressive(pixels) => Frame {
                width: self.width,
                height: self.height,
                // In parallel, as `Film::frame` (the viewer's frame per iteration).
                pixels: pixels
                    .par_iter()
                    .map(|p| p.radiance(iterations, photons).as_vec3().to_array())
                    .collect(),
                noise: Vec::new(),
            },
            Estimate::Independent { film, .. } => film.frame(),
        }
    }

    fn film(&self) -> Option<&Film> {
        match &self.estimate {
            Estimate::Progressive(_) => None,
            Estimate::Independent { film, .. } => Some(film),
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

    /// The global schedule averages independent per-iteration estimates, so
    /// its film has a noise estimate; the per-pixel one has none.
    fn estimates_noise(&self) -> bool {
        matches!(self.estimate, Estimate::Independent { .. })
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
