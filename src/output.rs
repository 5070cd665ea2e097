//! Writing frames to image files. Every write goes to a temporary file in
//! the destination folder and is renamed into place, so a crash or a full
//! disk never leaves a half-written image under the requested name.

use crate::film::{Frame, ToneMap};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Why an image could not be written; both name the file.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The file name's extension is not one of the formats Prism writes.
    #[error("{path}: unsupported image format (use .png, .bmp, .ppm or .exr)")]
    UnsupportedFormat {
        /// The requested image file.
        path: PathBuf,
    },
    /// Creating, writing or renaming the file failed.
    #[error("{path}: cannot write image: {message}")]
    Write {
        /// The requested image file.
        path: PathBuf,
        /// What failed.
        message: String,
    },
}

/// The image formats Prism writes, chosen by the file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// 8-bit sRGB PNG, with metadata as text chunks.
    Png,
    /// 8-bit sRGB BMP.
    Bmp,
    /// 8-bit sRGB PPM.
    Ppm,
    /// Linear 32-bit float OpenEXR (exposure applied, no tone mapping),
    /// with metadata as string attributes.
    Exr,
}

impl ImageFormat {
    /// The format named by `path`'s extension (case-insensitive); `None` for
    /// any other extension or none.
    pub fn from_path(path: &Path) -> Option<Self> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        match extension.as_str() {
            "png" => Some(Self::Png),
            "bmp" => Some(Self::Bmp),
            "ppm" => Some(Self::Ppm),
            "exr" => Some(Self::Exr),
            _ => None,
        }
    }
}

/// Saves `frame`: 8-bit sRGB after exposure and tone mapping for PNG, BMP and
/// PPM; linear 32-bit float for EXR. `metadata` goes into PNG text chunks.
pub fn save_frame(
    frame: &Frame,
    path: &Path,
    exposure_stops: f64,
    tone_map: ToneMap,
    metadata: &[(String, String)],
) -> Result<(), OutputError> {
    PendingImage::create(path)?.save(frame, exposure_stops, tone_map, metadata)
}

/// An image file about to be written, checked before any rendering: its
/// format is known and its temporary file already exists in the destination
/// folder (so the folder exists and is writable). [`PendingImage::save`]
/// writes the temporary file and renames it into place; dropping an unsaved
/// one removes the temporary file.
#[derive(Debug)]
pub struct PendingImage {
    path: PathBuf,
    temporary: PathBuf,
    format: ImageFormat,
}

impl PendingImage {
    /// Checks the format and creates the (empty) temporary file.
    pub fn create(path: &Path) -> Result<Self, OutputError> {
        let failed = |message: String| OutputError::Write {
            path: path.to_path_buf(),
            message,
        };
        // Before the format: `-o out` naming a folder is that mistake, not
        // a missing extension.
        if path.is_dir() {
            return Err(failed("is a directory".into()));
        }
        let format = ImageFormat::from_path(path).ok_or_else(|| OutputError::UnsupportedFormat {
            path: path.to_path_buf(),
        })?;
        let directory = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if !directory.is_dir() {
            return Err(failed(format!("folder {} does not exist", directory.display())));
        }
        let file_name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let temporary = directory.join(format!(".{file_name}.{}.tmp", std::process::id()));
        File::create(&temporary).map_err(|e| failed(format!("cannot create a file in {}: {e}", directory.display())))?;
        Ok(Self {
            path: path.to_path_buf(),
            temporary,
            format,
        })
    }

    /// The temporary file, for a caller that must remove it on a hard exit.
    pub fn temporary_path(&self) -> &Path {
        &self.temporary
    }

    /// Writes `frame` to the temporary file and renames it to the final name.
    pub fn save(
        self,
        frame: &Frame,
        exposure_stops: f64,
        tone_map: ToneMap,
        metadata: &[(String, String)],
    ) -> Result<(), OutputError> {
        let result = write_to(frame, &self.temporary, self.format, exposure_stops, tone_map, metadata)
            .and_then(|()| std::fs::rename(&self.temporary, &self.path).map_err(|e| e.to_string()));
        result.map_err(|message| OutputError::Write {
            path: self.path.clone(),
            message,
        })
        // Drop removes the temporary file if the rename did not happen.
    }
}

