//! The film: per-pixel sums, sample counts and the second moment the noise
//! estimate needs; and `Frame`, the linear snapshot that viewers, image files
//! and benchmarks read.
//!
//! Sums are kept in fixed point, in integers: integer addition is
//! associative, so a pixel's sums do not depend on how its samples were
//! grouped. That is what lets a render split into sample ranges on many
//! machines merge into exactly the film one machine would have made
//! (`crate::farm`); f64 sums would differ in their last bits, since
//! (a + b) + c ≠ a + (b + c) in floating point. It also never stops absorbing
//! samples, as f32 sums do after ~10⁷ of them.
//!
//! Units and limits (each sample is converted once, exactly where it can be):
//! - colour sums: i128 with [`COLOR_FRACTION_BITS`] = 64 fractional bits, a
//!   resolution of 2⁻⁶⁴ ≈ 5.4·10⁻²⁰ (samples ≥ 2⁻¹¹ convert without any
//!   rounding, as their 53-bit mantissas fit);
//! - squared luminance sum: u128 with [`SQUARE_FRACTION_BITS`] = 32
//!   fractional bits (2.3·10⁻¹⁰ per sample; the noise estimate it feeds
//!   compares variances of at least ~10⁻⁸ for the darkest pixel adaptive
//!   sampling judges, see `integrator::pass`, so this is far below what it
//!   could notice);
//! - a sample is accepted if every channel is finite and below
//!   [`MAX_SAMPLE_VALUE`] = 2³¹ in magnitude (radiance far beyond any scene's
//!   lights); then even 2³² samples of the largest value fit in both sums.
//!   Other samples are counted as rejected, as NaN ones always were.

use crate::color::{Color, luminance, srgb_encode_8bit};
use rayon::prelude::*;
use std::ops::Range;

/// Fractional bits of the colour sums (see the module doc).
pub const COLOR_FRACTION_BITS: u32 = 64;
/// Fractional bits of the squared-luminance sum (see the module doc).
pub const SQUARE_FRACTION_BITS: u32 = 32;
/// A sample channel must be below this in magnitude to be accepted: 2³¹.
pub const MAX_SAMPLE_VALUE: f64 = 2_147_483_648.0;

/// 2⁶⁴ and 2³², as f64 (exact).
const TWO_POW_64: f64 = 18_446_744_073_709_551_616.0;
const TWO_POW_32: f64 = 4_294_967_296.0;

/// Whether a sample can be added: every channel finite and below
/// [`MAX_SAMPLE_VALUE`] in magnitude.
#[inline]
pub fn accepts(sample: Color) -> bool {
    // `max_element` skips NaN, so finiteness is checked first.
    sample.is_finite() && sample.abs().max_element() < MAX_SAMPLE_VALUE
}

/// `value` (finite, |value| < 2⁵³; accepted samples are below 2³¹) in fixed
/// point with 64 fractional bits, rounded toward zero: trunc(value · 2⁶⁴).
#[inline]
fn fixed_64(value: f64) -> i128 {
    let magnitude = truncated_fixed_point(value, COLOR_FRACTION_BITS) as i128;
    // Two's complement negation by mask, not a branch on the sign (which
    // samples of spectral renders flip unpredictably).
    let negative = i128::from((value.to_bits() as i64) >> 63);
    (magnitude ^ negative) - negative
}

/// Adds `sample` (accepted) to per-channel sums kept in units of 2⁻⁶⁴.
#[inline]
fn add_color(sums: &mut [i128; 3], sample: Color) {
    for (sum, value) in sums.iter_mut().zip(sample.to_array()) {
        *sum = sum.wrapping_add(fixed_64(value));
    }
}

/// Adds per-channel sums to per-channel sums (exact, in any order).
#[inline]
fn add_sums(sums: &mut [i128; 3], other: [i128; 3]) {
    for (sum, other) in sums.iter_mut().zip(other) {
        *sum = sum.wrapping_add(other);
    }
}

/// A non-negative `value` (finite, < 2⁶³) with 32 fractional bits, rounded
/// toward zero: trunc(value · 2³²).
#[inline]
fn fixed_32(value: f64) -> u128 {
    truncated_fixed_point(value, SQUARE_FRACTION_BITS)
}

