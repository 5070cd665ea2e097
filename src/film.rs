//! The film: per-pixel sums in f64 (f32 sums stop absorbing new samples after
//! ~10⁷ of them), sample counts and the second moment the noise estimate needs;
//! and `Frame`, the linear snapshot that viewers, image files and benchmarks read.

use crate::color::{Color, luminance, srgb_encode_8bit};

/// Running sums of one pixel's samples.
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelAccumulator {
    pub sum: Color,
    /// Sum of squared luminance, for the variance of the mean.
    pub luminance_squared_sum: f64,
    pub count: u32,
}

impl PixelAccumulator {
    #[inline]
    pub fn add(&mut self, sample: Color) {
        self.sum += sample;
        let y = luminance(sample);
        self.luminance_squared_sum += y * y;
        self.count += 1;
    }

    pub fn mean(&self) -> Color {
        if self.count == 0 {
            Color::ZERO
        } else {
            self.sum / self.count as f64
        }
    }

    /// Standard error of the pixel's mean luminance (unbiased sample variance / n).
    pub fn standard_error(&self) -> f64 {
        if self.count < 2 {
            return f64::INFINITY;
        }
        let n = self.count as f64;
        let mean = luminance(self.sum) / n;
        let variance = ((self.luminance_squared_sum - n * mean * mean) / (n - 1.0)).max(0.0);
        (variance / n).sqrt()
    }
}

#[derive(Clone, Debug)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<PixelAccumulator>,
    /// Samples that came back NaN or infinite and were dropped.
    pub rejected_samples: u64,
}

impl Film {
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![PixelAccumulator::default(); width as usize * height as usize],
            rejected_samples: 0,
        }
    }

    /// The current estimate, linear.
    pub fn frame(&self) -> Frame {
        Frame {
            width: self.width,
            height: self.height,
            pixels: self.pixels.iter().map(|p| p.mean().as_vec3().to_array()).collect(),
            noise: self.pixels.iter().map(|p| p.standard_error() as f32).collect(),
        }
    }
}

/// A linear-radiance image, row-major from the top-left.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
    /// Per-pixel standard error of mean luminance; empty when unknown.
    pub noise: Vec<f32>,
}

/// How linear radiance becomes a displayable value in [0, 1].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ToneMap {
    /// Clip at 1 (what smallpt does).
    #[default]
    Clamp,
    /// x / (1 + x) per channel (Reinhard et al. 2002).
    Reinhard,
    /// Narkowicz's fit of the ACES filmic curve (2015).
    Filmic,
}

impl ToneMap {
    pub const ALL: [ToneMap; 3] = [ToneMap::Clamp, ToneMap::Reinhard, ToneMap::Filmic];

    pub fn apply(self, x: f64) -> f64 {
        let x = x.max(0.0);
        match self {
            ToneMap::Clamp => x.min(1.0),
            ToneMap::Reinhard => x / (1.0 + x),
            ToneMap::Filmic => ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0),
        }
    }
}

impl Frame {
    /// 8-bit sRGB pixels after exposure (in stops) and tone mapping.
    pub fn to_srgb8(&self, exposure_stops: f64, tone_map: ToneMap) -> Vec<[u8; 3]> {
        let scale = exposure_stops.exp2();
        self.pixels
            .iter()
            .map(|p| p.map(|c| srgb_encode_8bit(tone_map.apply(c as f64 * scale))))
            .collect()
    }

    /// Mean of each channel over the image.
    pub fn channel_means(&self) -> [f64; 3] {
        let n = self.pixels.len().max(1) as f64;
        let mut sum = [0.0; 3];
        for p in &self.pixels {
            for c in 0..3 {
                sum[c] += p[c] as f64;
            }
        }
        sum.map(|s| s / n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accumulator_mean_and_error() {
        let mut p = PixelAccumulator::default();
        for v in [1.0, 3.0] {
            p.add(Color::splat(v));
        }
        assert_eq!(p.mean(), Color::splat(2.0));
        // Sample variance of {1, 3} is 2; standard error sqrt(2/2) = 1.
        assert!((p.standard_error() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn tone_maps_stay_in_range() {
        for t in ToneMap::ALL {
            for x in [0.0, 0.5, 1.0, 100.0] {
                let y = t.apply(x);
                assert!((0.0..=1.0).contains(&y));
            }
        }
    }
}
