//! Path tracing as a progressive integrator: one sample per pixel per pass
//! through the shared pixel loop ([`super::pass`]); the per-sample tracer is
//! in [`tracer`]. Pass k of a render whose share starts at sample A uses
//! sample index A + k, so a share's film is exactly its samples of the
//! whole render.

pub mod ball_connection;
pub mod caustic_emission;
pub mod caustic_paths;
mod diffuse_lanes;
mod diffuse_rows;
pub mod lens_connection;
pub mod tracer;

pub use tracer::PathTracer;

use caustic_emission::CausticEmission;
use diffuse_rows::{DiffuseQuads, RowPaths};
use lens_connection::LensView;

use super::{Integrator, RowSet, Share, pass};
use crate::accel::Avx2;
use crate::camera::Camera;
use crate::film::{Film, Frame, LightSplats};
use crate::math::Ray;
use crate::sampler::{Sampler, SamplerKind};
use crate::scene::Scene;
use crate::settings::{IntegratorKind, RenderSettings};
use glam::DVec2;
use rayon::prelude::*;
use std::sync::atomic::AtomicBool;

/// Progressive path tracing into a film, one sample per pixel per pass.
pub struct PathIntegrator {
    settings: RenderSettings,
    tracer: PathTracer,
    sampler: SamplerKind,
    seed: u64,
    film: Film,
    passes: u32,
    /// Sample index of the first pass.
    first_sample: u32,
    /// Rows this render samples.
    rows: RowSet,
    adaptive_threshold: Option<f64>,
    /// Adaptive sampling's state after the last pass: whether every pixel
    /// has met the threshold (`Integrator::converged`), and `status`.
    adaptive: AdaptiveProgress,
    /// Where light paths for caustics are aimed, built at the first pass
    /// that traces them (a render's scene does not change).
    caustic_emission: Option<CausticEmission>,
    /// For a scene of a few diffuse quads lit by one quad light, the rows'
    /// kernel ([`diffuse_rows`]), found at the first pass.
    diffuse_quads: Option<DiffuseQuads>,
}

/// How far adaptive sampling has come, counted after each pass in one
/// parallel sweep of the film (the viewer shows it after every pass, and
/// a count one pixel after another took as long as building the frame).
#[derive(Clone, Copy, Debug, Default)]
struct AdaptiveProgress {
    /// Pixels in the render's rows, and how many of them have converged.
    in_rows: usize,
    converged: usize,
    /// Every pixel the render samples has converged.
    all_sampled_converged: bool,
}

impl AdaptiveProgress {
    fn of(film: &Film, sampled: crate::settings::PixelRect, rows: RowSet, threshold: f64) -> Self {
        let width = film.width as usize;
        let (in_rows, converged, all_sampled_converged) = film
            .pixels
            .par_iter()
            .enumerate()
            .with_min_len(crate::film::FRAME_PIXELS_PER_JOB)
            .map(|(i, pixel)| {
                let (x, y) = ((i % width) as u32, (i / width) as u32);
                if !rows.contains(y) {
                    return (0, 0, true);
                }
                let done = pass::is_converged(pixel, threshold);
                (1, usize::from(done), done || !sampled.contains(x, y))
            })
            .reduce(|| (0, 0, true), |a, b| (a.0 + b.0, a.1 + b.1, a.2 && b.2));
        Self {
            in_rows,
            converged,
            all_sampled_converged,
        }
    }
}

/// Whether `settings` allow light-traced caustics: asked for, path tracing
/// with light sampling, RGB, and every pixel sampled every pass (a pixel's
/// light-path estimate is divided by its pass count, which adaptive
/// sampling would make differ from its sample count).
fn caustic_paths_apply(settings: &RenderSettings) -> bool {
    settings.caustic_light_paths
        && settings.integrator == IntegratorKind::PathTracing
        && !settings.spectral
        && settings.adaptive_threshold.is_none()
}

impl PathIntegrator {
    /// A path-tracing render of the whole image: every row, samples from 0.
    pub fn new(settings: &RenderSettings) -> Self {
        Self::with_share(settings, &Share::whole(settings.samples_per_pixel.unwrap_or(0)))
    }

    /// Renders only `share`: its sample indices, in order, on its rows.
    pub fn with_share(settings: &RenderSettings, share: &Share) -> Self {
        Self {
            settings: settings.clone(),
            tracer: PathTracer::from_settings(settings),
            sampler: settings.sampler,
            seed: settings.seed,
            film: Film::new(settings.width, settings.height),
            passes: 0,
            first_sample: share.samples.start,
            rows: share.rows,
            adaptive_threshold: settings.adaptive_threshold,
            adaptive: AdaptiveProgress::default(),
            caustic_emission: None,
            diffuse_quads: None,
        }
    }
}