/// trunc(|value| · 2^`fraction_bits`) for finite |value| below
/// 2^(117 − `fraction_bits`) (2⁵³ for 64 fractional bits, 2⁸⁵ for 32), read
/// off the bits: |value| = m · 2^(e − 1075) for the 53-bit significand m and
/// biased exponent e (taken as 1 for subnormals, whose m lacks the implicit
/// bit), so the fixed-point value is m · 2^(e − 1075 + `fraction_bits`) =
/// (m · 2⁶⁴) >> (1139 − `fraction_bits` − e). In that range the shift is
/// not negative, and a right shift drops exactly the bits below the point,
/// i.e. truncates; m · 2⁶⁴ < 2¹¹⁷, so shifts of 127 and more give 0 and the
/// shift is clamped there. Floating-point to integer conversions cost more
/// here: x86-64 has none for unsigned or 128-bit integers, and Rust's
/// saturating casts add range checks.
#[inline]
fn truncated_fixed_point(value: f64, fraction_bits: u32) -> u128 {
    const SIGNIFICAND_BITS: u32 = 52;
    let bits = value.to_bits();
    let biased_exponent = ((bits >> SIGNIFICAND_BITS) & 0x7ff) as u32;
    let is_normal = u64::from(biased_exponent != 0);
    let significand = (bits & ((1 << SIGNIFICAND_BITS) - 1)) | (is_normal << SIGNIFICAND_BITS);
    let exponent = biased_exponent.max(1);
    let shift = (1075 + 64 - fraction_bits).saturating_sub(exponent).min(127);
    (u128::from(significand) << 64) >> shift
}

/// Running sums of one pixel's samples, exact (see the module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PixelAccumulator {
    /// Σ sample per channel, in units of 2⁻⁶⁴.
    sum: [i128; 3],
    /// Σ luminance², in units of 2⁻³², for the variance of the mean.
    luminance_squared_sum: u128,
    /// Samples added.
    pub count: u32,
}

/// A pixel's sums as the integers they are kept in: what film files store.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExactSums {
    /// Σ sample per channel, in units of 2⁻⁶⁴ ([`COLOR_FRACTION_BITS`]).
    pub sum: [i128; 3],
    /// Σ luminance², in units of 2⁻³² ([`SQUARE_FRACTION_BITS`]).
    pub luminance_squared_sum: u128,
    /// Samples added.
    pub count: u32,
}

impl PixelAccumulator {
    /// Adds one sample if [`accepts`] it; returns whether it did.
    #[inline]
    pub fn add(&mut self, sample: Color) -> bool {
        if !accepts(sample) {
            return false;
        }
        add_color(&mut self.sum, sample);
        let y = luminance(sample);
        self.luminance_squared_sum = self.luminance_squared_sum.wrapping_add(fixed_32(y * y));
        self.count += 1;
        true
    }

    /// Adds another accumulator's samples (exactly: the result does not
    /// depend on the order of merges). `None`, leaving `self` unchanged, if
    /// the count would pass `u32::MAX`.
    pub fn merge(&mut self, other: &PixelAccumulator) -> Option<()> {
        self.count = self.count.checked_add(other.count)?;
        add_sums(&mut self.sum, other.sum);
        self.luminance_squared_sum = self.luminance_squared_sum.wrapping_add(other.luminance_squared_sum);
        Some(())
    }

    /// The sums as stored.
    pub fn exact_sums(&self) -> ExactSums {
        ExactSums {
            sum: self.sum,
            luminance_squared_sum: self.luminance_squared_sum,
            count: self.count,
        }
    }

    /// An accumulator holding `sums` (e.g. read from a film file).
    pub fn from_exact_sums(sums: ExactSums) -> Self {
        Self {
            sum: sums.sum,
            luminance_squared_sum: sums.luminance_squared_sum,
            count: sums.count,
        }
    }

    /// Σ samples, as the nearest f64 per channel.
    pub fn sum(&self) -> Color {
        Color::from_array(self.sum.map(|s| s as f64 / TWO_POW_64))
    }

    /// Σ luminance², as the nearest f64.
    pub fn luminance_squared_sum(&self) -> f64 {
        self.luminance_squared_sum as f64 / TWO_POW_32
    }

    /// The pixel's estimate: the mean of its samples (black before the first).
    pub fn mean(&self) -> Color {
        self.mean_of(self.sum())
    }

    /// [`Self::mean`], given [`Self::sum`].
    fn mean_of(&self, sum: Color) -> Color {
        if self.count == 0 {
            Color::ZERO
        } else {
            sum / self.count as f64
        }
    }

    /// Standard error of the pixel's mean luminance (unbiased sample variance / n).
    pub fn standard_error(&self) -> f64 {
        self.standard_error_of(self.sum())
    }

