//! Image textures: files decoded once into linear RGB, looked up with
//! bilinear filtering.
//!
//! Invariants: texels are linear RGB in [0, 1] (8- and 16-bit files are
//! sRGB-decoded, float files are taken as already linear and clamped, since
//! every textured quantity is a reflectance). Lookups use the (u, v)
//! convention of OBJ and pbrt: v = 0 is the bottom row of the picture, so an
//! image mapped onto a quad whose `edge_v` points up stands upright.

use crate::color::{Color, srgb_decode};
use glam::DVec2;
use image::{DynamicImage, ImageReader};
use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::{Arc, LazyLock};

/// Why an image file could not become a texture. Every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The file could not be found, opened or read.
    #[error("cannot read image {}: {source}", path.display())]
    Read {
        /// The image file.
        path: PathBuf,
        /// What the operating system reported.
        source: std::io::Error,
    },
    /// The file is not an image in a format Prism decodes, or is damaged.
    #[error("cannot decode image {}: {source}", path.display())]
    Decode {
        /// The image file.
        path: PathBuf,
        /// What the decoder reported.
        source: image::ImageError,
    },
    /// The image is zero texels wide or high.
    #[error("image {} has no pixels", path.display())]
    Empty {
        /// The image file.
        path: PathBuf,
    },
}

/// What happens outside [0, 1]²: tile the picture, or stretch its border texels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// Tile the picture: u and u + 1 read the same texel.
    #[default]
    Repeat,
    /// Extend the border texels outward.
    Clamp,
}

impl Wrap {
    /// Texel index for a possibly out-of-range integer coordinate.
    #[inline]
    fn index(self, i: i64, size: usize) -> usize {
        match self {
            Wrap::Repeat => i.rem_euclid(size as i64) as usize,
            Wrap::Clamp => i.clamp(0, size as i64 - 1) as usize,
        }
    }
}

/// A decoded picture: `width × height` linear RGB texels, top row first.
#[derive(Clone)]
pub struct Image {
    width: usize,
    height: usize,
    texels: Texels,
    /// Where it came from, for messages (`None` when built in memory).
    source: Option<PathBuf>,
}

impl fmt::Debug for Image {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Never dump the pixels: a scene's debug print would be megabytes.
        f.debug_struct("Image")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("source", &self.source)
            .finish()
    }
}

/// How the texels are kept. An 8-bit file keeps its bytes, a quarter of
/// the memory of three floats (a 16k × 8k map: 384 MB instead of 1.5 GB),
/// each decoded through a 256-entry table as it is read: the same floats as
/// decoding them all at load. On earth.toml (two 8-bit pictures of 0.8 MB
/// as bytes) renders take the same time either way.
#[derive(Clone)]
enum Texels {
    /// Linear RGB (from 16-bit or float files, or built in memory).
    Linear(Vec<[f32; 3]>),
    /// sRGB-encoded bytes and the linear value of each byte
    /// ([`SRGB8_DECODED`], shared by every image). The reference is always
    /// that table's; it is held here so that a texel's read does not pass
    /// the `LazyLock`'s check first (reading the static at each texel made
    /// earth.toml 1.5–3% slower in paired renders).
    Srgb8 {
        bytes: Vec<[u8; 3]>,
        decoded: &'static [f32; 256],
    },
}

/// The linear value of each 8-bit sRGB code, computed once for all images.
static SRGB8_DECODED: LazyLock<[f32; 256]> = LazyLock::new(|| std::array::from_fn(|v| srgb_decode(v as f64 / 255.0) as f32));

impl Image {
    /// An image from linear texels listed row by row, top row first.
    /// `None` if the sizes disagree or are zero.
    pub fn from_linear(width: usize, height: usize, texels: &[Color]) -> Option<Self> {
        if width == 0 || height == 0 || texels.len() != width * height {
            return None;
        }
        let texels = Texels::Linear(
            texels
                .iter()
                .map(|c| clamp_texel([c.x as f32, c.y as f32, c.z as f32]))
                .collect(),
        );
        Some(Self {
            width,
            height,
            texels,
            source: None,
        })
    }

