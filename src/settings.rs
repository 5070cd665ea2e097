//! What a render is asked to do: plain data at the bottom of the layers,
//! read by the scene loader, the integrators, the progressive driver and the
//! viewer alike. Every field is a *sampling* parameter: changing one restarts
//! accumulation but keeps the scene and its BVH. Settings that only one
//! integrator reads are defined beside it (as plain data with no imports of
//! their own) and gathered here. Their one validation, shared by the scene
//! file and the command line, is in [`validate`].

pub mod validate;

pub use crate::integrator::sppm::settings::{RadiusSchedule, SppmSettings};
use crate::sampler::SamplerKind;
use serde::{Deserialize, Serialize};
use std::time::Duration;
pub use validate::{Setting, SettingError, SettingsPatch};

/// Which light-transport algorithm renders the image; the names are the
/// scene file's and command line's spellings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Deserialize, Serialize)]
pub enum IntegratorKind {
    /// Path tracing with next-event estimation and MIS.
    #[default]
    #[serde(rename = "pt")]
    PathTracing,
    /// Path tracing that only follows BSDF samples (the original's method).
    #[serde(rename = "pt-bsdf")]
    BsdfOnly,
    /// Stochastic progressive photon mapping.
    #[serde(rename = "sppm")]
    Sppm,
}

impl IntegratorKind {
    /// Every integrator, in the order menus list them.
    pub const ALL: [IntegratorKind; 3] = [IntegratorKind::PathTracing, IntegratorKind::BsdfOnly, IntegratorKind::Sppm];

    /// The name in scene files and on the command line (`pt`, `pt-bsdf`,
    /// `sppm`).
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::PathTracing => "pt",
            IntegratorKind::BsdfOnly => "pt-bsdf",
            IntegratorKind::Sppm => "sppm",
        }
    }
}

impl std::fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Everything that decides which samples a render takes (see the module
/// doc). Two renders with equal settings of the same scene and camera
/// produce the same image bit for bit after the same number of passes,
/// whatever the thread count.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel (path tracing) or iterations (SPPM); `None` = until stopped.
    pub samples_per_pixel: Option<u32>,
    /// Stop after this much render time; `None` = no limit. With a sample
    /// target as well, whichever is reached first ends the render.
    pub time_limit: Option<Duration>,
    /// Most bounces per path: scattering events for path tracing; specular
    /// bounces of camera paths and surface hits of photons for SPPM.
    pub max_depth: u32,
    /// The light-transport algorithm.
    pub integrator: IntegratorKind,
    /// The sample generator.
    pub sampler: SamplerKind,
    /// Seed of every sample stream: different seeds give independent images.
    pub seed: u64,
    /// SPPM's own settings (photons, radius), read only by SPPM.
    pub sppm: SppmSettings,
    /// Adaptive sampling: a pixel stops receiving samples once its relative
    /// standard error falls below this (see `integrator::pass::ADAPTIVE_*`);
    /// `None` samples every pixel every pass.
    pub adaptive_threshold: Option<f64>,
    /// Render only this part of the image (the viewer's region render);
    /// `None` renders the whole frame. Pixels outside it get no samples.
    pub region: Option<Region>,
    /// Carry sampled wavelengths instead of RGB (hero-wavelength spectral
    /// transport, see `spectrum`); a scene with dispersive glass is rendered
    /// spectrally whatever this says.
    pub spectral: bool,
    /// Path tracing: trace caustics (light focused by mirrors and glass onto
    /// the surfaces the camera sees) from the lights and connect them to the
    /// lens, rather than waiting for camera paths to hit the light through
    /// the glass (`integrator::path::caustic_paths`); and reach lights seen
    /// in mirror balls from the lens as well (`integrator::path::lens_connection`).
    pub caustic_light_paths: bool,
}

/// A rectangle of the image in film coordinates ([0, 1]², y down), so it
/// keeps its place whatever the resolution (previews, resolution scale).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// Top-left corner (x, y), each in [0, 1].
    pub min: [f64; 2],
    /// Bottom-right corner (x, y), each in [0, 1]; greater than `min`.
    pub max: [f64; 2],
}

impl Region {
    /// The region between two corners in any order, clipped to the image;
    /// `None` if nothing of it is left.
    pub fn from_corners(a: [f64; 2], b: [f64; 2]) -> Option<Self> {
        let clip = |v: f64| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        let min = [clip(a[0].min(b[0])), clip(a[1].min(b[1]))];
        let max = [clip(a[0].max(b[0])), clip(a[1].max(b[1]))];
        (max[0] > min[0] && max[1] > min[1]).then_some(Self { min, max })
    }

    /// The pixels of a `width` × `height` image whose centres it covers, at least one.
    pub fn pixels(&self, width: u32, height: u32) -> PixelRect {
        let span = |min: f64, max: f64, size: u32| {
            let first = ((min * size as f64 - 0.5).ceil().max(0.0) as u32).min(size.saturating_sub(1));
            let end = ((max * size as f64 - 0.5).floor() as i64 + 1).clamp(first as i64 + 1, size.max(1) as i64) as u32;
            (first, end)
        };
        let (x0, x1) = span(self.min[0], self.max[0], width);
        let (y0, y1) = span(self.min[1], self.max[1], height);
        PixelRect { x0, y0, x1, y1 }
    }
}

/// A half-open rectangle of pixels: columns `x0..x1`, rows `y0..y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    /// First column.
    pub x0: u32,
    /// First row (0 at the top).
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl PixelRect {
    /// The whole `width` × `height` image.
    pub fn full(width: u32, height: u32) -> Self {
        Self {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    /// Whether pixel (x, y) lies in the rectangle.
    #[inline]
    pub fn contains(&self, x: u32, y: u32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// Number of pixels in the rectangle.
    pub fn pixel_count(&self) -> usize {
        (self.x1 - self.x0) as usize * (self.y1 - self.y0) as usize
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            samples_per_pixel: Some(64),
            time_limit: None,
            max_depth: 16,
            integrator: IntegratorKind::PathTracing,
            sampler: SamplerKind::Sobol,
            seed: 0,
            sppm: SppmSettings::default(),
            adaptive_threshold: None,
            region: None,
            spectral: false,
            caustic_light_paths: true,
        }
    }
}

impl RenderSettings {
    /// Width over height.
    pub fn aspect(&self) -> f64 {
        self.width as f64 / self.height as f64
    }

    /// `width × height`.
    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The pixels a pass samples: the region's, or the whole image.
    pub fn sampled_pixels(&self) -> PixelRect {
        self.region.map_or(PixelRect::full(self.width, self.height), |r| {
            r.pixels(self.width, self.height)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_region_covers_the_pixels_whose_centres_lie_inside() {
        // x ∈ [0.25, 0.5] of 8 columns spans 2.0..4.0: centres 2.5 and 3.5 → columns 2, 3.
        let region = Region::from_corners([0.5, 1.0], [0.25, 0.0]).expect("a region");
        assert_eq!(
            region.pixels(8, 4),
            PixelRect {
                x0: 2,
                y0: 0,
                x1: 4,
                y1: 4
            }
        );
        // A sliver narrower than a pixel still renders the pixel it lies in.
        let sliver = Region::from_corners([0.51, 0.51], [0.52, 0.52]).expect("a region");
        assert_eq!(sliver.pixels(8, 4).pixel_count(), 1);
        assert!(sliver.pixels(8, 4).contains(4, 2));
        assert_eq!(Region::from_corners([0.3, 0.3], [0.3, 0.9]), None);
        assert_eq!(Region::from_corners([1.2, 1.5], [1.3, 2.0]), None);
    }
}
