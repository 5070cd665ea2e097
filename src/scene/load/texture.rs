//! Colour fields → [`Texture`]s: which keys go together, value checks, and
//! image files decoded once per load through the [`ImageCache`].

use super::Builder;
use crate::color::Color;
use crate::geometry::Transform;
use crate::input_file::regular_file;
use crate::material::texture::{Gradient, ImageCache, Mapping, PlanarProjection, Projection, SphereProjection, Texture, Wrap};
use crate::scene::description::{ColorDescription, MappingKind, Numbers, TextureDescription, Vector, WrapKind};
use crate::scene::document::FieldPath;
use crate::scene::error::SceneError;
use glam::{DVec2, DVec3};

/// Which pattern a texture table names, for messages.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Pattern {
    Image,
    Checker,
    Gradient,
}

impl Pattern {
    fn name(self) -> &'static str {
        match self {
            Pattern::Image => "image",
            Pattern::Checker => "checker",
            Pattern::Gradient => "gradient",
        }
    }
}

/// A colour field being built: where it is written, and its largest allowed component.
struct Field<'f> {
    path: &'f FieldPath,
    /// Diffuse albedo may not exceed 1: it would create energy.
    at_most_one: bool,
}

impl Builder<'_> {
    /// The texture a colour field describes. `at_most_one` for albedos.
    pub(super) fn texture(
        &self,
        path: &FieldPath,
        color: &ColorDescription,
        at_most_one: bool,
        images: &mut ImageCache,
    ) -> Result<Texture, SceneError> {
        let field = Field { path, at_most_one };
        match color {
            ColorDescription::Rgb(rgb) => Ok(Texture::Constant(self.reflectance(&field, None, *rgb)?)),
            ColorDescription::Texture(table) => self.texture_table(&field, table, images),
        }
    }

    /// An error about `key` inside the texture table of `field` (or about the
    /// whole field when `key` is `None`), placed where it is written.
    fn texture_error(&self, field: &Field, key: Option<&str>, message: impl Into<String>) -> SceneError {
        match key {
            Some(key) => self.error(&field.path.key(key), message),
            None => self.error(field.path, message),
        }
    }

    fn reflectance(&self, field: &Field, key: Option<&str>, rgb: Vector) -> Result<Color, SceneError> {
        if rgb.iter().any(|v| !v.is_finite()) {
            return Err(self.texture_error(field, key, "must be a finite number (found NaN or infinity)"));
        }
        if rgb.iter().any(|&v| v < 0.0) {
            return Err(self.texture_error(field, key, "colour components must not be negative"));
        }
        if field.at_most_one && rgb.iter().any(|&v| v > 1.0) {
            return Err(self.texture_error(field, key, "must not exceed 1 (it would create energy)"));
        }
        Ok(DVec3::from_array(rgb))
    }

    fn finite_vector(&self, field: &Field, key: &str, v: Option<Vector>) -> Result<Option<DVec3>, SceneError> {
        match v {
            Some(v) if v.iter().any(|c| !c.is_finite()) => Err(self.texture_error(field, Some(key), "must be finite numbers")),
            Some(v) => {
                // Texture centres, origins and edges are scene positions too.
                self.coordinates(&field.path.key(key), &v)?;
                Ok(Some(DVec3::from_array(v)))
            }
            None => Ok(None),
        }
    }

    fn texture_table(&self, field: &Field, t: &TextureDescription, images: &mut ImageCache) -> Result<Texture, SceneError> {
        // Exactly one pattern.
        let named: Vec<Pattern> = [
            (t.image.is_some(), Pattern::Image),
            (t.checker.is_some(), Pattern::Checker),
            (t.gradient.is_some(), Pattern::Gradient),
        ]
        .into_iter()
        .filter_map(|(present, pattern)| present.then_some(pattern))
        .collect();
        let pattern = match named.as_slice() {
            [one] => *one,
            [] => {
                return Err(self.texture_error(field, None, "a texture table needs one of `image`, `checker` or `gradient`"));
            }
            [_, second, ..] => {
                return Err(self.texture_error(
                    field,
                    Some(second.name()),
                    "give only one of `image`, `checker` or `gradient`",
                ));
            }
        };

        // Keys that belong to another pattern are mistakes, not silently ignored.
        let only = |present: bool, key: &str, allowed: &[Pattern]| {
            if present && !allowed.contains(&pattern) {
                let allowed: Vec<&str> = allowed.iter().map(|p| p.name()).collect();
                Err(self.texture_error(
                    field,
                    Some(key),
                    format!(
                        "does not apply to {} textures (only to {})",
                        pattern.name(),
                        allowed.join(", ")
                    ),
                ))
            } else {
                Ok(())
            }
        };
        use Pattern::{Checker, Image};
        for (present, key) in [
            (t.mapping.is_some(), "mapping"),
            (t.scale.is_some(), "scale"),
            (t.rotate_degrees.is_some(), "rotate_degrees"),
            (t.center.is_some(), "center"),
            (t.origin.is_some(), "origin"),
            (t.edge_u.is_some(), "edge_u"),
            (t.edge_v.is_some(), "edge_v"),
        ] {
            only(present, key, &[Image, Checker])?;
        }
        only(t.wrap.is_some(), "wrap", &[Image])?;
        only(t.axis.is_some(), "axis", &[Pattern::Gradient])?;
        only(t.from.is_some(), "from", &[Pattern::Gradient])?;
        only(t.to.is_some(), "to", &[Pattern::Gradient])?;

        match pattern {
            Pattern::Gradient => {
                let colors = t.gradient.unwrap_or_default();
                let colors = [
                    self.reflectance(field, Some("gradient"), colors[0])?,
                    self.reflectance(field, Some("gradient"), colors[1])?,
                ];
                let axis = self.finite_vector(field, "axis", t.axis)?.unwrap_or(DVec3::Y);
                let (from, to) = (t.from.unwrap_or(0.0), t.to.unwrap_or(1.0));
                let gradient = Gradient::new(colors, axis, from, to).ok_or_else(|| {
                    let key = if axis == DVec3::ZERO { "axis" } else { "to" };
                    self.texture_error(field, Some(key), "needs a non-zero `axis` and finite `from` ≠ `to`")
                })?;
                Ok(Texture::Gradient(gradient))
            }
            Pattern::Checker => {
                let colors = t.checker.unwrap_or_default();
                let colors = [
                    self.reflectance(field, Some("checker"), colors[0])?,
                    self.reflectance(field, Some("checker"), colors[1])?,
                ];
                let mapping = self.mapping(field, t, t.mapping.unwrap_or(MappingKind::Uv))?;
                Ok(Texture::Checker { colors, mapping })
            }
            Pattern::Image => {
                let mapping = self.mapping(field, t, t.mapping.unwrap_or(MappingKind::Uv))?;
                let wrap = match (t.wrap, &mapping.projection) {
                    (Some(WrapKind::Clamp), _) => [Wrap::Clamp; 2],
                    (Some(WrapKind::Repeat), _) => [Wrap::Repeat; 2],
                    // Around a globe longitude wraps; at the poles the top
                    // row must not blend with the bottom one.
                    (None, Projection::Sphere(_)) => [Wrap::Repeat, Wrap::Clamp],
                    (None, _) => [Wrap::Repeat; 2],
                };
                let file = self.base.join(t.image.as_deref().unwrap_or_default());
                // A missing file is reported by the image cache; a folder or a
                // device (which would be read forever) is refused here.
                if file.exists() {
                    regular_file(&file).map_err(|e| self.texture_error(field, Some("image"), format!("image file {e}")))?;
                }
                let image = images
                    .load(&file)
                    .map_err(|e| self.texture_error(field, Some("image"), e.to_string()))?;
                Ok(Texture::Image { image, mapping, wrap })
            }
        }
    }

    /// The mapping `kind` with its keys; keys of other mappings are errors.
    fn mapping(&self, field: &Field, t: &TextureDescription, kind: MappingKind) -> Result<Mapping, SceneError> {
        let misplaced = |present: bool, key: &str, wanted: &str| {
            if present {
                Err(self.texture_error(field, Some(key), format!("applies only with mapping = \"{wanted}\"")))
            } else {
                Ok(())
            }
        };
        if kind != MappingKind::Sphere {
            misplaced(t.rotate_degrees.is_some(), "rotate_degrees", "sphere")?;
            misplaced(t.center.is_some(), "center", "sphere")?;
        }
        if kind != MappingKind::Planar {
            misplaced(t.origin.is_some(), "origin", "planar")?;
            misplaced(t.edge_u.is_some(), "edge_u", "planar")?;
            misplaced(t.edge_v.is_some(), "edge_v", "planar")?;
        }

        let scale = DVec2::from_array(t.scale.map_or([1.0; 2], Numbers::to_array));
        if !(scale.is_finite() && scale.x != 0.0 && scale.y != 0.0) {
            return Err(self.texture_error(field, Some("scale"), "must be finite and non-zero"));
        }
        let projection = match kind {
            MappingKind::Uv => Projection::Uv,
            MappingKind::Sphere => {
                let degrees = match t.rotate_degrees {
                    None => None,
                    Some(Numbers::One(about_y)) => Some([0.0, about_y, 0.0]),
                    Some(Numbers::Each(euler)) => Some(euler),
                };
                let degrees = self.finite_vector(field, "rotate_degrees", degrees)?;
                // The same Euler convention as object transforms.
                let rotation = degrees.map(|d| Transform::new(DVec3::ZERO, d, DVec3::ONE).to_world.matrix3);
                let center = self.finite_vector(field, "center", t.center)?;
                Projection::Sphere(SphereProjection::new(rotation, center))
            }
            MappingKind::Planar => {
                let mut corners = [DVec3::ZERO; 3];
                for (corner, (key, value)) in
                    corners
                        .iter_mut()
                        .zip([("origin", t.origin), ("edge_u", t.edge_u), ("edge_v", t.edge_v)])
                {
                    *corner = self
                        .finite_vector(field, key, value)?
                        .ok_or_else(|| self.texture_error(field, Some("mapping"), format!("planar mapping needs `{key}`")))?;
                }
                let plane = PlanarProjection::new(corners[0], corners[1], corners[2])
                    .ok_or_else(|| self.texture_error(field, Some("edge_v"), "edges must not be parallel or zero"))?;
                Projection::Planar(plane)
            }
        };
        Ok(Mapping { projection, scale })
    }
}
