//! Looking closely at a frame, display only: the readout of one pixel, the
//! luminance histogram and the comparison with a reference image. Plain
//! functions of frames, so they are tested without a window.

use crate::color::luminance;
use crate::film::Frame;
use crate::metrics::{ErrorMetrics, error_metrics};
use crate::render::session::FrameInfo;
use glam::DVec3;

/// What the pixel under the cursor holds.
#[derive(Clone, Debug, PartialEq)]
pub struct PixelReadout {
    pub x: u32,
    pub y: u32,
    /// Linear radiance.
    pub rgb: [f32; 3],
    pub luminance: f64,
    /// Samples in this pixel, if known.
    pub samples: Option<u32>,
    /// Standard error of the mean luminance over the luminance; `None`
    /// without an estimate (fewer than two samples, or SPPM).
    pub relative_error: Option<f64>,
}

/// The readout of pixel (`x`, `y`) of a published frame, if it lies inside.
pub fn readout(info: &FrameInfo, x: u32, y: u32) -> Option<PixelReadout> {
    let frame = &info.frame;
    if x >= frame.width || y >= frame.height {
        return None;
    }
    let index = (y * frame.width + x) as usize;
    let rgb = *frame.pixels.get(index)?;
    let lum = luminance(DVec3::new(rgb[0] as f64, rgb[1] as f64, rgb[2] as f64));
    let samples = match &info.sample_counts {
        Some(counts) => counts.get(index).copied(),
        None if info.region.is_none() && !info.preview => Some(info.passes),
        None => None,
    };
    let relative_error = frame
        .noise
        .get(index)
        .map(|&e| e as f64)
        .filter(|e| info.noise_estimated && e.is_finite() && lum > 0.0)
        .map(|e| e / lum);
    Some(PixelReadout {
        x,
        y,
        rgb,
        luminance: lum,
        samples,
        relative_error,
    })
}

/// Lowest and highest bin edges of the histogram, in stops (log₂ luminance).
pub const HISTOGRAM_STOPS: (f64, f64) = (-12.0, 8.0);

/// Bins of the histogram: a quarter stop each.
pub const HISTOGRAM_BINS: usize = 80;

/// Pixel counts by log₂ luminance over [`HISTOGRAM_STOPS`] (values outside
/// go to the end bins), and the count of black pixels, which have no log.
#[derive(Clone, Debug, PartialEq)]
pub struct Histogram {
    pub bins: Vec<u32>,
    pub black: u32,
}

impl Histogram {
    pub fn of(frame: &Frame) -> Self {
        let (low, high) = HISTOGRAM_STOPS;
        let mut bins = vec![0u32; HISTOGRAM_BINS];
        let mut black = 0;
        for p in &frame.pixels {
            let lum = luminance(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
            // Black (and NaN, which compares false) has no log.
            if lum.is_nan() || lum <= 0.0 {
                black += 1;
                continue;
            }
            let t = (lum.log2() - low) / (high - low);
            let bin = (t * HISTOGRAM_BINS as f64).floor().clamp(0.0, (HISTOGRAM_BINS - 1) as f64) as usize;
            bins[bin] += 1;
        }
        Self { bins, black }
    }

    /// Where luminance `2^stops` falls, as a fraction of the histogram's width.
    pub fn position(stops: f64) -> f64 {
        let (low, high) = HISTOGRAM_STOPS;
        ((stops - low) / (high - low)).clamp(0.0, 1.0)
    }
}

/// Error of `frame` against `reference` (the metrics of `prism bench`), or
/// why there is none.
pub fn compare(frame: &Frame, reference: &Frame) -> Result<ErrorMetrics, String> {
    error_metrics(frame, reference).map_err(|_| {
        format!(
            "the reference is {}x{}, the image {}x{}",
            reference.width, reference.height, frame.width, frame.height
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::settings::RenderSettings;
    use std::sync::Arc;
    use std::time::Duration;

    fn info(pixels: Vec<[f32; 3]>, noise: Vec<f32>, counts: Option<Vec<u32>>) -> FrameInfo {
        FrameInfo {
            frame: Arc::new(Frame {
                width: 2,
                height: 1,
                pixels,
                noise,
            }),
            generation: 1,
            sequence: 1,
            camera: Camera::new(DVec3::Z, DVec3::ZERO, DVec3::Y, 40.0, 0.0, 1.0),
            settings: RenderSettings::default(),
            passes: 9,
            elapsed: Duration::ZERO,
            preview: false,
            radii: None,
            sample_counts: counts.map(Arc::new),
            noise_estimated: true,
            region: None,
        }
    }

    #[test]
    fn the_readout_reports_the_pixel_its_error_and_samples() {
        let shown = info(vec![[0.0; 3], [0.5, 0.5, 0.5]], vec![f32::INFINITY, 0.05], Some(vec![3, 7]));
        let pixel = readout(&shown, 1, 0).expect("inside");
        assert_eq!(pixel.rgb, [0.5; 3]);
        // Grey 0.5 has luminance 0.5 (the weights sum to 1); 0.05 / 0.5 = 10 %.
        assert!((pixel.luminance - 0.5).abs() < 1e-6);
        assert!((pixel.relative_error.expect("an estimate") - 0.1).abs() < 1e-6);
        assert_eq!(pixel.samples, Some(7));
        let unknown = readout(&shown, 0, 0).expect("inside");
        assert_eq!((unknown.relative_error, unknown.samples), (None, Some(3)));
        assert_eq!(readout(&shown, 2, 0), None);
        // Without per-pixel counts every pixel of a full pass has the pass count.
        let uniform = info(vec![[1.0; 3]; 2], Vec::new(), None);
        assert_eq!(readout(&uniform, 0, 0).map(|p| p.samples), Some(Some(9)));
    }

    #[test]
    fn the_histogram_bins_by_stops() {
        let frame = Frame {
            width: 4,
            height: 1,
            // Luminance 1 (0 stops), 1 again, 1/4 (−2 stops), black.
            pixels: vec![[1.0; 3], [1.0; 3], [0.25; 3], [0.0; 3]],
            noise: Vec::new(),
        };
        let histogram = Histogram::of(&frame);
        let bin = |stops: f64| (Histogram::position(stops) * HISTOGRAM_BINS as f64) as usize;
        assert_eq!(histogram.bins[bin(0.0)], 2);
        assert_eq!(histogram.bins[bin(-2.0)], 1);
        assert_eq!(histogram.black, 1);
        assert_eq!(histogram.bins.iter().sum::<u32>(), 3);
    }
}