impl PathIntegrator {
    /// One sample in every pixel still sampled, by `radiance` (the RGB or
    /// the spectral tracer); false if cancelled.
    fn add_pass<F>(&mut self, scene: &Scene, camera: &Camera, cancel: &AtomicBool, radiance: F) -> bool
    where
        F: Fn(&PathTracer, &Scene, Ray, &mut Sampler) -> crate::color::Color + Sync,
    {
        // A thin lens's camera ray is a longer chain before the path can
        // start (a second draw, the disk map, a normalisation), so through a
        // lens the pixel loop has its own copy with the chain compiled in:
        // no calls, nothing handed on through memory. A pinhole's loop
        // stays as it was: compiled the same way, Mitsuba's Cornell box ran
        // level to 2% slower.
        if camera.has_lens() {
            self.add_pass_with(scene, camera, cancel, radiance, camera_ray_compiled::<true>)
        } else {
            self.add_pass_with(scene, camera, cancel, radiance, camera_ray)
        }
    }

    /// [`PathIntegrator::add_pass`] with its camera rays made by `camera_ray`.
    #[inline(always)]
    fn add_pass_with<F, C>(&mut self, scene: &Scene, camera: &Camera, cancel: &AtomicBool, radiance: F, camera_ray: C) -> bool
    where
        F: Fn(&PathTracer, &Scene, Ray, &mut Sampler) -> crate::color::Color + Sync,
        C: Fn(&Camera, (u32, u32), u32, u32, &mut Sampler) -> Ray + Sync,
    {
        let sample_index = self.first_sample + self.passes;
        let (tracer, kind, seed) = (self.tracer, self.sampler, self.seed);
        let size = (self.film.width, self.film.height);
        let (pixels, rows) = (self.settings.sampled_pixels(), self.rows);
        pass::add_samples_adaptive(&mut self.film, pixels, rows, cancel, self.adaptive_threshold, |x, y| {
            let mut sampler = Sampler::new(kind, y as u64 * size.0 as u64 + x as u64, sample_index, seed);
            let ray = camera_ray(camera, size, x, y, &mut sampler);
            radiance(&tracer, scene, ray, &mut sampler)
        })
    }

    /// [`PathIntegrator::add_pass`] by whole rows with the diffuse kernel
    /// (`self.diffuse_quads`), its rays four at a time in AVX instructions
    /// (`avx2`).
    fn add_pass_by_rows(&mut self, avx2: Avx2, scene: &Scene, camera: &Camera, cancel: &AtomicBool) -> bool {
        let Some(kernel) = &self.diffuse_quads else {
            return self.add_pass(scene, camera, cancel, PathTracer::radiance);
        };
        let sample_index = self.first_sample + self.passes;
        let (kind, seed) = (self.sampler, self.seed);
        let size = (self.film.width, self.film.height);
        let sampled = (self.settings.sampled_pixels(), self.rows);
        let ahead = dimensions_drawn_ahead(camera.has_lens());
        let sample_row = |y: u32, columns: &[u32], values: &mut Vec<crate::color::Color>| {
            let start = |x: u32| {
                let mut sampler = Sampler::new(kind, y as u64 * size.0 as u64 + x as u64, sample_index, seed);
                sampler.draw_ahead(avx2, ahead);
                let ray = camera_ray(camera, size, x, y, &mut sampler);
                (sampler, ray)
            };
            // The row's loop compiled for AVX2, the four-ray queries inside.
            RowPaths::with(|paths| {
                avx2.run(
                    #[inline(always)]
                    || kernel.radiance_of_row(avx2, scene, columns, start, paths, values),
                )
            })
        };
        pass::add_sample_rows_adaptive(&mut self.film, sampled, cancel, self.adaptive_threshold, sample_row)
    }
}

/// The 2D draws a path reads first, computed together when its pixel
/// sample starts ([`Sampler::draw_ahead`]): the film position (dimension
/// 1), the lens's (2) if the camera has one, and the first bounce's light
/// point and direction (4 and 5); a pinhole's fourth is the second
/// bounce's light point (9). The tracer's `BounceDraws` lays out these
/// dimensions. Only the diffuse kernel's rows draw ahead: at the shipped
/// scenes' sizes the path-by-path loop gained nothing from it (its scalar
/// draws hide in the traversals), and the Cornell box with glass balls ran
/// 4–6% slower.
fn dimensions_drawn_ahead(lens: bool) -> [u32; 4] {
    if lens { [1, 2, 4, 5] } else { [1, 4, 5, 9] }
}

