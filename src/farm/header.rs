//! The header of a film file: what image the part belongs to, and which of
//! its samples it holds. Written as TOML, so `head -c 2000 part.film` shows
//! it.
//!
//! Two parts belong to the same image when their `width`, `height` and
//! every entry of `image` agree: Prism's version, the scene's content hash
//! ([`super::content_hash`]) and every setting that changes the image for
//! the integrator used (a setting the integrator never reads is left out,
//! so it cannot make equal images look different). Values are kept as text,
//! floats in Rust's shortest form that reads back to the same bits, so the
//! comparison is exact and an error can quote both values.

use super::FarmError;
use crate::integrator::{RowSet, Share};
use crate::settings::{IntegratorKind, RenderSettings};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// One film file's header.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilmHeader {
    /// The scene file's name, for people (not compared: the hash is).
    pub scene: String,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The samples every row should have once all parts are in (the
    /// `--spp` a `--part K/N` split), when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_samples: Option<u32>,
    /// Samples dropped as NaN, infinite or too large, over all pixels.
    pub rejected_samples: u64,
    /// Light paths traced per pass, when the film holds light-path
    /// contributions (path tracing with `caustic_light_paths`): the records
    /// are then followed by one light record per pixel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub light_paths_per_pass: Option<u64>,
    /// What must agree between parts of one image (see the module doc).
    pub image: BTreeMap<String, String>,
    /// The samples held: blocks of rows, each with a range of sample indices.
    pub coverage: Vec<CoverageBlock>,
}

/// Sample indices `samples[0]..samples[1]` of rows `first_row`,
/// `first_row + row_step`, … (every row when 0 and 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoverageBlock {
    /// The first row covered (0 at the top).
    pub first_row: u32,
    /// Distance between covered rows; 1 for every row from `first_row` on
    /// (never 0 in a valid file).
    pub row_step: u32,
    /// The half-open range of sample indices each covered row holds.
    pub samples: [u32; 2],
}

impl CoverageBlock {
    /// The block of one render's share.
    pub fn of_share(share: &Share) -> Self {
        Self {
            first_row: share.rows.first,
            row_step: share.rows.step,
            samples: [share.samples.start, share.samples.end],
        }
    }

    /// The block's rows.
    pub fn rows(&self) -> RowSet {
        RowSet {
            first: self.first_row,
            step: self.row_step,
        }
    }

    /// Whether row `y` is one of the block's rows.
    pub fn contains_row(&self, y: u32) -> bool {
        self.rows().contains(y)
    }

    /// Samples per covered row.
    pub fn len(&self) -> u32 {
        self.samples[1].saturating_sub(self.samples[0])
    }

    /// Whether the block holds no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The entries of [`FilmHeader::image`] for a render of `settings` of a
/// scene with content hash `scene_hash`.
pub fn image_identity(settings: &RenderSettings, scene_hash: &str) -> BTreeMap<String, String> {
    let mut image = BTreeMap::new();
    let mut put = |key: &str, value: String| {
        image.insert(key.to_string(), value);
    };
    put("prism_version", env!("CARGO_PKG_VERSION").to_string());
    put("scene_hash", scene_hash.to_string());
    put("integrator", settings.integrator.to_string());
    put("sampler", settings.sampler.to_string());
    put("seed", settings.seed.to_string());
    put("max_depth", settings.max_depth.to_string());
    if settings.spectral {
        // Only when set, so RGB films keep the headers they always had.
        put("spectral", "true".to_string());
    }
    if settings.caustic_light_paths && settings.integrator == IntegratorKind::PathTracing {
        put("caustic_light_paths", "true".to_string());
    }
    match settings.integrator {
        IntegratorKind::PathTracing | IntegratorKind::BsdfOnly => {
            let threshold = settings.adaptive_threshold.map_or("off".into(), |t| format!("{t:?}"));
            put("adaptive_threshold", threshold);
        }
        IntegratorKind::Sppm => {
            let sppm = &settings.sppm;
            put("photons_per_iteration", sppm.photons_per_iteration.to_string());
            put(
                "initial_radius",
                sppm.initial_radius.map_or("auto".into(), |r| format!("{r:?}")),
            );
            put("alpha", format!("{:?}", sppm.alpha));
            put("radius_schedule", sppm.radius_schedule.to_string());
        }
    }
    image
}

impl FilmHeader {
    /// The header of a render of `share` with `settings`.
    pub fn new(scene: &str, settings: &RenderSettings, scene_hash: &str, share: &Share, target: Option<u32>) -> Self {
        Self {
            scene: scene.to_string(),
            width: settings.width,
            height: settings.height,
            target_samples: target,
            rejected_samples: 0,
            light_paths_per_pass: None,
            image: image_identity(settings, scene_hash),
            coverage: vec![CoverageBlock::of_share(share)],
        }
    }

