//! What the image area shows, and keeping its textures current: the newest
//! published frame (raw, firefly-clamped or denoised), a heatmap view, or
//! the comparison with a reference. Everything here is display only: the
//! render never restarts for it, and the frames themselves are not changed.
//!
//! Uploads are the only per-frame cost that grows with the image: a texture
//! is re-made only when what it shows changed, and while a region renders
//! only the rows of the region are uploaded.

use super::app::{ViewKind, ViewerApp};
use super::denoiser::{Denoised, Job};
use super::inspect::{self, Histogram};
use super::texture;
use crate::denoise;
use crate::film::{Frame, ToneMap};
use crate::metrics::ErrorMetrics;
use crate::render::session::{FrameInfo, RenderStats};
use egui::{ColorImage, TextureHandle, TextureOptions};
use std::sync::Arc;

/// Magnified pixels stay crisp squares (tev's choice, and cheaper to draw in
/// software GL than bilinear filtering); shrunken images are filtered.
pub const TEXTURE_OPTIONS: TextureOptions = TextureOptions {
    magnification: egui::TextureFilter::Nearest,
    minification: egui::TextureFilter::Linear,
    wrap_mode: egui::TextureWrapMode::ClampToEdge,
    mipmap_mode: None,
};

/// The denoised preview.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DenoiseMode {
    /// The raw render only (the default).
    #[default]
    Off,
    /// The image area shows the denoised frame.
    On,
    /// Raw on the left, denoised on the right.
    SideBySide,
}

/// The A/B comparison with a reference image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum CompareMode {
    /// The render only (the default).
    #[default]
    Off,
    /// Show the reference instead of the render.
    Reference,
    /// Show where and how much the render differs from the reference.
    Difference,
}

/// A reference image to compare against.
#[derive(Clone, Debug)]
pub struct Reference {
    pub name: String,
    pub frame: Arc<Frame>,
}

/// What a texture was last made from.
#[derive(Clone, Copy, Debug, PartialEq)]
struct MapKey {
    source: u64,
    exposure: f64,
    tone_map: ToneMap,
    view: ViewKind,
    denoise: DenoiseMode,
    compare: CompareMode,
    firefly_clamp: Option<f32>,
    reference: usize,
}

/// The image area's state.
#[derive(Default)]
pub struct Display {
    pub texture: Option<TextureHandle>,
    /// The denoised half of the side-by-side view.
    pub side_texture: Option<TextureHandle>,
    pub frame: Option<FrameInfo>,
    pub denoised: Option<Denoised>,
    pub stats: RenderStats,
    mapped_for: Option<MapKey>,
    side_mapped_for: Option<MapKey>,
    /// The rows the last upload of the main texture came from (a region's).
    mapped_frame: Option<(u64, Option<crate::settings::PixelRect>)>,
    pub noise: Option<f64>,
    pub histogram: Option<Histogram>,
    histogram_for: Option<(u64, bool)>,
    pub comparison: Option<Result<ErrorMetrics, String>>,
    compared_for: Option<(u64, bool, usize)>,
    pub radii_range: Option<(f32, f32)>,
    /// Full and partial texture uploads so far (for the log).
    pub uploads: (u64, u64),
}

impl ViewerApp {
    /// Takes the newest published and denoised frames and brings the textures up to date.
    pub(super) fn refresh_display(&mut self, ctx: &egui::Context) {
        let published = self.session.latest();
        self.display.stats = published.stats;
        if let Some(info) = published.frame {
            let newer = match &self.display.frame {
                Some(shown) => info.sequence != shown.sequence && info.generation >= shown.generation,
                None => true,
            };
            if newer {
                self.display.noise = texture::noise_estimate(&info.frame).filter(|_| info.noise_estimated);
                self.display.radii_range = info.radii.as_deref().and_then(|r| texture::radii_range(r));
                self.log_refresh(&info);
                self.display.frame = Some(info);
                self.request_denoise();
            }
        }
        if let Some(denoised) = self.denoiser.as_ref().and_then(|d| d.take()) {
            self.log.denoise(denoised.took);
            self.display.denoised = Some(denoised);
        }
        if self.view == ViewKind::Noise && !self.noise_view_available() {
            self.view = ViewKind::Image;
        }
        self.update_textures(ctx);
        self.update_inspection();
    }

    /// Whether the frame shown has a per-pixel noise estimate to show.
    pub(super) fn noise_view_available(&self) -> bool {
        self.display.frame.as_ref().is_none_or(|f| f.noise_estimated)
    }

    /// Sends the newest frame to the denoiser when the preview wants it.
    pub(super) fn request_denoise(&mut self) {
        if self.denoise_mode == DenoiseMode::Off {
            return;
        }
        let (Some(info), Some(scene), Some(denoiser)) = (&self.display.frame, &self.scene, &self.denoiser) else {
            return;
        };
        if self.display.denoised.as_ref().is_some_and(|d| d.sequence == info.sequence) {
            return;
        }
        denoiser.request(Job {
            sequence: info.sequence,
            frame: Arc::clone(&info.frame),
            scene: Arc::clone(scene),
            camera: info.camera,
            firefly_clamp: self.firefly_clamp,
        });
    }

    /// The denoised frame if it matches the shown frame's size, else the raw one.
    fn denoised_or_raw(&self, info: &FrameInfo) -> (u64, Arc<Frame>) {
        match &self.display.denoised {
            Some(d) if (d.frame.width, d.frame.height) == (info.frame.width, info.frame.height) => {
                (d.sequence | 1 << 63, Arc::clone(&d.frame))
            }
            _ => (info.sequence, self.clamped(&info.frame)),
        }
    }

