//! The one validation of render settings, shared by the scene file's
//! `[render]` table and the command line: a [`SettingsPatch`] holds the values
//! a user asked for, [`SettingsPatch::apply_to`] checks each against its
//! documented range before it reaches [`RenderSettings`], and errors name the
//! [`Setting`] so each caller can say where it was written (a file, line and
//! key, or a `--flag`). Limits that concern the whole image (its memory) are
//! checked by [`RenderSettings::check_memory`] once every source has spoken.
//!
//! Everything here is checked before anything is allocated: a width that
//! cannot fit in memory must be refused with an estimate, not end in an
//! allocation failure.

use super::{IntegratorKind, RadiusSchedule, RenderSettings};
use crate::sampler::SamplerKind;
use serde::Deserialize;
use std::fmt;
use std::time::Duration;

/// Largest width or height, in pixels (2¹⁶: beyond every display and print
/// size, and far below where `width × height` could overflow an index).
pub const MAX_IMAGE_SIDE: u32 = 65_536;
/// Largest `max_depth`. A path's cost grows linearly with its depth, and a
/// path trapped between surfaces (glass with total internal reflection, a
/// degenerate sliver) runs to the limit; 1024 bounces keep such a path under a
/// millisecond while leaving throughput below any visible level for every
/// physical albedo (0.99¹⁰²⁴ ≈ 3·10⁻⁵).
pub const MAX_DEPTH: u32 = 1024;
/// Worker threads: 1 to 256. Above that, thread start-up and scheduling cost
/// more than they give (1,024 threads take 6.7 s on a 32×24 image that renders
/// in 0.03 s on 64).
pub const MAX_THREADS: usize = 256;
/// Longest `--time`: about three years, far beyond any render and well inside
/// what a `Duration` can hold.
pub const MAX_TIME_SECONDS: f64 = 1e8;
/// Exposure range in stops: 2⁶⁴ is far beyond any real scene's dynamic range
/// and keeps scaled values finite in 32-bit float output.
pub const MAX_EXPOSURE_STOPS: f64 = 64.0;
/// Range of SPPM's initial gather radius, in scene units: its square and the
/// density estimate's 1/(πr²) stay normal f64 numbers across it.
pub const RADIUS_RANGE: (f64, f64) = (1e-12, 1e12);

/// Bytes of memory per pixel that path tracing needs: the film's fixed-point
/// sums and count (80, see `film`), the linear frame with its noise estimate (16), 8-bit output and
/// its copy for the encoder (6), and room for the EXR encoder's f32 copy (12),
/// rounded up.
pub const PATH_TRACING_BYTES_PER_PIXEL: u64 = 120;

/// Bytes per pixel that light-traced caustics add to path tracing: the
/// film's fixed-point light sums (48) and one pass's list of connections
/// before they are summed (32 per connection; a light path per four pixels
/// connects at most about eight times on the shipped scenes), rounded up.
pub const LIGHT_PATH_BYTES_PER_PIXEL: u64 = 80;
/// Bytes of memory per pixel that SPPM needs: its pixel statistics (64) and
/// photon tallies (32), one pass's visible points (about 250) with their grid
/// keys (a sphere covers up to 8 cells: 8 × 12 bytes, plus the point list of
/// 40 and the slot table), and the output buffers as for path tracing (34),
/// rounded up.
pub const SPPM_BYTES_PER_PIXEL: u64 = 640;

