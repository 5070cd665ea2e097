//! Emissive materials: an RGB `radiance`, or a spectrum of its own (a named
//! CIE illuminant or a blackbody temperature) scaled by `luminance`. Which
//! keys go together, and their ranges.

use super::Builder;
use crate::material::Material;
use crate::scene::description::Vector;
use crate::scene::document::FieldPath;
use crate::scene::error::SceneError;
use crate::spectrum::blackbody::{TEMPERATURE_MAX, TEMPERATURE_MIN};
use crate::spectrum::{EmissionSpectrum, SpectrumSource, StandardIlluminant};
use std::sync::Arc;

/// The keys of an emissive material that say what it emits.
pub(super) struct EmissiveKeys<'d> {
    pub radiance: Option<Vector>,
    pub spectrum: Option<&'d str>,
    pub temperature: Option<f64>,
    pub luminance: Option<f64>,
}

impl Builder<'_> {
    /// Checks and builds an emissive material; `path` is the material's.
    pub(super) fn emissive(&self, path: &FieldPath, keys: EmissiveKeys<'_>, two_sided: bool) -> Result<Material, SceneError> {
        let source = match (keys.spectrum, keys.temperature) {
            (Some(_), Some(_)) => {
                return Err(self.error(&path.key("temperature"), "give `spectrum` or `temperature`, not both"));
            }
            (Some(name), None) => Some(SpectrumSource::Illuminant(self.illuminant(&path.key("spectrum"), name)?)),
            (None, Some(kelvin)) => Some(SpectrumSource::Blackbody {
                kelvin: self.temperature(&path.key("temperature"), kelvin)?,
            }),
            (None, None) => None,
        };
        match (source, keys.radiance, keys.luminance) {
            (None, Some(radiance), None) => Ok(Material::Emissive {
                radiance: self.color(&path.key("radiance"), radiance)?,
                two_sided,
                spectrum: None,
            }),
            (None, Some(_), Some(_)) => Err(self.error(
                &path.key("luminance"),
                "`luminance` scales a `spectrum` or `temperature`; an RGB `radiance` is its own scale",
            )),
            (None, None, _) => Err(self.error(
                &path.key("radiance"),
                "missing field `radiance` (or a `spectrum` or `temperature` with a `luminance`)",
            )),
            (Some(_), Some(_), _) => Err(self.error(
                &path.key("radiance"),
                "give `radiance` or a `spectrum`/`temperature` with a `luminance`, not both",
            )),
            (Some(_), None, None) => Err(self.error(
                &path.key("luminance"),
                "missing field `luminance` (the emitter's brightness: 1 is that of `radiance = [1, 1, 1]`)",
            )),
            (Some(source), None, Some(luminance)) => {
                let luminance_path = path.key("luminance");
                self.finite(&luminance_path, &[luminance])?;
                if luminance < 0.0 {
                    return Err(self.error(&luminance_path, format!("must not be negative (found {luminance})")));
                }
                let spectrum = EmissionSpectrum::new(source, luminance);
                Ok(Material::Emissive {
                    radiance: spectrum.rgb(),
                    two_sided,
                    spectrum: Some(Arc::new(spectrum)),
                })
            }
        }
    }

    fn illuminant(&self, path: &FieldPath, name: &str) -> Result<StandardIlluminant, SceneError> {
        StandardIlluminant::named(name).ok_or_else(|| {
            let names: Vec<&str> = StandardIlluminant::NAMED.iter().map(|(n, _)| *n).collect();
            self.error(path, format!("unknown illuminant {name:?} (known: {})", names.join(", ")))
        })
    }

    fn temperature(&self, path: &FieldPath, kelvin: f64) -> Result<f64, SceneError> {
        self.finite(path, &[kelvin])?;
        if !(TEMPERATURE_MIN..=TEMPERATURE_MAX).contains(&kelvin) {
            return Err(self.error(
                path,
                format!("must be between {TEMPERATURE_MIN} and {TEMPERATURE_MAX} kelvin (found {kelvin})"),
            ));
        }
        Ok(kelvin)
    }
}
