//! The one parallel pixel loop every per-pixel integrator shares: rows are
//! handed to rayon's workers one at a time, each owns its pixels (no locks),
//! and the cancel flag is checked once per row.
//!
//! Adaptive sampling skips pixels whose estimate is already good enough. A
//! pixel's activity is decided only from its own accumulated state at the
//! start of a pass, so the image stays a pure function of the seed whatever
//! the thread count; and since a stopped pixel's state no longer changes, it
//! stays stopped, so each pixel's samples are a prefix of its sequence.
//!
//! A pass may cover only a rectangle of the image (the viewer's region
//! render), and a render's share (`super::share`) only some rows; pixels
//! outside them are left as they are. Since a pixel's activity depends on
//! nothing outside it, the rows' shares of an adaptive render add up to
//! exactly the whole render.

use super::share::RowSet;
use crate::color::{Color, luminance};
use crate::film::{Film, PixelAccumulator};
use crate::settings::PixelRect;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Samples a pixel takes before adaptive sampling may stop it: a variance
/// estimated from fewer is itself too noisy to trust (a pixel whose first few
/// paths all missed a small light would look converged), and 32 is a power of
/// two, where a pixel's Sobol' prefix is a complete (0, m, 2)-net.
pub const ADAPTIVE_MIN_SAMPLES: u32 = 32;

/// Luminance below which the adaptive error is measured absolutely rather than
/// relatively: 1% of display white, so near-black pixels need not reach a
/// relative error their tone-mapped value could never show.
pub const ADAPTIVE_LUMINANCE_FLOOR: f64 = 0.01;

/// Whether adaptive sampling with `threshold` stops this pixel: standard error
/// of its mean luminance / max(mean luminance, floor) ≤ threshold.
#[inline]
pub fn is_converged(pixel: &PixelAccumulator, threshold: f64) -> bool {
    if pixel.count < ADAPTIVE_MIN_SAMPLES {
        return false;
    }
    let mean = luminance(pixel.sum()) / pixel.count as f64;
    pixel.standard_error() <= threshold * mean.max(ADAPTIVE_LUMINANCE_FLOOR)
}

/// Adds one sample to every pixel: `sample(x, y)`. Returns false if cancelled.
pub fn add_samples(film: &mut Film, cancel: &AtomicBool, sample: impl Fn(u32, u32) -> Color + Sync) -> bool {
    let pixels = PixelRect::full(film.width, film.height);
    // `|_| true` is inlined away: the non-adaptive loop costs what it did.
    add_samples_where(film, pixels, RowSet::ALL, cancel, |_| true, sample)
}

/// Adds one sample to each pixel of `pixels` in `rows` that adaptive
/// sampling with `threshold` has not stopped (see [`is_converged`]); `None`
/// samples every one.
pub fn add_samples_adaptive(
    film: &mut Film,
    pixels: PixelRect,
    rows: RowSet,
    cancel: &AtomicBool,
    threshold: Option<f64>,
    sample: impl Fn(u32, u32) -> Color + Sync,
) -> bool {
    match threshold {
        Some(threshold) => add_samples_where(film, pixels, rows, cancel, |pixel| !is_converged(pixel, threshold), sample),
        None => add_samples_where(film, pixels, rows, cancel, |_| true, sample),
    }
}

/// Adds one sample to each pixel of `pixels` in `rows` for which
/// `active(pixel)` holds, judged on the pixel's state before this pass.
/// Returns false if cancelled.
pub fn add_samples_where(
    film: &mut Film,
    pixels: PixelRect,
    rows: RowSet,
    cancel: &AtomicBool,
    active: impl Fn(&PixelAccumulator) -> bool + Sync,
    sample: impl Fn(u32, u32) -> Color + Sync,
) -> bool {
    let width = film.width as usize;
    let (columns, lines) = (pixels.x0 as usize..pixels.x1 as usize, pixels.y0 as usize..pixels.y1 as usize);
    let rejected = AtomicU64::new(0);
    // One row per job. Rayon would otherwise cut the rows into as many
    // pieces as threads, halved once more, and split a piece again only
    // when another thread steals it; the last piece a thread starts (an
    // eighth to a quarter of the image on two threads) then runs alone to
    // its end while the others wait. Rows through glass or a bunny cost
    // several times rows of sky, so that tail was a tenth of a glass
    // scene's two-thread render (docs/performance.md, "Parallel jobs").
    let film_rows = film.pixels.par_chunks_mut(width).with_max_len(1).enumerate();
    film_rows.skip(lines.start).take(lines.len()).for_each(|(y, row)| {
        if cancel.load(Ordering::Relaxed) || !rows.contains(y as u32) {
            return;
        }
        let mut row_rejected = 0;
        for (x, pixel) in row[columns.clone()].iter_mut().enumerate() {
            if !active(pixel) {
                continue;
            }
            let value = sample((columns.start + x) as u32, y as u32);
            add_finite(pixel, value, &mut row_rejected);
        }
        if row_rejected > 0 {
            rejected.fetch_add(row_rejected, Ordering::Relaxed);
        }
    });
    film.rejected_samples += rejected.into_inner();
    !cancel.load(Ordering::Relaxed)
}

