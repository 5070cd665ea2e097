//! A denoised preview of a progressive render, for display only: the film and
//! its frames stay unbiased and untouched; this makes a new, filtered frame.
//!
//! 1. [`Guides`]: first-hit albedo and normal per pixel (a pass of its own);
//! 2. the radiance is divided by the albedo, so the filter smooths lighting
//!    and the texture comes back sharp when multiplied in again (SVGF's
//!    demodulation, Schied et al. 2017);
//! 3. the edge-avoiding à-trous wavelet filter (`atrous`; Dammertz et al.
//!    2010), its luminance weight scaled by each pixel's estimated standard
//!    deviation (from `Frame::noise`, so the filter backs off by itself as
//!    samples accumulate), or by a fixed fraction of its luminance where the
//!    integrator gives no noise estimate.
//!
//! [`clamp_fireflies`] is a separate, optional and biased display aid: it
//! caps each pixel's luminance, which removes energy.
//!
//! Nothing here knows about any UI toolkit; `prism bench --denoise` and
//! `benches/denoise.rs` measure it.

mod atrous;
pub mod guides;

pub use guides::Guides;

use crate::film::Frame;
use atrous::{Plane, Signal};

/// Parameters of the filter. The defaults are SVGF's (σl = 4; the normal
/// weight's exponent is fixed at SVGF's 128) with five iterations (a footprint of 63 pixels).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DenoiseSettings {
    /// Filter iterations, 1 to 5; iteration i has taps 2^i pixels apart.
    pub iterations: u32,
    /// Luminance tolerance in standard deviations of the centre pixel.
    pub sigma_luminance: f32,
    /// Relative standard error assumed where a pixel has no noise estimate
    /// (fewer than two samples, or an integrator without one).
    pub assumed_relative_error: f32,
}

impl Default for DenoiseSettings {
    fn default() -> Self {
        Self {
            iterations: atrous::MAX_ITERATIONS,
            sigma_luminance: 4.0,
            assumed_relative_error: 0.5,
        }
    }
}

/// Why a frame cannot be denoised.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum DenoiseError {
    /// The guides' width and height, then the frame's: the guides were made
    /// for another image size (or their buffers have the wrong length).
    #[error("the guides are {0}x{1} but the frame is {2}x{3}")]
    SizeMismatch(u32, u32, u32, u32),
}

/// Albedo below this (per channel) is not divided out: dividing by it would
/// amplify the noise of a channel the surface hardly reflects.
const MIN_ALBEDO: f32 = 0.02;

/// Luminance below which relative errors are measured against this floor
/// instead, so black pixels do not get a zero tolerance.
const LUMINANCE_FLOOR: f32 = 1e-3;

/// The filtered frame; its `noise` is left empty (the filter's output has no
/// per-pixel standard error of the kind `Frame::noise` holds).
pub fn denoise(frame: &Frame, guides: &Guides, settings: &DenoiseSettings) -> Result<Frame, DenoiseError> {
    if (guides.width, guides.height) != (frame.width, frame.height)
        || guides.albedo.len() != frame.pixels.len()
        || guides.normal.len() != frame.pixels.len()
    {
        return Err(DenoiseError::SizeMismatch(
            guides.width,
            guides.height,
            frame.width,
            frame.height,
        ));
    }
    let (width, height) = (frame.width as usize, frame.height as usize);
    if width == 0 || height == 0 {
        return Ok(frame.clone());
    }
    // The radiance divided by the albedo (where there is one), and the
    // variance of its luminance.
    let mut color = [0; 3].map(|_| Plane::zeros(width, height));
    let mut luminance_plane = Plane::zeros(width, height);
    let mut variance = Plane::zeros(width, height);
    for y in 0..height {
        let [r, g, b] = &mut color;
        let rows = [r.row_mut(y), g.row_mut(y), b.row_mut(y)];
        let luminance_row = luminance_plane.row_mut(y);
        let variance_row = variance.row_mut(y);
        for x in 0..width {
            let i = y * width + x;
            let divisor = guides.albedo[i].map(demodulation_divisor);
            let demodulated = [0, 1, 2].map(|c| {
                let v = frame.pixels[i][c];
                if v.is_finite() { v / divisor[c] } else { 0.0 }
            });
            for c in 0..3 {
                rows[c][x] = demodulated[c];
            }
            luminance_row[x] = luminance(demodulated);
            let deviation = match frame.noise.get(i).copied().filter(|e| e.is_finite()) {
                Some(error) => error / luminance(divisor),
                None => settings.assumed_relative_error * luminance(demodulated).max(LUMINANCE_FLOOR),
            };
            variance_row[x] = deviation * deviation;
        }
    }
    for plane in color.iter_mut().chain([&mut luminance_plane, &mut variance]) {
        plane.replicate_edges();
    }
    let signal = Signal {
        color,
        luminance: luminance_plane,
        variance,
    };
    let filtered = atrous::filter(signal, guides.planes(), settings);
    let mut pixels = Vec::with_capacity(width * height);
    let [r, g, b] = filtered.each_ref().map(|p| p.rows());
    for (((r, g), b), albedo) in r.zip(g).zip(b).zip(guides.albedo.chunks_exact(width)) {
        for x in 0..width {
            let d = albedo[x].map(demodulation_divisor);
            pixels.push([r[x] * d[0], g[x] * d[1], b[x] * d[2]]);
        }
    }
    Ok(Frame {
        width: frame.width,
        height: frame.height,
        pixels,
        noise: Vec::new(),
    })
}