/// The camera ray of one pixel sample; consumes the sampler's first two
/// dimensions (film position within the pixel: a box filter, and lens).
pub fn camera_ray(camera: &Camera, size: (u32, u32), x: u32, y: u32, sampler: &mut Sampler) -> Ray {
    camera_ray_compiled::<false>(camera, size, x, y, sampler)
}

/// [`camera_ray`], compiled into its caller; with `CAMERA_INLINED` the
/// camera's own ray arithmetic is too ([`Camera::generate_ray_inlined`]).
#[inline(always)]
fn camera_ray_compiled<const CAMERA_INLINED: bool>(
    camera: &Camera,
    (width, height): (u32, u32),
    x: u32,
    y: u32,
    sampler: &mut Sampler,
) -> Ray {
    let jitter = sampler.next_2d();
    // A pinhole reads no lens sample; its dimension is still used up, so
    // later draws do not depend on the camera.
    let lens = if camera.has_lens() {
        sampler.next_2d()
    } else {
        sampler.skip();
        DVec2::ZERO
    };
    let film_point = DVec2::new((x as f64 + jitter.x) / width as f64, (y as f64 + jitter.y) / height as f64);
    let aspect = width as f64 / height as f64;
    if CAMERA_INLINED {
        camera.generate_ray_inlined(film_point, aspect, lens)
    } else {
        camera.generate_ray(film_point, aspect, lens)
    }
}

impl Integrator for PathIntegrator {
    fn render_pass(&mut self, scene: &Scene, camera: &Camera, cancel: &AtomicBool) -> bool {
        let spectral = self.settings.spectral || scene.has_dispersion();
        let light_traced = caustic_paths_apply(&self.settings) && !spectral && caustic_paths::scene_has_caustics(scene);
        self.tracer.caustics_by_light_paths = light_traced;
        if self.passes == 0 {
            let size = (self.film.width, self.film.height);
            let lens = light_traced && lens_connection::scene_has_lens_connections(scene);
            self.tracer.lens_connections = lens.then(|| LensView::new(scene, camera, size));
            self.diffuse_quads = DiffuseQuads::of(scene, &self.tracer);
        }
        if light_traced {
            let pixels = self.settings.sampled_pixels();
            let film = &mut self.film;
            if film.light.is_none() && self.passes == 0 {
                film.light = Some(LightSplats::new(
                    caustic_paths::paths_per_pass(pixels.pixel_count()),
                    film.pixels.len(),
                ));
            }
            let emission = self.caustic_emission.get_or_insert_with(|| CausticEmission::new(scene));
            let stream = (self.sampler, self.seed, self.first_sample + self.passes);
            // Only this share's rows keep splats: every share traces the
            // light paths of its passes, and each pixel divides by its own.
            let rows = self.rows;
            let share_pixels = |x: u32, y: u32| pixels.contains(x, y) && rows.contains(y);
            let light = (&*emission, self.settings.max_depth);
            let lens = self.tracer.lens_connections.as_ref();
            if !caustic_paths::add_pass(film, scene, camera, light, lens, share_pixels, stream, cancel) {
                return false;
            }
        }
        // RGB or spectral, chosen once per pass: each is its own compiled
        // loop; a scene of a few diffuse quads in RGB has a kernel of its own
        // where AVX2 runs its four-ray queries.
        let completed = if spectral {
            self.add_pass(scene, camera, cancel, PathTracer::spectral_radiance)
        } else if let (true, Some(avx2)) = (self.diffuse_quads.is_some(), scene.bvh().avx2()) {
            self.add_pass_by_rows(avx2, scene, camera, cancel)
        } else {
            self.add_pass(scene, camera, cancel, PathTracer::radiance)
        };
        if completed {
            self.passes += 1;
            if let Some(threshold) = self.adaptive_threshold {
                // A stopped pixel stays stopped (its state no longer changes), so
                // once all that are sampled are, every later pass would be empty.
                self.adaptive = AdaptiveProgress::of(&self.film, self.settings.sampled_pixels(), self.rows, threshold);
            }
        }
        completed
    }

    fn converged(&self) -> bool {
        self.adaptive.all_sampled_converged
    }

    fn preview(&self, divisor: u32) -> Box<dyn Integrator> {
        Box::new(Self::new(&super::reduced_resolution(&self.settings, divisor)))
    }

    fn passes(&self) -> u32 {
        self.passes
    }

    fn frame(&self) -> Frame {
        self.film.frame()
    }

    fn film(&self) -> Option<&Film> {
        Some(&self.film)
    }

    /// `None` while every pixel has one sample per pass: no adaptive
    /// sampling, no region, every row, no sample refused. (Copying the
    /// counts out of the film took 0.6–1.8 ms of every viewer pass.)
    fn sample_counts(&self) -> Option<Vec<u32>> {
        let one_per_pass = self.adaptive_threshold.is_none()
            && self.settings.region.is_none()
            && self.rows == RowSet::ALL
            && self.film.rejected_samples == 0;
        (!one_per_pass).then(|| self.film.pixels.par_iter().map(|p| p.count).collect())
    }