/// A setting a user can give, in the scene file's `[render]` table or on the
/// command line (or both: the command line wins).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Setting {
    /// Image width in pixels, 1 to [`MAX_IMAGE_SIDE`].
    Width,
    /// Image height in pixels, 1 to [`MAX_IMAGE_SIDE`].
    Height,
    /// Samples per pixel (SPPM: iterations), at least 1.
    SamplesPerPixel,
    /// Render-time limit in seconds (command line only).
    TimeLimit,
    /// Most bounces per path, 1 to [`MAX_DEPTH`].
    MaxDepth,
    /// The light-transport algorithm.
    Integrator,
    /// The sample generator.
    Sampler,
    /// The seed of every sample stream.
    Seed,
    /// SPPM photons per iteration, at least 1.
    PhotonsPerIteration,
    /// SPPM's initial gather radius in scene units, within [`RADIUS_RANGE`].
    InitialRadius,
    /// SPPM's α, strictly between 0 and 1.
    Alpha,
    /// SPPM's radius schedule.
    RadiusSchedule,
    /// Relative standard error at which a pixel stops taking samples;
    /// positive.
    AdaptiveThreshold,
    /// Spectral transport (true) or RGB (false, the default).
    Spectral,
    /// Path tracing: caustics traced from the lights (true, the default) or
    /// by camera paths alone (false).
    CausticLightPaths,
    /// Worker threads, 1 to [`MAX_THREADS`] (command line only).
    Threads,
    /// Exposure in stops, within ±[`MAX_EXPOSURE_STOPS`] (command line only;
    /// display and output, not sampling).
    Exposure,
}

impl Setting {
    /// The key in a scene file's `[render]` table (`None`: command line only).
    pub fn key(self) -> Option<&'static str> {
        Some(match self {
            Setting::Width => "width",
            Setting::Height => "height",
            Setting::SamplesPerPixel => "spp",
            Setting::MaxDepth => "max_depth",
            Setting::Integrator => "integrator",
            Setting::Sampler => "sampler",
            Setting::Seed => "seed",
            Setting::PhotonsPerIteration => "photons_per_iteration",
            Setting::InitialRadius => "initial_radius",
            Setting::Alpha => "alpha",
            Setting::RadiusSchedule => "radius_schedule",
            Setting::AdaptiveThreshold => "adaptive_threshold",
            Setting::Spectral => "spectral",
            Setting::CausticLightPaths => "caustic_light_paths",
            Setting::TimeLimit | Setting::Threads | Setting::Exposure => return None,
        })
    }

    /// The `prism render` flag.
    pub fn flag(self) -> &'static str {
        match self {
            Setting::Width => "--width",
            Setting::Height => "--height",
            Setting::SamplesPerPixel => "--spp",
            Setting::TimeLimit => "--time",
            Setting::MaxDepth => "--max-depth",
            Setting::Integrator => "--integrator",
            Setting::Sampler => "--sampler",
            Setting::Seed => "--seed",
            Setting::PhotonsPerIteration => "--photons",
            Setting::InitialRadius => "--radius",
            Setting::Alpha => "--alpha",
            Setting::RadiusSchedule => "--radius-schedule",
            Setting::AdaptiveThreshold => "--adaptive-threshold",
            Setting::Spectral => "--spectral",
            Setting::CausticLightPaths => "--caustic-light-paths",
            Setting::Threads => "--threads",
            Setting::Exposure => "--exposure",
        }
    }
}

/// A value outside its documented range.
#[derive(Clone, Debug, PartialEq)]
pub struct SettingError {
    /// Which setting was refused.
    pub setting: Setting,
    /// What is wrong with its value, with the value found.
    pub message: String,
}

impl SettingError {
    fn new(setting: Setting, message: impl Into<String>) -> Self {
        Self {
            setting,
            message: message.into(),
        }
    }
}

impl fmt::Display for SettingError {
    /// As the command line names it: `--width: must be at most 65536 (found 100000)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.setting.flag(), self.message)
    }
}

impl std::error::Error for SettingError {}