/// [`add_samples_adaptive`] for a sampler of whole rows: `sample_row(y,
/// columns, values)` writes into `values` one sample for each pixel of row
/// `y` in `columns` (in that order).
pub fn add_sample_rows_adaptive(
    film: &mut Film,
    (pixels, rows): (PixelRect, RowSet),
    cancel: &AtomicBool,
    threshold: Option<f64>,
    sample_row: impl Fn(u32, &[u32], &mut Vec<Color>) + Sync,
) -> bool {
    let active = |pixel: &PixelAccumulator| threshold.is_none_or(|threshold| !is_converged(pixel, threshold));
    let width = film.width as usize;
    let (x0, lines) = (pixels.x0, pixels.y0 as usize..pixels.y1 as usize);
    let columns = pixels.x0 as usize..pixels.x1 as usize;
    let rejected = AtomicU64::new(0);
    // One row per job, as in `add_samples_where`. The two loops are kept
    // apart: the pixel-by-pixel one run through a shared row loop and a
    // closure rendered the other scenes 2–4% slower (paired renders).
    let film_rows = film.pixels.par_chunks_mut(width).with_max_len(1).enumerate();
    film_rows.skip(lines.start).take(lines.len()).for_each_init(
        || (Vec::new(), Vec::new()),
        |(sampled, values), (y, row)| {
            if cancel.load(Ordering::Relaxed) || !rows.contains(y as u32) {
                return;
            }
            let row = &mut row[columns.clone()];
            sampled.clear();
            sampled.extend((x0..).zip(row.iter()).filter(|(_, pixel)| active(pixel)).map(|(x, _)| x));
            sample_row(y as u32, sampled, values);
            let mut row_rejected = 0;
            for (&x, &value) in sampled.iter().zip(values.iter()) {
                add_finite(&mut row[(x - x0) as usize], value, &mut row_rejected);
            }
            if row_rejected > 0 {
                rejected.fetch_add(row_rejected, Ordering::Relaxed);
            }
        },
    );
    film.rejected_samples += rejected.into_inner();
    !cancel.load(Ordering::Relaxed)
}

