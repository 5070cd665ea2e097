//! Turning a linear `Frame` into what the window shows: the tone-mapped
//! image (exposure and tone map are applied here, so they never restart the
//! render, as in Nori), whole or a band of rows (a region render uploads
//! only the rows it changed), or a heatmap of the per-pixel noise, the SPPM
//! radii or the difference from a reference; and the image-wide noise
//! estimate for the status line.

use crate::color::{luminance, srgb_encode};
use crate::film::{Frame, ToneMap};
use egui::{Color32, ColorImage};
use glam::DVec3;
use std::ops::Range;
use std::sync::OnceLock;

/// Entries of the sRGB encoding table over [0, 1]: the curve's steepest part
/// (slope 12.92 near 0) moves by 12.92 · 255 / 16384 ≈ 0.2 of an 8-bit code
/// per entry, so the table never shifts a value by a visible step.
const SRGB_TABLE_SIZE: usize = 16384;

fn srgb_table() -> &'static [u8] {
    static TABLE: OnceLock<Vec<u8>> = OnceLock::new();
    TABLE.get_or_init(|| {
        (0..SRGB_TABLE_SIZE)
            .map(|i| (srgb_encode(i as f64 / (SRGB_TABLE_SIZE - 1) as f64) * 255.0 + 0.5) as u8)
            .collect()
    })
}

/// Linear display value in [0, 1] to an 8-bit sRGB code.
#[inline]
fn encode(table: &[u8], value: f64) -> u8 {
    let index = (value.clamp(0.0, 1.0) * (SRGB_TABLE_SIZE - 1) as f64 + 0.5) as usize;
    table[index.min(SRGB_TABLE_SIZE - 1)]
}

/// The frame after exposure (in stops) and tone mapping, sRGB-encoded.
pub fn tone_mapped(frame: &Frame, exposure_stops: f64, tone_map: ToneMap) -> ColorImage {
    tone_mapped_rows(frame, exposure_stops, tone_map, 0..frame.height as usize)
}

/// Rows `rows` of the tone-mapped frame, as an image of their own.
pub fn tone_mapped_rows(frame: &Frame, exposure_stops: f64, tone_map: ToneMap, rows: Range<usize>) -> ColorImage {
    let table = srgb_table();
    let scale = exposure_stops.exp2();
    let width = frame.width as usize;
    let pixels = frame.pixels[rows.start * width..rows.end * width]
        .iter()
        .map(|p| {
            let [r, g, b] = p.map(|c| encode(table, tone_map.apply(c as f64 * scale)));
            Color32::from_rgb(r, g, b)
        })
        .collect();
    ColorImage::new([width, rows.len()], pixels)
}

/// Per pixel, how far `frame` is from `reference` relative to the
/// reference (|Δluminance| / (luminance + 0.01)), on the noise view's log
/// scale: dark blue 0.1 %, white 100 % or more. `None` if the sizes differ.
pub fn difference_heatmap(frame: &Frame, reference: &Frame) -> Option<ColorImage> {
    if (frame.width, frame.height) != (reference.width, reference.height) || frame.pixels.len() != reference.pixels.len() {
        return None;
    }
    let lum = |p: &[f32; 3]| luminance(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
    let pixels = frame
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, b)| {
            let relative = (lum(a) - lum(b)).abs() / (lum(b) + 0.01);
            heat_color(((relative.max(1e-3).log10() + 3.0) / 3.0).clamp(0.0, 1.0))
        })
        .collect();
    Some(ColorImage::new([frame.width as usize, frame.height as usize], pixels))
}

/// Relative standard error of a pixel's mean (standard error / mean luminance).
fn relative_error(frame: &Frame, index: usize) -> f64 {
    let [r, g, b] = frame.pixels[index];
    let mean = luminance(DVec3::new(r as f64, g as f64, b as f64));
    let error = frame.noise.get(index).copied().unwrap_or(f32::INFINITY) as f64;
    if mean > 0.0 {
        error / mean
    } else if error > 0.0 {
        f64::INFINITY
    } else {
        0.0
    }
}

/// A heatmap of the per-pixel relative error on a log scale from 0.1 %
/// (dark blue) to 100 % or unknown (white). Pixels with fewer than two
/// samples have no variance estimate and show as unknown.
pub fn noise_heatmap(frame: &Frame) -> ColorImage {
    let pixels = (0..frame.pixels.len())
        .map(|i| {
            let relative = relative_error(frame, i);
            let t = if relative.is_finite() {
                ((relative.max(1e-3).log10() + 3.0) / 3.0).clamp(0.0, 1.0)
            } else {
                1.0
            };
            heat_color(t)
        })
        .collect();
    ColorImage::new([frame.width as usize, frame.height as usize], pixels)
}