/// The settings a user asked for; `None` keeps the current value. This is
/// also the scene file's `[render]` table, key for key.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SettingsPatch {
    /// Image width in pixels (`--width`).
    pub width: Option<u32>,
    /// Image height in pixels (`--height`).
    pub height: Option<u32>,
    /// Samples per pixel, or SPPM iterations (`--spp`).
    pub spp: Option<u32>,
    /// Most bounces per path (`--max-depth`).
    pub max_depth: Option<u32>,
    /// `pt`, `pt-bsdf` or `sppm` (`--integrator`).
    pub integrator: Option<IntegratorKind>,
    /// `sobol` or `random` (`--sampler`).
    pub sampler: Option<SamplerKind>,
    /// Seed of the sample streams (`--seed`).
    pub seed: Option<u64>,
    /// SPPM photons per iteration (`--photons`).
    pub photons_per_iteration: Option<u32>,
    /// SPPM's initial gather radius in scene units (`--radius`); unset picks
    /// it from the pixel footprint.
    pub initial_radius: Option<f64>,
    /// SPPM's α, the share of new photons kept per iteration (`--alpha`).
    pub alpha: Option<f64>,
    /// SPPM's radius schedule: "per-pixel" (default) or "global" (farm renders).
    pub radius_schedule: Option<RadiusSchedule>,
    /// Relative standard error at which a pixel stops taking samples.
    pub adaptive_threshold: Option<f64>,
    /// Spectral transport (`--spectral`).
    pub spectral: Option<bool>,
    /// Caustics traced from the lights (`--caustic-light-paths`).
    pub caustic_light_paths: Option<bool>,
    /// Command line only: render for this long instead of to a sample count.
    #[serde(skip)]
    pub time_seconds: Option<f64>,
}

impl SettingsPatch {
    /// Checks every value given against its range, then writes them into
    /// `settings`. On error nothing has been written.
    pub fn apply_to(&self, settings: &mut RenderSettings) -> Result<(), SettingError> {
        let mut next = settings.clone();
        if let Some(width) = self.width {
            next.width = image_side(Setting::Width, width)?;
        }
        if let Some(height) = self.height {
            next.height = image_side(Setting::Height, height)?;
        }
        if let Some(seconds) = self.time_seconds {
            next.time_limit = Some(time_limit(seconds)?);
            next.samples_per_pixel = None;
        }
        if let Some(spp) = self.spp {
            next.samples_per_pixel = Some(at_least_one(Setting::SamplesPerPixel, spp)?);
        }
        if let Some(depth) = self.max_depth {
            at_least_one(Setting::MaxDepth, depth)?;
            if depth > MAX_DEPTH {
                return Err(SettingError::new(
                    Setting::MaxDepth,
                    format!("must be at most {MAX_DEPTH} (found {depth})"),
                ));
            }
            next.max_depth = depth;
        }
        next.integrator = self.integrator.unwrap_or(next.integrator);
        next.sampler = self.sampler.unwrap_or(next.sampler);
        next.seed = self.seed.unwrap_or(next.seed);
        if let Some(photons) = self.photons_per_iteration {
            next.sppm.photons_per_iteration = at_least_one(Setting::PhotonsPerIteration, photons)?;
        }
        if let Some(radius) = self.initial_radius {
            let (low, high) = RADIUS_RANGE;
            if !(low..=high).contains(&radius) {
                return Err(SettingError::new(
                    Setting::InitialRadius,
                    format!("must be between {low:e} and {high:e} scene units (found {})", shown(radius)),
                ));
            }
            next.sppm.initial_radius = Some(radius);
        }
        if let Some(alpha) = self.alpha {
            if !(alpha > 0.0 && alpha < 1.0) {
                return Err(SettingError::new(
                    Setting::Alpha,
                    format!("must be strictly between 0 and 1 (found {})", shown(alpha)),
                ));
            }
            next.sppm.alpha = alpha;
        }
        next.sppm.radius_schedule = self.radius_schedule.unwrap_or(next.sppm.radius_schedule);
        if let Some(threshold) = self.adaptive_threshold {
            if !(threshold.is_finite() && threshold > 0.0) {
                return Err(SettingError::new(
                    Setting::AdaptiveThreshold,
                    format!("must be a positive finite number (found {})", shown(threshold)),
                ));
            }
            next.adaptive_threshold = Some(threshold);
        }
        next.spectral = self.spectral.unwrap_or(next.spectral);
        next.caustic_light_paths = self.caustic_light_paths.unwrap_or(next.caustic_light_paths);
        *settings = next;
        Ok(())
    }
}