    /// [`Self::standard_error`], given [`Self::sum`].
    fn standard_error_of(&self, sum: Color) -> f64 {
        if self.count < 2 {
            return f64::INFINITY;
        }
        let n = self.count as f64;
        let mean = luminance(sum) / n;
        let variance = ((self.luminance_squared_sum() - n * mean * mean) / (n - 1.0)).max(0.0);
        (variance / n).sqrt()
    }
}

/// Contributions of paths traced from the lights and splatted onto the film
/// wherever they reach the lens (`integrator::path::caustic_paths`): per
/// pixel, Σ contribution in the colour sums' fixed point, so the sums are
/// exact and order-free like the camera samples'. Every pass traces
/// `paths_per_pass` light paths, so a pixel with n camera samples (n
/// passes) adds Σ / (`paths_per_pass` · n) to its estimate.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LightSplats {
    /// Light paths traced per pass, over the whole image.
    pub paths_per_pass: u64,
    /// Σ per channel and pixel (row-major), in units of 2⁻⁶⁴.
    pub sums: Vec<[i128; 3]>,
}

impl LightSplats {
    /// No splats yet, for `pixels` pixels.
    pub fn new(paths_per_pass: u64, pixels: usize) -> Self {
        Self {
            paths_per_pass,
            sums: vec![[0; 3]; pixels],
        }
    }

    /// Adds a contribution to pixel `index` if [`accepts`] it; returns whether it did.
    pub fn add(&mut self, index: usize, value: Color) -> bool {
        if !accepts(value) {
            return false;
        }
        add_color(&mut self.sums[index], value);
        true
    }

    /// Adds another film's light sums pixel by pixel (exact, order-free);
    /// both must trace the same light paths per pass and have as many pixels.
    pub fn merge(&mut self, other: &LightSplats) {
        for (sums, other) in self.sums.iter_mut().zip(&other.sums) {
            add_sums(sums, *other);
        }
    }

    /// What pixel `index` adds to the estimate after `passes` passes.
    pub fn radiance(&self, index: usize, passes: u32) -> Color {
        if passes == 0 || self.paths_per_pass == 0 {
            return Color::ZERO;
        }
        let sum = Color::from_array(self.sums[index].map(|s| s as f64 / TWO_POW_64));
        sum / (self.paths_per_pass as f64 * passes as f64)
    }
}

/// The accumulated samples of a whole image (or of a farm part's share of
/// it). Integrators add samples to it; [`Film::frame`] turns it into the
/// linear image everything downstream reads.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Film {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// One accumulator per pixel, row-major from the top-left
    /// (`y * width + x`).
    pub pixels: Vec<PixelAccumulator>,
    /// Samples that came back NaN, infinite or beyond [`MAX_SAMPLE_VALUE`]
    /// and were dropped.
    pub rejected_samples: u64,
    /// Light-path contributions, for path tracing with caustics traced from
    /// the lights; `None` for films of camera samples alone.
    pub light: Option<LightSplats>,
}

/// Why two films cannot be added.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FilmMergeError {
    /// The first film's width and height, then the second's.
    #[error("the films differ in size ({0}×{1} and {2}×{3})")]
    Size(u32, u32, u32, u32),
    /// Merging would push this pixel's (row-major index) sample count past
    /// `u32::MAX`.
    #[error("pixel {0} would hold more than {max} samples", max = u32::MAX)]
    CountOverflow(usize),
    /// One film has light-path contributions and the other not, or they
    /// trace different numbers of light paths per pass.
    #[error("the films were rendered with different light paths (caustic_light_paths)")]
    LightPaths,
}

