//! Compares a rendered image with a reference: RMSE and channel means.
//!
//! `cargo run --release --example rmse -- image.exr reference.exr [reference2.exr]`
//!
//! With two independent references (same scene, different seeds) the
//! reference is their mean, and the error is also reported with the
//! reference's own noise removed: E[RMSE(x, ref)²] = error(x)² + σ²_ref, and
//! σ²_ref = RMSE(ref₁, ref₂)² / 4 for the mean of two equal-effort renders.

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

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 || args.len() > 3 {
        bail!("usage: rmse IMAGE REFERENCE [REFERENCE2]");
    }
    let image = load(&args[0])?;
    let first = load(&args[1])?;
    let (reference, reference_variance) = match args.get(2) {
        Some(path) => {
            let second = load(path)?;
            let spread = rmse(&first, &second)?;
            let mut mean = first.clone();
            for (m, s) in mean.pixels.iter_mut().zip(&second.pixels) {
                for c in 0..3 {
                    m[c] = 0.5 * (m[c] + s[c]);
                }
            }
            println!("reference halves differ by RMSE {spread:.5}");
            (mean, Some(spread * spread / 4.0))
        }
        None => (first, None),
    };
    let error = rmse(&image, &reference)?;
    let fmt = |m: [f64; 3]| format!("[{:.5}, {:.5}, {:.5}]", m[0], m[1], m[2]);
    println!("image means     {}", fmt(image.channel_means()));
    println!("reference means {}", fmt(reference.channel_means()));
    println!("RMSE {error:.5}");
    if let Some(variance) = reference_variance {
        let corrected = (error * error - variance).max(0.0).sqrt();
        println!(
            "RMSE without the reference's noise {corrected:.5} (reference noise RMSE {:.5})",
            variance.sqrt()
        );
    }
    Ok(())
}