/// Adds `value` unless the film refuses it (NaN, infinite or beyond
/// `film::MAX_SAMPLE_VALUE`), which is counted instead.
#[inline]
fn add_finite(pixel: &mut PixelAccumulator, value: Color, rejected: &mut u64) {
    if !pixel.add(value) {
        *rejected += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::render_with_threads;
    use crate::scene::{DEFAULT_SCENE, load_scene_str};
    use crate::settings::RenderSettings;
    use std::path::Path;

    /// A pixel whose samples never vary converges exactly at the minimum
    /// count; one whose samples alternate 0 / 2 (relative error 1/√n) stays
    /// active until 1/√n ≤ threshold.
    #[test]
    fn adaptive_sampling_stops_only_converged_pixels() {
        let mut film = Film::new(2, 1);
        let cancel = AtomicBool::new(false);
        let threshold = 0.1;
        for pass in 0..200u32 {
            add_samples_adaptive(
                &mut film,
                PixelRect::full(2, 1),
                RowSet::ALL,
                &cancel,
                Some(threshold),
                |x, _| {
                    if x == 0 {
                        Color::splat(0.5)
                    } else {
                        Color::splat(2.0 * (pass % 2) as f64)
                    }
                },
            );
        }
        assert_eq!(film.pixels[0].count, ADAPTIVE_MIN_SAMPLES);
        // After an even n of alternating 0/2 samples the mean is 1 and the
        // standard error 1/√(n−1), ≤ 0.1 first at n = 102; at odd n = 101 the
        // mean is 100/101 and the error 0.099995 > 0.1 · 100/101. Exact count.
        let stopped = film.pixels[1].count;
        assert_eq!(stopped, 102, "noisy pixel stopped after {stopped} samples");
        assert!(is_converged(&film.pixels[1], threshold));
    }

    /// A pass over a rectangle samples its pixels, at their own coordinates,
    /// and leaves every other pixel untouched.
    #[test]
    fn a_pass_over_a_rectangle_samples_only_its_pixels() {
        let mut film = Film::new(5, 4);
        let cancel = AtomicBool::new(false);
        let rect = PixelRect {
            x0: 1,
            y0: 2,
            x1: 4,
            y1: 3,
        };
        add_samples_adaptive(&mut film, rect, RowSet::ALL, &cancel, None, |x, y| {
            Color::new(x as f64, y as f64, 1.0)
        });
        for y in 0..4 {
            for x in 0..5 {
                let pixel = &film.pixels[(y * 5 + x) as usize];
                let inside = rect.contains(x, y);
                assert_eq!(pixel.count, u32::from(inside), "pixel ({x}, {y})");
                if inside {
                    assert_eq!(pixel.mean(), Color::new(x as f64, y as f64, 1.0));
                }
            }
        }
    }

    /// Sampling whole rows fills the film exactly as sampling pixel by
    /// pixel does: the same pixels active at each pass (adaptive sampling
    /// stops some early), only the region's columns and the share's rows,
    /// and the same samples refused (NaN).
    #[test]
    fn rows_sampled_together_fill_the_film_as_pixels_one_at_a_time() {
        let cancel = AtomicBool::new(false);
        let region = PixelRect {
            x0: 1,
            y0: 0,
            x1: 6,
            y1: 5,
        };
        let rows = RowSet { first: 1, step: 2 };
        let value = |x: u32, y: u32, pass: u32| match (x + 3 * y + pass) % 7 {
            0 if x == 4 => Color::splat(f64::NAN),
            _ if x == 5 => Color::splat(1.0),
            k if x == 2 => Color::splat(0.5 + 0.07 * f64::from(k % 2)),
            k => Color::new(f64::from(k), f64::from(x), f64::from(y)),
        };
        let (mut by_pixel, mut by_row) = (Film::new(7, 5), Film::new(7, 5));
        for pass in 0..80 {
            add_samples_adaptive(&mut by_pixel, region, rows, &cancel, Some(0.01), |x, y| value(x, y, pass));
            add_sample_rows_adaptive(&mut by_row, (region, rows), &cancel, Some(0.01), |y, columns, values| {
                values.clear();
                values.extend(columns.iter().map(|&x| value(x, y, pass)));
            });
        }
        assert_eq!(by_pixel.pixels, by_row.pixels);
        assert_eq!(by_pixel.rejected_samples, by_row.rejected_samples);
        // Some pixels stopped at the minimum, some later, some ran every
        // pass, some were refused samples and some never sampled, so each
        // part of the comparison was exercised.
        let counts: Vec<u32> = by_row.pixels.iter().map(|pixel| pixel.count).collect();
        assert!(
            counts.contains(&0) && counts.contains(&ADAPTIVE_MIN_SAMPLES) && counts.contains(&80),
            "{counts:?}"
        );
        assert!(counts.iter().any(|&n| n > ADAPTIVE_MIN_SAMPLES && n < 80), "{counts:?}");
        assert!(by_row.rejected_samples > 0);
    }

    /// A render whose pixels have all converged stops there, not at its
    /// sample target: under a constant background every sample is equal, so
    /// every pixel stops at exactly the minimum count. The Cornell box at the
    /// same threshold is still noisy after 40 passes and runs to its target.
    #[test]
    fn adaptive_render_stops_once_every_pixel_has_converged() {
        let loaded = load_scene_str(DEFAULT_SCENE, Path::new("cornell"), Path::new(".")).expect("default scene loads");
        let sky = crate::scene::Scene::new(Vec::new(), Vec::new(), Vec::new(), Color::splat(0.7));
        let settings = RenderSettings {
            width: 8,
            height: 6,
            samples_per_pixel: Some(10_000),
            adaptive_threshold: Some(0.05),
            ..loaded.settings.clone()
        };
        let integrator = render_with_threads(&sky, &loaded.camera, &settings, Some(2)).expect("pool");
        assert!(integrator.converged(), "{}", integrator.status());
        assert_eq!(integrator.passes(), ADAPTIVE_MIN_SAMPLES);

        let noisy = RenderSettings {
            samples_per_pixel: Some(40),
            ..settings
        };
        let integrator = render_with_threads(&loaded.scene, &loaded.camera, &noisy, Some(2)).expect("pool");
        assert!(!integrator.converged(), "{}", integrator.status());
        assert_eq!(integrator.passes(), 40);
    }

    /// Same seed, same image, with 1 or 2 threads, adaptive sampling on: a
    /// pixel's activity depends only on its own samples. Exact equality: any
    /// dependence on scheduling would change some pixel's sample count.
    #[test]
    fn adaptive_images_do_not_depend_on_thread_count() {
        let loaded = load_scene_str(DEFAULT_SCENE, Path::new("cornell"), Path::new(".")).expect("default scene loads");
        let settings = RenderSettings {
            width: 12,
            height: 12,
            samples_per_pixel: Some(48),
            adaptive_threshold: Some(0.3),
            ..loaded.settings.clone()
        };
        let one = render_with_threads(&loaded.scene, &loaded.camera, &settings, Some(1)).expect("pool");
        let two = render_with_threads(&loaded.scene, &loaded.camera, &settings, Some(2)).expect("pool");
        assert_eq!(one.frame(), two.frame());
        // And some pixels did stop (else this would test nothing adaptive).
        assert!(
            one.status().contains("active") && !one.status().starts_with("adaptive: 100%"),
            "{}",
            one.status()
        );
    }
}