impl Drop for PendingImage {
    fn drop(&mut self) {
        if self.temporary.exists() {
            let _ = std::fs::remove_file(&self.temporary);
        }
    }
}

fn write_to(
    frame: &Frame,
    path: &Path,
    format: ImageFormat,
    exposure_stops: f64,
    tone_map: ToneMap,
    metadata: &[(String, String)],
) -> Result<(), String> {
    let (width, height) = (frame.width, frame.height);
    match format {
        ImageFormat::Exr => write_exr(frame, path, exposure_stops, metadata),
        ImageFormat::Png => {
            let data: Vec<u8> = frame.to_srgb8(exposure_stops, tone_map).into_iter().flatten().collect();
            let file = File::create(path).map_err(|e| e.to_string())?;
            let mut encoder = png::Encoder::new(BufWriter::new(file), width, height);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
            for (key, value) in metadata {
                encoder
                    .add_text_chunk(key.clone(), value.clone())
                    .map_err(|e| e.to_string())?;
            }
            let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
            writer.write_image_data(&data).map_err(|e| e.to_string())?;
            writer.finish().map_err(|e| e.to_string())
        }
        ImageFormat::Bmp | ImageFormat::Ppm => {
            let data: Vec<u8> = frame.to_srgb8(exposure_stops, tone_map).into_iter().flatten().collect();
            let buffer = image::RgbImage::from_raw(width, height, data).ok_or("frame size mismatch")?;
            let format = if format == ImageFormat::Bmp {
                image::ImageFormat::Bmp
            } else {
                image::ImageFormat::Pnm
            };
            let mut writer = BufWriter::new(File::create(path).map_err(|e| e.to_string())?);
            let mut bytes = std::io::Cursor::new(Vec::new());
            buffer.write_to(&mut bytes, format).map_err(|e| e.to_string())?;
            writer.write_all(bytes.get_ref()).map_err(|e| e.to_string())?;
            writer.flush().map_err(|e| e.to_string())
        }
    }
}

/// Linear 32-bit float RGB through the `exr` crate directly (image's encoder
/// cannot attach attributes); `metadata` becomes string attributes.
fn write_exr(frame: &Frame, path: &Path, exposure_stops: f64, metadata: &[(String, String)]) -> Result<(), String> {
    use exr::prelude::*;
    if frame.pixels.len() != frame.width as usize * frame.height as usize {
        return Err("frame size mismatch".into());
    }
    let scale = exposure_stops.exp2() as f32;
    let width = frame.width as usize;
    let channels = SpecificChannels::rgb(|position: Vec2<usize>| {
        let p = frame.pixels[position.y() * width + position.x()];
        (p[0] * scale, p[1] * scale, p[2] * scale)
    });
    let mut attributes = LayerAttributes::default();
    for (key, value) in metadata {
        // EXR text is Latin-1 without NUL; anything else is left out.
        if let (Some(key), Some(value)) = (Text::new_or_none(key), Text::new_or_none(value)) {
            attributes.other.insert(key, AttributeValue::Text(value));
        }
    }
    let layer = Layer::new((width, frame.height as usize), attributes, Encoding::FAST_LOSSLESS, channels);
    Image::from_layer(layer).write().to_file(path).map_err(|e| e.to_string())
}

/// Reads an image file back as a linear frame (EXR stays linear; 8-bit
/// formats are sRGB-decoded). Used by benchmarks, tests and the viewer's
/// reference image. Errors name the file.
pub fn load_frame(path: &Path) -> Result<Frame, String> {
    // A named pipe would block the reader (and the viewer's window with it).
    crate::input_file::regular_file(path)?;
    let image = image::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let is_float = matches!(
        image,
        image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
    );
    let rgb = image.to_rgb32f();
    let (width, height) = rgb.dimensions();
    let pixels = rgb
        .pixels()
        .map(|p| {
            if is_float {
                p.0
            } else {
                p.0.map(|c| crate::color::srgb_decode(c as f64) as f32)
            }
        })
        .collect();
    Ok(Frame {
        width,
        height,
        pixels,
        noise: Vec::new(),
    })
}