impl Film {
    /// An empty film of `width` × `height` pixels.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![PixelAccumulator::default(); width as usize * height as usize],
            rejected_samples: 0,
            light: None,
        }
    }

    /// Adds another film's samples pixel by pixel. Exact and order-free: any
    /// grouping of the same films gives the same bits. On error `self` may
    /// be partly merged.
    pub fn merge(&mut self, other: &Film) -> Result<(), FilmMergeError> {
        if (self.width, self.height) != (other.width, other.height) {
            return Err(FilmMergeError::Size(self.width, self.height, other.width, other.height));
        }
        match (&mut self.light, &other.light) {
            (None, None) => {}
            (Some(light), Some(other)) if light.paths_per_pass == other.paths_per_pass => light.merge(other),
            // An empty film takes the other's light paths.
            (None, Some(other)) if self.pixels.iter().all(|p| p.count == 0) => self.light = Some(other.clone()),
            _ => return Err(FilmMergeError::LightPaths),
        }
        for (index, (pixel, other)) in self.pixels.iter_mut().zip(&other.pixels).enumerate() {
            pixel.merge(other).ok_or(FilmMergeError::CountOverflow(index))?;
        }
        self.rejected_samples = self.rejected_samples.saturating_add(other.rejected_samples);
        Ok(())
    }

    /// Samples held, over all pixels.
    pub fn sample_count(&self) -> u64 {
        self.pixels.iter().map(|p| p.count as u64).sum()
    }

    /// The current estimate, linear, with each pixel's noise estimate.
    ///
    /// Built in parallel on the current rayon pool, each pixel's sums
    /// converted once for both values: the viewer builds a frame after
    /// every pass, and the conversions of the exact integer sums to floats
    /// are library routines (x86-64 has no instruction for them). Built
    /// one pixel after another on the viewer's render thread, a 512 × 512
    /// frame took 15 ms, an eighth to a quarter of a two-thread pass's
    /// time, while the render pool waited.
    pub fn frame(&self) -> Frame {
        let (pixels, noise) = (0..self.pixels.len())
            .into_par_iter()
            .with_min_len(FRAME_PIXELS_PER_JOB)
            .map(|index| self.estimate(index))
            .unzip();
        Frame {
            width: self.width,
            height: self.height,
            pixels,
            noise,
        }
    }

    /// The estimate in `columns` × `rows` over a copy of `backdrop`, which
    /// has the film's size: what the viewer shows during a region render
    /// (the region over the image of before), computing only the region's
    /// pixels, as [`Film::frame`] does them.
    pub fn frame_over(&self, backdrop: &Frame, columns: Range<usize>, rows: Range<usize>) -> Frame {
        backdrop.with_region(columns, rows, |index| self.estimate(index))
    }

    /// Pixel `index`'s estimate (camera samples and light paths) and the
    /// standard error of its camera samples' luminance, its sums converted
    /// once for both.
    fn estimate(&self, index: usize) -> ([f32; 3], f32) {
        let pixel = &self.pixels[index];
        let sum = pixel.sum();
        let mean = pixel.mean_of(sum);
        let value = match &self.light {
            None => mean,
            Some(light) => mean + light.radiance(index, pixel.count),
        };
        (value.as_vec3().to_array(), pixel.standard_error_of(sum) as f32)
    }
}

/// Pixels per parallel job of a sweep over the film ([`Film::frame`],
/// adaptive sampling's progress): tens of microseconds each.
pub(crate) const FRAME_PIXELS_PER_JOB: usize = 4096;

/// A linear-radiance image, row-major from the top-left.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Linear RGB radiance per pixel, row-major from the top-left
    /// (`y * width + x`): the mean of the pixel's samples, before exposure
    /// and tone mapping.
    pub pixels: Vec<[f32; 3]>,
    /// Per-pixel standard error of mean luminance; empty when unknown.
    pub noise: Vec<f32>,
}

impl Frame {
    /// A copy with the pixels in `columns` × `rows` replaced by
    /// `value(index)` (colour and noise), set in parallel by rows. A frame
    /// without a noise estimate gets an unknown (infinite) one outside them.
    pub fn with_region(
        &self,
        columns: Range<usize>,
        rows: Range<usize>,
        value: impl Fn(usize) -> ([f32; 3], f32) + Sync,
    ) -> Frame {
        let mut out = self.clone();
        if out.noise.len() != out.pixels.len() {
            out.noise = vec![f32::INFINITY; out.pixels.len()];
        }
        let width = self.width as usize;
        (out.pixels.par_chunks_mut(width).zip(out.noise.par_chunks_mut(width)))
            .enumerate()
            .filter(|(y, _)| rows.contains(y))
            .for_each(|(y, (pixels, noise))| {
                for x in columns.clone() {
                    (pixels[x], noise[x]) = value(y * width + x);
                }
            });
        out
    }
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
    /// Every tone map, in the order the viewer lists them.
    pub const ALL: [ToneMap; 3] = [ToneMap::Clamp, ToneMap::Reinhard, ToneMap::Filmic];

    /// Maps one linear channel value (after exposure) to [0, 1]; negative
    /// input is clamped to 0 first.
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