/// A refused value as a person would write it: Rust prints `1e300` as 301
/// digits, so magnitudes outside [10⁻⁴, 10⁶) are shown with an exponent.
fn shown(value: f64) -> String {
    let magnitude = value.abs();
    if value.is_finite() && magnitude != 0.0 && !(1e-4..1e6).contains(&magnitude) {
        format!("{value:e}")
    } else {
        format!("{value}")
    }
}

fn at_least_one(setting: Setting, value: u32) -> Result<u32, SettingError> {
    if value == 0 {
        Err(SettingError::new(setting, "must be at least 1 (found 0)"))
    } else {
        Ok(value)
    }
}

fn image_side(setting: Setting, value: u32) -> Result<u32, SettingError> {
    at_least_one(setting, value)?;
    if value > MAX_IMAGE_SIDE {
        return Err(SettingError::new(
            setting,
            format!("must be at most {MAX_IMAGE_SIDE} pixels (found {value})"),
        ));
    }
    Ok(value)
}

/// A render-time limit in seconds: positive, finite, at most [`MAX_TIME_SECONDS`].
pub fn time_limit(seconds: f64) -> Result<Duration, SettingError> {
    if !(seconds > 0.0 && seconds <= MAX_TIME_SECONDS) {
        return Err(SettingError::new(
            Setting::TimeLimit,
            format!(
                "must be a number of seconds above 0 and at most {MAX_TIME_SECONDS:e} (found {})",
                shown(seconds)
            ),
        ));
    }
    Ok(Duration::from_secs_f64(seconds))
}

/// A worker thread count in 1..=[`MAX_THREADS`].
pub fn thread_count(threads: usize) -> Result<usize, SettingError> {
    if !(1..=MAX_THREADS).contains(&threads) {
        return Err(SettingError::new(
            Setting::Threads,
            format!("must be between 1 and {MAX_THREADS} (found {threads})"),
        ));
    }
    Ok(threads)
}

/// An exposure in stops: finite, within ±[`MAX_EXPOSURE_STOPS`].
pub fn exposure(stops: f64) -> Result<f64, SettingError> {
    if !(stops.is_finite() && stops.abs() <= MAX_EXPOSURE_STOPS) {
        return Err(SettingError::new(
            Setting::Exposure,
            format!(
                "must be a finite number of stops between -{MAX_EXPOSURE_STOPS} and {MAX_EXPOSURE_STOPS} (found {})",
                shown(stops)
            ),
        ));
    }
    Ok(stops)
}

impl RenderSettings {
    /// Estimated memory a render of these settings needs, in bytes (the
    /// per-pixel buffers, which dominate for any image worth refusing).
    pub fn memory_estimate(&self) -> u64 {
        let per_pixel = match self.integrator {
            IntegratorKind::Sppm => SPPM_BYTES_PER_PIXEL,
            IntegratorKind::PathTracing if self.caustic_light_paths => PATH_TRACING_BYTES_PER_PIXEL + LIGHT_PATH_BYTES_PER_PIXEL,
            IntegratorKind::PathTracing | IntegratorKind::BsdfOnly => PATH_TRACING_BYTES_PER_PIXEL,
        };
        self.width as u64 * self.height as u64 * per_pixel
    }

    /// Refuses an image whose [`memory_estimate`](Self::memory_estimate)
    /// exceeds `available` bytes (see [`available_memory`]), saying the
    /// estimate. The error names [`Setting::Width`]; callers say which
    /// source set the size.
    pub fn check_memory(&self, available: Option<u64>) -> Result<(), SettingError> {
        let needed = self.memory_estimate();
        match available {
            Some(available) if needed > available => Err(SettingError::new(
                Setting::Width,
                format!(
                    "a {}×{} image with {} needs about {} of memory, more than the {} available",
                    self.width,
                    self.height,
                    self.integrator,
                    format_bytes(needed),
                    format_bytes(available)
                ),
            )),
            _ => Ok(()),
        }
    }
}