    fn rejected_samples(&self) -> u64 {
        self.film.rejected_samples
    }

    fn status(&self) -> String {
        match self.adaptive_threshold {
            Some(_) if self.adaptive.all_sampled_converged => "adaptive: converged, 0% of pixels active".to_string(),
            Some(_) => {
                let AdaptiveProgress { in_rows, converged, .. } = self.adaptive;
                let active = 100.0 * (1.0 - converged as f64 / in_rows.max(1) as f64);
                format!("adaptive: {active:.0}% of pixels active")
            }
            None => String::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::Color;
    use crate::settings::PixelRect;

    /// Sample counts are given exactly when they are not all the pass
    /// count: with adaptive sampling or a region, and not for a plain render.
    #[test]
    fn sample_counts_only_where_they_differ_from_the_pass_count() {
        let loaded = crate::scene::load_scene_str(
            crate::scene::DEFAULT_SCENE,
            std::path::Path::new("cornell"),
            std::path::Path::new("."),
        )
        .expect("default scene loads");
        let cancel = AtomicBool::new(false);
        let plain = RenderSettings {
            width: 16,
            height: 12,
            samples_per_pixel: Some(3),
            ..loaded.settings.clone()
        };
        let adaptive = RenderSettings {
            adaptive_threshold: Some(0.05),
            ..plain.clone()
        };
        let region = RenderSettings {
            region: crate::settings::Region::from_corners([0.25, 0.25], [0.5, 0.75]),
            ..plain.clone()
        };
        for (settings, given) in [(&plain, false), (&adaptive, true), (&region, true)] {
            let mut integrator = PathIntegrator::new(settings);
            for _ in 0..3 {
                assert!(integrator.render_pass(&loaded.scene, &loaded.camera, &cancel));
            }
            let counts = integrator.sample_counts();
            assert_eq!(counts.is_some(), given, "{settings:?}");
            if counts.is_none() {
                assert!(integrator.film.pixels.iter().all(|p| p.count == 3));
            }
        }
    }

    /// The parallel sweep counts what a plain count over the film does: a
    /// film of pixels that have converged (constant samples past the
    /// minimum count), pixels still noisy and pixels never sampled, with a
    /// row set and a sampled rectangle that each leave some out.
    #[test]
    fn adaptive_progress_counts_what_a_plain_count_does() {
        let (width, height) = (97, 61);
        let mut film = Film::new(width, height);
        for (i, pixel) in film.pixels.iter_mut().enumerate() {
            let samples = (crate::sampler::mix64(i as u64) % 3) as u32 * 20;
            for k in 0..samples {
                let value = if i % 5 == 0 { 1.0 + (k % 2) as f64 } else { 0.5 };
                pixel.add(Color::splat(value));
            }
        }
        let threshold = 0.05;
        for rows in [RowSet::ALL, RowSet { first: 1, step: 3 }] {
            for sampled in [
                PixelRect::full(width, height),
                PixelRect {
                    x0: 10,
                    y0: 5,
                    x1: 60,
                    y1: 40,
                },
            ] {
                let progress = AdaptiveProgress::of(&film, sampled, rows, threshold);
                let (mut in_rows, mut converged, mut all) = (0, 0, true);
                for (i, pixel) in film.pixels.iter().enumerate() {
                    let (x, y) = ((i as u32 % width), (i as u32 / width));
                    if rows.contains(y) {
                        in_rows += 1;
                        let done = pass::is_converged(pixel, threshold);
                        converged += usize::from(done);
                        all &= done || !sampled.contains(x, y);
                    }
                }
                assert_eq!(
                    (progress.in_rows, progress.converged, progress.all_sampled_converged),
                    (in_rows, converged, all)
                );
                assert!(
                    converged > 0 && converged < in_rows,
                    "the film must mix converged and active pixels"
                );
            }
        }
        // A film where every sampled pixel converged, the rest never sampled.
        let mut film = Film::new(8, 4);
        for pixel in &mut film.pixels[..16] {
            for _ in 0..pass::ADAPTIVE_MIN_SAMPLES {
                pixel.add(Color::splat(0.25));
            }
        }
        let top = PixelRect {
            x0: 0,
            y0: 0,
            x1: 8,
            y1: 2,
        };
        assert!(AdaptiveProgress::of(&film, top, RowSet::ALL, threshold).all_sampled_converged);
        assert!(!AdaptiveProgress::of(&film, PixelRect::full(8, 4), RowSet::ALL, threshold).all_sampled_converged);
    }
}