/// What a channel of radiance is divided by: its albedo, where there is one.
#[inline]
fn demodulation_divisor(albedo: f32) -> f32 {
    if albedo >= MIN_ALBEDO { albedo } else { 1.0 }
}

/// Rec. 709 luminance, as `color::luminance`.
#[inline]
fn luminance(c: [f32; 3]) -> f32 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// Caps every pixel's luminance at `max_luminance`, keeping its hue: hides
/// fireflies (rare, very bright samples) at the cost of bias, since the
/// energy above the cap is lost. For display only.
pub fn clamp_fireflies(frame: &mut Frame, max_luminance: f32) {
    for pixel in &mut frame.pixels {
        let luminance = luminance(*pixel);
        if luminance > max_luminance {
            let scale = max_luminance / luminance;
            *pixel = pixel.map(|c| c * scale);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn guides(width: u32, height: u32, albedo: impl Fn(usize) -> [f32; 3]) -> Guides {
        let count = (width * height) as usize;
        Guides::new(width, height, (0..count).map(albedo).collect(), vec![[0.0, 0.0, 1.0]; count])
    }

    /// White noise of known variance on a flat grey wall: the filtered image
    /// keeps the mean (the weights are normalised) and has far less variance.
    #[test]
    fn noise_on_a_flat_wall_is_smoothed_and_the_mean_kept() {
        let (width, height) = (64u32, 64u32);
        let count = (width * height) as usize;
        // A fixed pseudo-random sequence (xorshift), uniform in [0, 1).
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = move || (crate::math::xorshift64(&mut state) >> 40) as f32 / (1u64 << 24) as f32;
        // Mean 0.5, standard deviation 0.2/√3 ≈ 0.115 per pixel.
        let pixels: Vec<[f32; 3]> = (0..count).map(|_| [0.3 + 0.4 * uniform(); 3]).collect();
        let noise = vec![0.4 / 12f32.sqrt(); count];
        let frame = Frame {
            width,
            height,
            pixels,
            noise,
        };
        let filtered = denoise(&frame, &guides(width, height, |_| [0.5; 3]), &DenoiseSettings::default()).expect("same size");
        let stats = |f: &Frame| {
            let n = f.pixels.len() as f64;
            let mean = f.pixels.iter().map(|p| p[0] as f64).sum::<f64>() / n;
            let variance = f.pixels.iter().map(|p| (p[0] as f64 - mean).powi(2)).sum::<f64>() / n;
            (mean, variance)
        };
        let (raw_mean, raw_variance) = stats(&frame);
        let (mean, variance) = stats(&filtered);
        // Normalised weights keep a flat image's mean up to the edge
        // replication's reweighting: 1 % of 0.5 is well above that.
        assert!((mean - raw_mean).abs() < 0.005, "mean {raw_mean} → {mean}");
        // Averaging ~hundreds of independent pixels divides the variance by
        // far more than 10; 10 leaves room for the edge-stopping weights.
        assert!(variance < raw_variance / 10.0, "variance {raw_variance} → {variance}");
    }

    /// Two walls of different albedo meet at a vertical edge under the same
    /// light: the filter smooths the lighting (divided by albedo, the same on
    /// both sides) and multiplies each side's albedo back, so each keeps its
    /// own colour exactly (noise-free input) instead of blurring into the other.
    #[test]
    fn albedo_edges_are_kept() {
        let (width, height) = (32u32, 16u32);
        let albedo = |i: usize| if i % 32 < 16 { [0.8, 0.1, 0.1] } else { [0.1, 0.8, 0.1] };
        let pixels: Vec<[f32; 3]> = (0..512).map(|i| albedo(i).map(|a| a * 2.0)).collect();
        let frame = Frame {
            width,
            height,
            pixels: pixels.clone(),
            noise: vec![0.05; 512],
        };
        let filtered = denoise(&frame, &guides(width, height, albedo), &DenoiseSettings::default()).expect("same size");
        for (i, (a, b)) in filtered.pixels.iter().zip(&pixels).enumerate() {
            for c in 0..3 {
                // Only f32 rounding of the division and the weighted mean.
                assert!(
                    (a[c] - b[c]).abs() <= 1e-5 * b[c].max(0.1),
                    "pixel {i} channel {c}: {a:?} vs {b:?}"
                );
            }
        }
    }

    #[test]
    fn guides_of_another_size_are_an_error() {
        let frame = Frame {
            width: 4,
            height: 4,
            pixels: vec![[0.0; 3]; 16],
            noise: Vec::new(),
        };
        let result = denoise(&frame, &guides(2, 2, |_| [1.0; 3]), &DenoiseSettings::default());
        assert_eq!(result, Err(DenoiseError::SizeMismatch(2, 2, 4, 4)));
    }

    #[test]
    fn the_firefly_clamp_caps_luminance_and_keeps_hue() {
        let mut frame = Frame {
            width: 2,
            height: 1,
            pixels: vec![[100.0, 50.0, 0.0], [0.5, 0.5, 0.5]],
            noise: Vec::new(),
        };
        clamp_fireflies(&mut frame, 4.0);
        let [r, g, b] = frame.pixels[0];
        assert!((0.2126 * r + 0.7152 * g + 0.0722 * b - 4.0).abs() < 1e-4);
        assert!((r / g - 2.0).abs() < 1e-5 && b == 0.0);
        assert_eq!(frame.pixels[1], [0.5; 3]);
    }
}