    /// A film with light splats and pixels of 0, 1 and several samples, so
    /// every branch of a pixel's estimate is taken.
    fn varied_film(width: u32, height: u32) -> Film {
        let mut film = Film::new(width, height);
        film.light = Some(LightSplats::new(7, film.pixels.len()));
        for index in 0..film.pixels.len() {
            let samples = index % 4;
            for k in 0..samples {
                film.pixels[index].add(Color::new(0.1 * k as f64, 0.5, index as f64 / 100.0));
            }
            if let Some(light) = film.light.as_mut().filter(|_| index % 3 == 0) {
                assert!(light.add(index, Color::new(0.25, 0.0, 1.5)));
            }
        }
        film
    }

    /// The frame, built in parallel, holds each pixel's mean (plus its
    /// light splats) and standard error exactly as the accumulator gives
    /// them one by one.
    #[test]
    fn frames_hold_each_pixels_estimate() {
        let film = varied_film(67, 45);
        let frame = film.frame();
        let light = film.light.as_ref().expect("the film has light splats");
        for (index, pixel) in film.pixels.iter().enumerate() {
            let value = pixel.mean() + light.radiance(index, pixel.count);
            assert_eq!(frame.pixels[index], value.as_vec3().to_array(), "pixel {index}");
            assert_eq!(
                frame.noise[index].to_bits(),
                (pixel.standard_error() as f32).to_bits(),
                "pixel {index}"
            );
        }
    }

    /// A region over a backdrop takes the film's estimate inside the region
    /// and the backdrop's pixels and noise outside it; a backdrop without a
    /// noise estimate gets an infinite one.
    #[test]
    fn a_region_over_a_backdrop_is_the_frame_inside_and_the_backdrop_outside() {
        let (width, height) = (67, 45);
        let film = varied_film(width, height);
        let full = film.frame();
        let count = (width * height) as usize;
        let backdrop = Frame {
            width,
            height,
            pixels: (0..count).map(|i| [i as f32, -1.0, 2.0]).collect(),
            noise: (0..count).map(|i| i as f32 * 0.5).collect(),
        };
        let without_noise = Frame {
            noise: Vec::new(),
            ..backdrop.clone()
        };
        let (columns, rows) = (5..40, 3..31);
        for backdrop in [&backdrop, &without_noise] {
            let out = film.frame_over(backdrop, columns.clone(), rows.clone());
            assert_eq!((out.width, out.height), (width, height));
            for index in 0..count {
                let (x, y) = (index % width as usize, index / width as usize);
                if columns.contains(&x) && rows.contains(&y) {
                    assert_eq!(
                        (out.pixels[index], out.noise[index].to_bits()),
                        (full.pixels[index], full.noise[index].to_bits())
                    );
                } else {
                    let noise = backdrop.noise.get(index).copied().unwrap_or(f32::INFINITY);
                    assert_eq!(
                        (out.pixels[index], out.noise[index].to_bits()),
                        (backdrop.pixels[index], noise.to_bits())
                    );
                }
            }
        }
    }

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

    /// The sums do not depend on grouping: samples added one by one equal
    /// any split merged back, bit for bit, for values f64 sums would round
    /// differently ((0.1 + 0.2) + 0.3 ≠ 0.1 + (0.2 + 0.3) in f64).
    #[test]
    fn merged_accumulators_equal_one_accumulator_exactly() {
        let samples: Vec<Color> = (0..97)
            .map(|i| {
                Color::new(
                    0.1 * i as f64,
                    1.0 / (1.0 + i as f64),
                    1e-9 * (i * i) as f64 + 3e4 * (i % 3) as f64,
                )
            })
            .collect();
        let mut whole = PixelAccumulator::default();
        for s in &samples {
            assert!(whole.add(*s));
        }
        for split in [1, 13, 50, 96] {
            let (mut first, mut second) = (PixelAccumulator::default(), PixelAccumulator::default());
            samples[..split].iter().for_each(|s| assert!(first.add(*s)));
            samples[split..].iter().for_each(|s| assert!(second.add(*s)));
            // Merged in either order.
            let mut a = first;
            a.merge(&second).expect("no overflow");
            let mut b = second;
            b.merge(&first).expect("no overflow");
            assert_eq!((a, b), (whole, whole), "split at {split}");
        }
        // f64 sums of the same groups do differ: the property is not vacuous.
        let direct = samples.iter().fold(0.0, |s, c| s + c.y);
        let grouped = samples[..13].iter().fold(0.0, |s, c| s + c.y) + samples[13..].iter().fold(0.0, |s, c| s + c.y);
        assert_ne!(direct, grouped);
    }