    /// The frame with the firefly clamp applied, if it is on.
    fn clamped(&self, frame: &Arc<Frame>) -> Arc<Frame> {
        match self.firefly_clamp {
            Some(max) => {
                let mut copy = (**frame).clone();
                denoise::clamp_fireflies(&mut copy, max);
                Arc::new(copy)
            }
            None => Arc::clone(frame),
        }
    }

    fn key(&self, source: u64) -> MapKey {
        MapKey {
            source,
            exposure: self.exposure,
            tone_map: self.tone_map,
            view: self.view,
            denoise: self.denoise_mode,
            compare: self.compare_mode,
            firefly_clamp: self.firefly_clamp,
            reference: self.reference.as_ref().map_or(0, |r| Arc::as_ptr(&r.frame) as usize),
        }
    }

    fn update_textures(&mut self, ctx: &egui::Context) {
        let Some(info) = self.display.frame.clone() else {
            return;
        };
        // The main picture.
        let (source, shown) = match (self.view, self.denoise_mode) {
            (ViewKind::Image, DenoiseMode::On) => self.denoised_or_raw(&info),
            _ => (info.sequence, self.clamped(&info.frame)),
        };
        let key = self.key(source);
        if self.display.mapped_for != Some(key) {
            let rows = self.changed_rows(&info, key);
            match rows {
                Some(rows) if self.display.texture.is_some() => {
                    let image = texture::tone_mapped_rows(&shown, self.exposure, self.tone_map, rows.clone());
                    if let Some(texture) = &mut self.display.texture {
                        texture.set_partial([0, rows.start], image, TEXTURE_OPTIONS);
                    }
                    self.display.uploads.1 += 1;
                }
                _ => {
                    let image = self.main_image(&info, &shown);
                    upload(ctx, &mut self.display.texture, "prism-render", image);
                    self.display.uploads.0 += 1;
                }
            }
            self.display.mapped_for = Some(key);
            self.display.mapped_frame = Some((info.generation, info.region));
        }
        // The denoised half of the side-by-side view.
        if self.denoise_mode == DenoiseMode::SideBySide && self.view == ViewKind::Image {
            let (source, denoised) = self.denoised_or_raw(&info);
            let key = self.key(source);
            if self.display.side_mapped_for != Some(key) {
                let image = texture::tone_mapped(&denoised, self.exposure, self.tone_map);
                upload(ctx, &mut self.display.side_texture, "prism-denoised", image);
                self.display.side_mapped_for = Some(key);
            }
        }
    }

    /// While a region renders, only its rows change between its frames: the
    /// rows to upload, if the texture holds the previous frame of the same
    /// region in the same mapping.
    fn changed_rows(&self, info: &FrameInfo, key: MapKey) -> Option<std::ops::Range<usize>> {
        let region = info.region?;
        let previous = self.display.mapped_for?;
        let same_mapping = MapKey {
            source: previous.source,
            ..key
        } == previous;
        let plain_image = key.view == ViewKind::Image && key.compare == CompareMode::Off && key.denoise != DenoiseMode::On;
        let same_region = self.display.mapped_frame == Some((info.generation, Some(region)));
        (same_mapping && plain_image && same_region).then_some(region.y0 as usize..region.y1 as usize)
    }

    fn main_image(&self, info: &FrameInfo, shown: &Frame) -> ColorImage {
        let (width, height) = (info.frame.width, info.frame.height);
        match self.view {
            ViewKind::Noise => texture::noise_heatmap(&info.frame),
            ViewKind::Radii => match info.radii.as_deref().filter(|r| r.len() == info.frame.pixels.len()) {
                Some(radii) => texture::radii_heatmap(width, height, radii),
                None => texture::noise_heatmap(&info.frame),
            },
            ViewKind::Image => match (self.compare_mode, &self.reference) {
                (CompareMode::Reference, Some(reference)) => texture::tone_mapped(&reference.frame, self.exposure, self.tone_map),
                (CompareMode::Difference, Some(reference)) => texture::difference_heatmap(shown, &reference.frame)
                    .unwrap_or_else(|| texture::tone_mapped(shown, self.exposure, self.tone_map)),
                _ => texture::tone_mapped(shown, self.exposure, self.tone_map),
            },
        }
    }

    /// The histogram and the comparison follow the frame shown.
    fn update_inspection(&mut self) {
        let Some(info) = &self.display.frame else {
            return;
        };
        let denoised = self.denoise_mode == DenoiseMode::On;
        let (source, shown) = if denoised {
            self.denoised_or_raw(info)
        } else {
            (info.sequence, Arc::clone(&info.frame))
        };
        if self.show_histogram && self.display.histogram_for != Some((source, denoised)) {
            self.display.histogram = Some(Histogram::of(&shown));
            self.display.histogram_for = Some((source, denoised));
        }
        match &self.reference {
            Some(reference) => {
                let key = (source, denoised, Arc::as_ptr(&reference.frame) as usize);
                if self.display.compared_for != Some(key) {
                    self.display.comparison = Some(inspect::compare(&shown, &reference.frame));
                    self.display.compared_for = Some(key);
                }
            }
            None => self.display.comparison = None,
        }
    }
}

fn upload(ctx: &egui::Context, texture: &mut Option<TextureHandle>, name: &str, image: ColorImage) {
    match texture {
        Some(texture) if texture.size() == image.size => texture.set(image, TEXTURE_OPTIONS),
        _ => *texture = Some(ctx.load_texture(name, image, TEXTURE_OPTIONS)),
    }
}
