//! Image error metrics for comparing a render with a reference: what the
//! benchmarks and convergence tests report.

use crate::film::Frame;

/// Two frames that cannot be compared pixel by pixel.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error("frames differ in size: {0}x{1} vs {2}x{3}")]
pub struct SizeMismatch(pub u32, pub u32, pub u32, pub u32);

/// Root-mean-square error over all pixels and the three channels, in linear
/// radiance: sqrt(Σ (a − b)² / (3 · pixels)). Zero for two empty frames.
pub fn rmse(a: &Frame, b: &Frame) -> Result<f64, SizeMismatch> {
    if a.width != b.width || a.height != b.height || a.pixels.len() != b.pixels.len() {
        return Err(SizeMismatch(a.width, a.height, b.width, b.height));
    }
    if a.pixels.is_empty() {
        return Ok(0.0);
    }
    let squared: f64 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| (0..3).map(|c| (p[c] as f64 - q[c] as f64).powi(2)).sum::<f64>())
        .sum();
    Ok((squared / (3 * a.pixels.len()) as f64).sqrt())
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

    #[test]
    fn mismatched_sizes_are_an_error() {
        let a = frame(vec![[0.0; 3]; 4], 2);
        let b = frame(vec![[0.0; 3]; 4], 4);
        assert_eq!(rmse(&a, &b), Err(SizeMismatch(2, 2, 4, 1)));
    }
}
