//! The one parallel pixel loop every per-pixel integrator shares: rows are
//! handed to rayon's workers, each owns its pixels (no locks), and the
//! cancel flag is checked once per row.

use crate::color::Color;
use crate::film::{Film, PixelAccumulator};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Adds one sample to every pixel: `sample(x, y)`. Returns false if cancelled.
pub fn add_samples(film: &mut Film, cancel: &AtomicBool, sample: impl Fn(u32, u32) -> Color + Sync) -> bool {
    let width = film.width as usize;
    let rejected = AtomicU64::new(0);
    film.pixels.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        if cancel.load(Ordering::Relaxed) {
            return;
        }
        let mut row_rejected = 0;
        for (x, pixel) in row.iter_mut().enumerate() {
            let value = sample(x as u32, y as u32);
            add_finite(pixel, value, &mut row_rejected);
        }
        if row_rejected > 0 {
            rejected.fetch_add(row_rejected, Ordering::Relaxed);
        }
    });
    film.rejected_samples += rejected.into_inner();
    !cancel.load(Ordering::Relaxed)
}

#[inline]
fn add_finite(pixel: &mut PixelAccumulator, value: Color, rejected: &mut u64) {
    if value.is_finite() {
        pixel.add(value);
    } else {
        *rejected += 1;
    }
}
