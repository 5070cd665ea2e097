//! Compares a rendered image with a reference: RMSE, channel means and the
//! pixels where the error is.
//!
//! `cargo run --release --example rmse -- image.exr reference.exr [more references…]`
//!
//! With an even number of independent, equal-effort references (same scene,
//! different seeds) the reference is their mean, and the error is also
//! reported with the reference's own noise removed: E[RMSE(x, ref)²] =
//! error(x)² + σ²_ref, and σ²_ref = RMSE(mean of first half, mean of second
//! half)² / 4 (each half-mean has twice the variance of the full mean).

use anyhow::{Context, Result, bail};
use prism::film::Frame;
use prism::metrics::rmse;
use prism::output::load_frame;
use std::path::Path;

fn load(path: &str) -> Result<Frame> {
    load_frame(Path::new(path))
        .map_err(anyhow::Error::msg)
        .with_context(|| format!("cannot read {path}"))
}

/// Pixel-wise mean of frames of equal size.
fn mean(frames: &[Frame]) -> Result<Frame> {
    let mut sum = frames[0].clone();
    for frame in &frames[1..] {
        rmse(&sum, frame)?; // size check
        for (m, p) in sum.pixels.iter_mut().zip(&frame.pixels) {
            for c in 0..3 {
                m[c] += p[c];
            }
        }
    }
    let scale = 1.0 / frames.len() as f32;
    for m in &mut sum.pixels {
        *m = m.map(|v| v * scale);
    }
    Ok(sum)
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        bail!("usage: rmse IMAGE REFERENCE [REFERENCE…]");
    }
    let image = load(&args[0])?;
    let references = args[1..].iter().map(|p| load(p)).collect::<Result<Vec<_>>>()?;
    let reference = mean(&references)?;
    let reference_variance = if references.len() % 2 == 0 {
        let half = references.len() / 2;
        let spread = rmse(&mean(&references[..half])?, &mean(&references[half..])?)?;
        println!("reference halves differ by RMSE {spread:.5}");
        Some(spread * spread / 4.0)
    } else {
        None
    };
    let error = rmse(&image, &reference)?;
    let fmt = |m: [f64; 3]| format!("[{:.5}, {:.5}, {:.5}]", m[0], m[1], m[2]);
    println!("image means     {}", fmt(image.channel_means()));
    println!("reference means {}", fmt(reference.channel_means()));
    println!("RMSE {error:.5}");
    print_worst_pixels(&image, &reference, 8);
    if let Some(variance) = reference_variance {
        let corrected = (error * error - variance).max(0.0).sqrt();
        println!(
            "RMSE without the reference's noise {corrected:.5} (reference noise RMSE {:.5})",
            variance.sqrt()
        );
    }
    Ok(())
}

/// Where the error is: the pixels with the largest squared error, and their
/// share of the total.
fn print_worst_pixels(image: &Frame, reference: &Frame, count: usize) {
    let squared: Vec<f64> = image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, b)| (0..3).map(|c| (a[c] as f64 - b[c] as f64).powi(2)).sum())
        .collect();
    let total: f64 = squared.iter().sum();
    let mut order: Vec<usize> = (0..squared.len()).collect();
    order.sort_by(|&a, &b| squared[b].total_cmp(&squared[a]));
    let width = image.width as usize;
    let share: f64 = order.iter().take(count).map(|&i| squared[i]).sum::<f64>() / total.max(f64::MIN_POSITIVE);
    println!("worst {count} pixels hold {:.1}% of the squared error:", 100.0 * share);
    for &i in order.iter().take(count) {
        let (a, b) = (image.pixels[i], reference.pixels[i]);
        println!(
            "  ({:4}, {:4}) image [{:.3}, {:.3}, {:.3}] reference [{:.3}, {:.3}, {:.3}]",
            i % width,
            i / width,
            a[0],
            a[1],
            a[2],
            b[0],
            b[1],
            b[2]
        );
    }
}