/// Memory the system could give this process now, in bytes (Linux's
/// `MemAvailable`); `None` where it cannot be read.
pub fn available_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// `12.3 GB`-style sizes (decimal units, as `free -h` does not; stated so).
pub fn format_bytes(bytes: u64) -> String {
    let gb = bytes as f64 / 1e9;
    if gb >= 1.0 {
        format!("{gb:.1} GB")
    } else {
        format!("{:.0} MB", bytes as f64 / 1e6)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refused_values_are_shown_briefly() {
        assert_eq!(shown(1e300), "1e300");
        assert_eq!(shown(-2.5e-9), "-2.5e-9");
        assert_eq!(shown(1.5), "1.5");
        assert_eq!(shown(-1.0), "-1");
        assert_eq!(shown(0.0), "0");
        assert_eq!(shown(f64::NAN), "NaN");
        assert_eq!(shown(f64::INFINITY), "inf");
        let error = time_limit(1e300).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(error.ends_with("(found 1e300)"), "{error}");
    }

    #[test]
    fn a_patch_is_applied_whole_or_not_at_all() {
        let mut settings = RenderSettings::default();
        let patch = SettingsPatch {
            width: Some(32),
            max_depth: Some(MAX_DEPTH + 1),
            ..Default::default()
        };
        let error = patch.apply_to(&mut settings).err();
        assert_eq!(error.map(|e| e.setting), Some(Setting::MaxDepth));
        assert_eq!(settings, RenderSettings::default());
    }

    #[test]
    fn limits_are_inclusive_and_name_the_setting() {
        let mut settings = RenderSettings::default();
        let at_limits = SettingsPatch {
            width: Some(MAX_IMAGE_SIDE),
            height: Some(1),
            max_depth: Some(MAX_DEPTH),
            initial_radius: Some(RADIUS_RANGE.1),
            ..Default::default()
        };
        assert_eq!(at_limits.apply_to(&mut settings), Ok(()));
        assert_eq!((settings.width, settings.max_depth), (MAX_IMAGE_SIDE, MAX_DEPTH));
        let too_wide = SettingsPatch {
            width: Some(100_000),
            ..Default::default()
        };
        let error = too_wide.apply_to(&mut settings).err().map(|e| e.to_string());
        assert_eq!(error.as_deref(), Some("--width: must be at most 65536 pixels (found 100000)"));
        assert!(thread_count(0).is_err() && thread_count(MAX_THREADS + 1).is_err());
        assert_eq!(thread_count(MAX_THREADS), Ok(MAX_THREADS));
        assert!(exposure(f64::NAN).is_err() && exposure(f64::INFINITY).is_err());
        assert!(time_limit(f64::NAN).is_err() && time_limit(1e30).is_err() && time_limit(0.0).is_err());
    }

    #[test]
    fn memory_estimate_refuses_what_cannot_fit() {
        let settings = RenderSettings {
            width: 15_000,
            height: 15_000,
            caustic_light_paths: false,
            ..Default::default()
        };
        // With light-traced caustics, 2.25e8 pixels × 200 bytes = 45 GB.
        let traced = RenderSettings {
            caustic_light_paths: true,
            ..settings.clone()
        };
        assert_eq!(traced.memory_estimate(), 45_000_000_000);
        // 2.25e8 pixels × 120 bytes = 27 GB.
        assert_eq!(settings.memory_estimate(), 27_000_000_000);
        let error = settings.check_memory(Some(8_000_000_000)).err().map(|e| e.message);
        assert_eq!(
            error.as_deref(),
            Some("a 15000×15000 image with pt needs about 27.0 GB of memory, more than the 8.0 GB available")
        );
        assert!(settings.check_memory(Some(30_000_000_000)).is_ok());
        assert!(settings.check_memory(None).is_ok());
    }
}