    /// The header as TOML text (fails only on a count beyond TOML's 64-bit
    /// signed integers).
    pub fn to_toml(&self) -> Result<String, String> {
        toml::to_string(self).map_err(|e| format!("cannot write the header: {e}"))
    }

    /// Parses and checks a header read from `path`.
    pub fn from_toml(text: &str, path: &Path) -> Result<Self, FarmError> {
        let corrupt = |message: String| FarmError::Corrupt {
            path: path.to_path_buf(),
            message,
        };
        let header: FilmHeader = toml::from_str(text).map_err(|e| corrupt(format!("bad header: {}", e.message())))?;
        let max = crate::settings::validate::MAX_IMAGE_SIDE;
        if !(1..=max).contains(&header.width) || !(1..=max).contains(&header.height) {
            return Err(corrupt(format!("bad header: image size {}×{}", header.width, header.height)));
        }
        if let Some(block) = header
            .coverage
            .iter()
            .find(|b| b.row_step == 0 || b.samples[0] > b.samples[1])
        {
            return Err(corrupt(format!("bad header: coverage block {block:?}")));
        }
        Ok(header)
    }

    /// Checks that `other` (read from `other_path`) is a part of the same
    /// image as `self` (from `path`); the error names the first difference.
    pub fn check_same_image(&self, path: &Path, other: &FilmHeader, other_path: &Path) -> Result<(), FarmError> {
        let differ = |key: &str, value: String, other_value: String| FarmError::OtherImage {
            path: other_path.to_path_buf(),
            other: path.to_path_buf(),
            key: key.to_string(),
            value,
            other_value,
        };
        if (self.width, self.height) != (other.width, other.height) {
            return Err(differ(
                "the image size",
                format!("{}×{}", self.width, self.height),
                format!("{}×{}", other.width, other.height),
            ));
        }
        let keys = self.image.keys().chain(other.image.keys());
        for key in keys {
            let (value, other_value) = (self.image.get(key), other.image.get(key));
            if value != other_value {
                let show = |v: Option<&String>| v.cloned().unwrap_or_else(|| "not set".into());
                return Err(differ(key, show(value), show(other_value)));
            }
        }
        if let (Some(a), Some(b)) = (self.target_samples, other.target_samples)
            && a != b
        {
            return Err(differ("the planned samples per pixel", a.to_string(), b.to_string()));
        }
        Ok(())
    }

    /// Samples held over all pixels.
    pub fn samples_held(&self) -> u64 {
        self.coverage
            .iter()
            .map(|block| block.rows().rows(self.height).count() as u64 * self.width as u64 * block.len() as u64)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_read_back_and_name_what_differs() {
        let settings = RenderSettings {
            width: 8,
            height: 4,
            seed: u64::MAX,
            adaptive_threshold: Some(0.1 + 0.2),
            ..Default::default()
        };
        let header = FilmHeader::new("box.toml", &settings, "fnv1a64:0", &Share::whole(16), Some(16));
        let text = header.to_toml().expect("serialises");
        let back = FilmHeader::from_toml(&text, Path::new("a.film")).expect("reads back");
        assert_eq!(back, header);
        // Floats keep every bit: 0.1 + 0.2 is not 0.3.
        assert_eq!(back.image["adaptive_threshold"], "0.30000000000000004");
        assert_eq!(back.samples_held(), 8 * 4 * 16);

        let other = FilmHeader::new(
            "box.toml",
            &RenderSettings {
                seed: 7,
                ..settings.clone()
            },
            "fnv1a64:0",
            &Share::whole(16),
            None,
        );
        let error = header.check_same_image(Path::new("a.film"), &other, Path::new("b.film"));
        let message = error.err().map(|e| e.to_string()).unwrap_or_default();
        assert_eq!(
            message,
            "b.film: not a part of the same image as a.film: seed is 18446744073709551615 there but 7 here"
        );
        // SPPM's settings do not matter to a path tracer's image.
        let mut sppm_changed = settings.clone();
        sppm_changed.sppm.alpha = 0.5;
        let same = FilmHeader::new("box.toml", &sppm_changed, "fnv1a64:0", &Share::whole(16), Some(16));
        assert!(header.check_same_image(Path::new("a"), &same, Path::new("b")).is_ok());
    }

    #[test]
    fn malformed_headers_are_corrupt() {
        for text in [
            "width = 3",
            "not toml [",
            &FilmHeader::new("s", &RenderSettings::default(), "h", &Share::whole(1), None)
                .to_toml()
                .unwrap_or_default()
                .replace("row_step = 1", "row_step = 0"),
        ] {
            let error = FilmHeader::from_toml(text, Path::new("p.film"))
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(error.starts_with("p.film: corrupt: bad header"), "{text:?}: {error}");
        }
    }
}