/// The smallest and largest positive gather radius, if any.
pub fn radii_range(radii: &[f32]) -> Option<(f32, f32)> {
    let positive = radii.iter().copied().filter(|r| *r > 0.0 && r.is_finite());
    positive.fold(None, |range, r| match range {
        None => Some((r, r)),
        Some((lo, hi)) => Some((lo.min(r), hi.max(r))),
    })
}

/// A heatmap of SPPM's per-pixel gather radii on a log scale from the
/// smallest (dark) to the largest (white) current radius; pixels without a
/// radius yet are black. When every radius is the same (an absolute initial
/// radius at the first iteration) they all show the ramp's middle colour,
/// and the legend says so.
pub fn radii_heatmap(width: u32, height: u32, radii: &[f32]) -> ColorImage {
    let (low, high) = radii_range(radii).map_or((1.0, 1.0), |(lo, hi)| ((lo as f64).ln(), (hi as f64).ln()));
    // Below a relative spread of 1e-6 the radii are equal up to rounding.
    let equal = high - low < 1e-6;
    let pixels = radii
        .iter()
        .map(|&r| {
            if !(r > 0.0 && r.is_finite()) {
                Color32::BLACK
            } else if equal {
                heat_color(0.5)
            } else {
                heat_color(0.1 + 0.9 * ((r as f64).ln() - low) / (high - low))
            }
        })
        .collect();
    ColorImage::new([width as usize, height as usize], pixels)
}

/// A perceptually ordered ramp: black → blue → red → yellow → white.
pub fn heat_color(t: f64) -> Color32 {
    const STOPS: [[f64; 3]; 5] = [
        [0.0, 0.0, 0.05],
        [0.1, 0.2, 0.8],
        [0.85, 0.1, 0.2],
        [1.0, 0.85, 0.1],
        [1.0, 1.0, 1.0],
    ];
    let x = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let i = (x as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    let c = |k: usize| ((STOPS[i][k] * (1.0 - f) + STOPS[i + 1][k] * f) * 255.0 + 0.5) as u8;
    Color32::from_rgb(c(0), c(1), c(2))
}

/// The image's noise level: root-mean-square per-pixel standard error over
/// the mean luminance of the image, or `None` while most pixels have fewer
/// than two samples.
pub fn noise_estimate(frame: &Frame) -> Option<f64> {
    if frame.noise.len() != frame.pixels.len() || frame.pixels.is_empty() {
        return None;
    }
    let mut squared = 0.0;
    let mut count = 0usize;
    for &error in &frame.noise {
        if error.is_finite() {
            squared += (error as f64) * (error as f64);
            count += 1;
        }
    }
    if count * 2 < frame.noise.len() {
        return None;
    }
    let [r, g, b] = frame.channel_means();
    let mean = luminance(DVec3::new(r, g, b));
    (mean > 0.0).then(|| (squared / count as f64).sqrt() / mean)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(pixels: Vec<[f32; 3]>, noise: Vec<f32>) -> Frame {
        Frame {
            width: pixels.len() as u32,
            height: 1,
            pixels,
            noise,
        }
    }

    #[test]
    fn table_matches_the_exact_encoding() {
        // Tolerance: one 8-bit code, the table's rounding (see SRGB_TABLE_SIZE).
        let table = srgb_table();
        for i in 0..=1000 {
            let x = i as f64 / 1000.0;
            let exact = (srgb_encode(x) * 255.0 + 0.5) as i32;
            assert!((encode(table, x) as i32 - exact).abs() <= 1, "x = {x}");
        }
    }

    #[test]
    fn exposure_scales_before_tone_mapping() {
        let f = frame(vec![[0.25, 0.25, 0.25]], Vec::new());
        let plus_two = tone_mapped(&f, 2.0, ToneMap::Clamp);
        // 0.25 · 2² = 1 → white.
        assert_eq!(plus_two.pixels[0], Color32::WHITE);
        let plain = tone_mapped(&f, 0.0, ToneMap::Clamp);
        assert!(plain.pixels[0].r() < 255);
    }

    #[test]
    fn noise_estimate_is_relative_rms_error() {
        // Two grey pixels of luminance 0.5 with errors 0.03 and 0.04: RMS 0.03536, relative 0.0707.
        let f = frame(vec![[0.5; 3], [0.5; 3]], vec![0.03, 0.04]);
        let estimate = noise_estimate(&f).expect("estimate");
        let expected = ((0.03f64.powi(2) + 0.04f64.powi(2)) / 2.0).sqrt() / 0.5;
        assert!((estimate - expected).abs() < 1e-6, "{estimate} vs {expected}");
        let unknown = frame(vec![[0.5; 3]], vec![f32::INFINITY]);
        assert_eq!(noise_estimate(&unknown), None);
    }
}