    /// Fixed point with 64 fractional bits holds any sample ≥ 2⁻¹¹ without
    /// rounding, so sums of such samples are exact where f64 would round;
    /// smaller samples lose at most 2⁻⁶⁴ each.
    #[test]
    fn fixed_point_is_exact_where_promised() {
        for value in [
            0.1,
            -0.1,
            1.0 / 3.0,
            12345.678,
            2f64.powi(-11),
            MAX_SAMPLE_VALUE - 1.0,
            -(MAX_SAMPLE_VALUE - 0.5),
        ] {
            assert_eq!(fixed_64(value) as f64 / TWO_POW_64, value, "{value}");
        }
        for value in [1e-12, 3e-19, 7.77e-15] {
            let error = (fixed_64(value) as f64 / TWO_POW_64 - value).abs();
            assert!(error <= 1.0 / TWO_POW_64, "{value}: {error}");
        }
        assert_eq!(fixed_32(2.5) as f64 / TWO_POW_32, 2.5);
        let mut p = PixelAccumulator::default();
        for _ in 0..10 {
            p.add(Color::splat(0.1));
        }
        // Ten exact copies of the f64 0.1 sum to exactly 10 × it, rounded once.
        assert_eq!(p.sum(), Color::splat(10.0 * 0.1));
    }

    /// The bit-level conversions against the arithmetic definition
    /// trunc(v · 2^f) (whole part truncated, the exact fraction scaled),
    /// over every binade a sample or squared luminance can occupy,
    /// subnormals and both zeros included.
    #[test]
    fn fixed_point_conversions_truncate_like_the_arithmetic_definition() {
        fn by_arithmetic(value: f64, scale: f64, fraction_bits: u32) -> i128 {
            let magnitude = value.abs();
            let whole = magnitude as u64;
            let fraction = ((magnitude - whole as f64) * scale) as u64;
            let fixed = (((whole as u128) << fraction_bits) | fraction as u128) as i128;
            if value < 0.0 { -fixed } else { fixed }
        }
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut values = vec![
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
            1.0,
            -1.0,
            MAX_SAMPLE_VALUE - 1.0,
        ];
        for _ in 0..200_000 {
            crate::math::xorshift64(&mut state);
            // Random significand and sign, exponent from subnormal to 2³¹.
            let exponent = (state >> 52) % 1054;
            let bits = (state & ((1 << 52) - 1)) | (exponent << 52) | (state & (1 << 63));
            values.push(f64::from_bits(bits));
        }
        for value in values {
            assert!(value.abs() < MAX_SAMPLE_VALUE);
            assert_eq!(fixed_64(value), by_arithmetic(value, TWO_POW_64, 64), "{value:e}");
            let square = value * value;
            assert_eq!(fixed_32(square) as i128, by_arithmetic(square, TWO_POW_32, 32), "{square:e}");
        }
    }

    #[test]
    fn unacceptable_samples_are_refused_and_not_counted() {
        let mut p = PixelAccumulator::default();
        for bad in [f64::NAN, f64::INFINITY, -f64::INFINITY, MAX_SAMPLE_VALUE, -1e300] {
            assert!(!p.add(Color::new(1.0, bad, 1.0)), "{bad}");
        }
        assert_eq!(p, PixelAccumulator::default());
        // The largest accepted value, 2³¹ times (by doubling merges), still
        // sums exactly: (2³¹ − 1) · 2³¹ < 2⁶³ is within the colour sum's range.
        let big = MAX_SAMPLE_VALUE - 1.0;
        let mut many = PixelAccumulator::default();
        assert!(many.add(Color::splat(big)));
        for _ in 0..31 {
            let copy = many;
            many.merge(&copy).expect("fits");
        }
        assert_eq!((many.count, many.sum().x), (1 << 31, big * MAX_SAMPLE_VALUE));
        // One more doubling passes u32::MAX samples and is refused.
        let copy = many;
        assert_eq!(many.merge(&copy), None);
    }

    #[test]
    fn films_of_different_sizes_do_not_merge() {
        let mut a = Film::new(2, 2);
        assert_eq!(a.merge(&Film::new(2, 3)), Err(FilmMergeError::Size(2, 2, 2, 3)));
        let mut full = Film::new(1, 1);
        full.pixels[0].count = u32::MAX;
        let mut one = Film::new(1, 1);
        one.pixels[0].add(Color::ONE);
        assert_eq!(full.merge(&one), Err(FilmMergeError::CountOverflow(0)));
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
