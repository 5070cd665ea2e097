//! Image error metrics for comparing a render with a reference: what the
//! benchmarks and convergence tests report.
//!
//! Over all pixels and channels, with x the estimate and r the reference:
//! RMSE = sqrt(mean (x − r)²); relMSE = mean (x − r)² / (r² + ε) with ε = 0.01
//! (Rousselle, Knaus and Zwicker 2011, so dark pixels do not dominate); and the
//! mean bias per channel, mean (x − r), which stays near 0 for unbiased
//! estimators and reveals the consistent-but-biased ones (SPPM) and leaks.

use crate::film::Frame;

/// Two frames that cannot be compared pixel by pixel: the first one's width
/// and height, then the second one's.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error("frames differ in size: {0}x{1} vs {2}x{3}")]
pub struct SizeMismatch(pub u32, pub u32, pub u32, pub u32);

/// The ε of relMSE.
pub const RELATIVE_MSE_EPSILON: f64 = 0.01;

/// Error of an estimate against a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorMetrics {
    /// Root-mean-square error, in linear radiance.
    pub rmse: f64,
    /// Relative MSE with ε = [`RELATIVE_MSE_EPSILON`] (see the module doc).
    pub relative_mse: f64,
    /// Mean signed error per channel (R, G, B).
    pub bias: [f64; 3],
}

/// Compares two frames of the same size (all zero for two empty frames).
pub fn error_metrics(estimate: &Frame, reference: &Frame) -> Result<ErrorMetrics, SizeMismatch> {
    if (estimate.width, estimate.height) != (reference.width, reference.height) || estimate.pixels.len() != reference.pixels.len()
    {
        return Err(SizeMismatch(
            estimate.width,
            estimate.height,
            reference.width,
            reference.height,
        ));
    }
    let mut squared = 0.0;
    let mut relative = 0.0;
    let mut bias = [0.0; 3];
    for (x, r) in estimate.pixels.iter().zip(&reference.pixels) {
        for c in 0..3 {
            let (x, r) = (x[c] as f64, r[c] as f64);
            let difference = x - r;
            squared += difference * difference;
            relative += difference * difference / (r * r + RELATIVE_MSE_EPSILON);
            bias[c] += difference;
        }
    }
    let pixels = estimate.pixels.len().max(1) as f64;
    Ok(ErrorMetrics {
        rmse: (squared / (3.0 * pixels)).sqrt(),
        relative_mse: relative / (3.0 * pixels),
        bias: bias.map(|b| b / pixels),
    })
}

/// Root-mean-square error over all pixels and the three channels, in linear
/// radiance: sqrt(Σ (a − b)² / (3 · pixels)). Zero for two empty frames.
pub fn rmse(a: &Frame, b: &Frame) -> Result<f64, SizeMismatch> {
    error_metrics(a, b).map(|metrics| metrics.rmse)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(pixels: Vec<[f32; 3]>, width: u32) -> Frame {
        Frame {
            width,
            height: pixels.len() as u32 / width,
            pixels,
            noise: Vec::new(),
        }
    }

    #[test]
    fn rmse_of_known_differences() {
        let a = frame(vec![[0.0; 3], [1.0, 1.0, 1.0]], 2);
        let b = frame(vec![[0.0, 0.0, 3.0], [1.0, 1.0, 1.0]], 2);
        // One channel of six differs by 3: sqrt(9 / 6).
        assert!((rmse(&a, &b).unwrap_or(f64::NAN) - 1.5f64.sqrt()).abs() < 1e-12);
        assert_eq!(rmse(&a, &a), Ok(0.0));
        assert_eq!(rmse(&a, &b), rmse(&b, &a));
    }

    /// Hand-computed values (exact in f32/f64 up to rounding, tolerance 1e-12).
    #[test]
    fn metrics_match_their_definitions() {
        let reference = frame(vec![[1.0, 0.0, 0.5], [0.0, 0.0, 0.0]], 2);
        let estimate = frame(vec![[2.0, 0.0, 0.5], [0.0, 0.5, 0.0]], 2);
        let m = error_metrics(&estimate, &reference).expect("same size");
        // Squared errors 1 and 0.25 over 6 values.
        assert!((m.rmse - (1.25f64 / 6.0).sqrt()).abs() < 1e-12);
        // relMSE: 1 / (1 + 0.01) and 0.25 / (0 + 0.01), over 6 values.
        assert!((m.relative_mse - (1.0 / 1.01 + 25.0) / 6.0).abs() < 1e-12);
        assert_eq!(m.bias, [0.5, 0.25, 0.0]);
    }

    #[test]
    fn mismatched_sizes_are_an_error() {
        let a = frame(vec![[0.0; 3]; 4], 2);
        let b = frame(vec![[0.0; 3]; 4], 4);
        assert_eq!(rmse(&a, &b), Err(SizeMismatch(2, 2, 4, 1)));
        assert_eq!(error_metrics(&frame(vec![[0.0; 3]], 1), &b), Err(SizeMismatch(1, 1, 4, 1)));
    }
}