    /// Decodes a PNG, JPEG or BMP file (the format is guessed from its bytes).
    pub fn load(path: &Path) -> Result<Self, ImageError> {
        let read = |source| ImageError::Read {
            path: path.to_path_buf(),
            source,
        };
        let decoded = ImageReader::open(path)
            .and_then(|reader| reader.with_guessed_format())
            .map_err(read)?
            .decode()
            .map_err(|source| ImageError::Decode {
                path: path.to_path_buf(),
                source,
            })?;
        let (width, height) = (decoded.width() as usize, decoded.height() as usize);
        if width == 0 || height == 0 {
            return Err(ImageError::Empty {
                path: path.to_path_buf(),
            });
        }
        Ok(Self {
            width,
            height,
            texels: texels_of(decoded),
            source: Some(path.to_path_buf()),
        })
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The texel in column `x`, row `y` (row 0 at the top).
    #[inline]
    pub fn texel(&self, x: usize, y: usize) -> Color {
        let index = y * self.width + x;
        let [r, g, b] = match &self.texels {
            Texels::Linear(texels) => texels[index],
            Texels::Srgb8 { bytes, decoded } => bytes[index].map(|byte| decoded[byte as usize]),
        };
        Color::new(r as f64, g as f64, b as f64)
    }

    /// Bilinear interpolation between the four texel centres around `uv`
    /// (texel (x, y) has its centre at u = (x + ½)/width, v = 1 − (y + ½)/height).
    #[inline]
    pub fn bilinear(&self, uv: DVec2, wrap: [Wrap; 2]) -> Color {
        // A NaN coordinate (a degenerate hit) reads the corner rather than poisoning the path.
        let uv = if uv.is_finite() { uv } else { DVec2::ZERO };
        let x = uv.x * self.width as f64 - 0.5;
        let y = (1.0 - uv.y) * self.height as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let (xa, xb) = (wrap[0].index(x0, self.width), wrap[0].index(x0 + 1, self.width));
        let (ya, yb) = (wrap[1].index(y0, self.height), wrap[1].index(y0 + 1, self.height));
        let top = self.texel(xa, ya) * (1.0 - fx) + self.texel(xb, ya) * fx;
        let bottom = self.texel(xa, yb) * (1.0 - fx) + self.texel(xb, yb) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

/// The texels of a decoded file, linear or as sRGB bytes with their
/// decoding (floats are taken as linear).
fn texels_of(decoded: DynamicImage) -> Texels {
    let is_float = matches!(decoded, DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_));
    if is_float {
        Texels::Linear(decoded.to_rgb32f().pixels().map(|p| clamp_texel(p.0)).collect())
    } else if decoded.color().bytes_per_pixel() / decoded.color().channel_count() > 1 {
        // 16 bits per channel: decode each value; a table would have 65536 entries.
        let decode = |v: u16| srgb_decode(v as f64 / 65535.0) as f32;
        Texels::Linear(decoded.to_rgb16().pixels().map(|p| p.0.map(decode)).collect())
    } else {
        // 8 bits per channel: 256 possible values, decoded once each.
        Texels::Srgb8 {
            bytes: decoded.to_rgb8().pixels().map(|p| p.0).collect(),
            decoded: &SRGB8_DECODED,
        }
    }
}

/// Reflectances live in [0, 1]; NaN becomes 0.
fn clamp_texel(texel: [f32; 3]) -> [f32; 3] {
    texel.map(|v| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) })
}

/// Decoded images by canonical path, so a file used by many materials (or
/// spelled many ways) is decoded once and shared.
#[derive(Debug, Default)]
pub struct ImageCache {
    images: HashMap<PathBuf, Arc<Image>>,
}

impl ImageCache {
    /// The image at `path`, decoding it on first use.
    pub fn load(&mut self, path: &Path) -> Result<Arc<Image>, ImageError> {
        let canonical = path.canonicalize().map_err(|source| ImageError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        if let Some(image) = self.images.get(&canonical) {
            return Ok(Arc::clone(image));
        }
        let image = Arc::new(Image::load(&canonical)?);
        self.images.insert(canonical, Arc::clone(&image));
        Ok(image)
    }

    /// How many distinct files have been decoded.
    pub fn len(&self) -> usize {
        self.images.len()
    }

    /// Whether no file has been decoded yet.
    pub fn is_empty(&self) -> bool {
        self.images.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_by_two() -> Image {
        // Top row: red, green; bottom row: blue, white.
        let texels = [Color::X, Color::Y, Color::Z, Color::ONE];
        Image::from_linear(2, 2, &texels).unwrap_or_else(|| panic!("sizes agree"))
    }

    #[test]
    fn texel_centres_read_back_exactly_and_midpoints_average() {
        let image = two_by_two();
        // Texel centres at u, v ∈ {¼, ¾}; interpolation weights are then exactly 0 or 1.
        let at = |u, v| image.bilinear(DVec2::new(u, v), [Wrap::Clamp; 2]);
        assert_eq!(at(0.25, 0.75), Color::X);
        assert_eq!(at(0.75, 0.75), Color::Y);
        assert_eq!(at(0.25, 0.25), Color::Z);
        assert_eq!(at(0.75, 0.25), Color::ONE);
        // The centre is equidistant from all four: their mean, to rounding.
        let mean = (Color::X + Color::Y + Color::Z + Color::ONE) / 4.0;
        assert!((at(0.5, 0.5) - mean).length() < 1e-12);
    }

    #[test]
    fn repeat_wraps_across_the_border_and_clamp_does_not() {
        let image = two_by_two();
        // u = 0 lies halfway between the left column's centre and the right
        // column's (wrapped) centre.
        let repeat = image.bilinear(DVec2::new(0.0, 0.75), [Wrap::Repeat; 2]);
        assert!((repeat - (Color::X + Color::Y) / 2.0).length() < 1e-12);
        assert_eq!(image.bilinear(DVec2::new(0.0, 0.75), [Wrap::Clamp; 2]), Color::X);
        // One whole period away reads the same texel.
        assert_eq!(image.bilinear(DVec2::new(2.25, -0.75), [Wrap::Repeat; 2]), Color::Z);
    }

    #[test]
    fn non_finite_coordinates_do_not_produce_nan() {
        let c = two_by_two().bilinear(DVec2::new(f64::NAN, 0.5), [Wrap::Repeat; 2]);
        assert!(c.is_finite());
    }
}
