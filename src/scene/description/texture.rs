//! Colour fields as written: an RGB array, or an inline table describing a
//! texture. Documented in docs/scene-format.md ("Textures").
//!
//! The table is one struct of optional keys rather than an untagged enum, so
//! a misspelt key is reported by name; which keys may go together is checked
//! by hand in `scene::load` (pbrt's rule: an unused parameter is an error).

use super::Vector;
use serde::Deserialize;
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use std::fmt;

/// A reflectance: a constant colour or a texture.
#[derive(Debug, Clone)]
pub enum ColorDescription {
    /// A constant linear RGB colour, `[r, g, b]`.
    Rgb(Vector),
    /// A texture table, `{ image = "…" }` and the like.
    Texture(Box<TextureDescription>),
}

impl<'de> Deserialize<'de> for ColorDescription {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct ColorVisitor;
        impl<'de> Visitor<'de> for ColorVisitor {
            type Value = ColorDescription;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an RGB array such as [0.5, 0.5, 0.5] or a texture table such as { image = \"file.png\" }")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
                Vector::deserialize(de::value::SeqAccessDeserializer::new(seq)).map(ColorDescription::Rgb)
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
                TextureDescription::deserialize(de::value::MapAccessDeserializer::new(map))
                    .map(|t| ColorDescription::Texture(Box::new(t)))
            }
        }
        deserializer.deserialize_any(ColorVisitor)
    }
}

/// Exactly one pattern key (`image`, `checker`, `gradient`) plus the keys that
/// pattern uses.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureDescription {
    /// Image file (PNG, JPEG, BMP), relative to the scene file.
    pub image: Option<String>,
    /// Two colours alternating in unit squares of the mapped coordinates.
    pub checker: Option<[Vector; 2]>,
    /// Two colours ramped along `axis` from `from` to `to` (world units).
    pub gradient: Option<[Vector; 2]>,
    /// How points become texture coordinates; default `uv`.
    pub mapping: Option<MappingKind>,
    /// Sphere mapping: turn the globe, degrees about +y (a number) or Euler
    /// angles about x, then y, then z (an array), as object transforms.
    pub rotate_degrees: Option<Numbers<3>>,
    /// Sphere mapping: project from this point instead of using the sphere's uv.
    pub center: Option<Vector>,
    /// Planar mapping: the parallelogram `origin + a·edge_u + b·edge_v` ↦ (a, b).
    pub origin: Option<Vector>,
    /// Planar mapping: the side along which a (u) grows.
    pub edge_u: Option<Vector>,
    /// Planar mapping: the side along which b (v) grows.
    pub edge_v: Option<Vector>,
    /// Repetitions per unit of mapped coordinates: a number or [u, v].
    pub scale: Option<Numbers<2>>,
    /// Image only: `repeat` (default) or `clamp`.
    pub wrap: Option<WrapKind>,
    /// Gradient only: direction of the ramp (default +y) and where it starts
    /// and ends along it (default 0 and 1).
    pub axis: Option<Vector>,
    /// Gradient only: where along `axis` the ramp starts (first colour).
    pub from: Option<f64>,
    /// Gradient only: where along `axis` the ramp ends (second colour).
    pub to: Option<f64>,
}

/// The `mapping` key: how points become texture coordinates (see
/// [`crate::material::texture::Projection`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MappingKind {
    /// The shape's own uv parameterisation (the default).
    Uv,
    /// Latitude and longitude of the direction from a centre, as on a globe.
    Sphere,
    /// Affine coordinates in a parallelogram (`origin`, `edge_u`, `edge_v`).
    Planar,
}

/// The `wrap` key of an image texture.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WrapKind {
    /// Tile the picture (the default).
    Repeat,
    /// Extend the border texels.
    Clamp,
}

/// A number (meaning the same value for every component) or an array of `N`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Numbers<const N: usize> {
    /// A single number.
    One(f64),
    /// One number per component.
    Each([f64; N]),
}

impl<'de, const N: usize> Deserialize<'de> for Numbers<N> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct NumbersVisitor<const N: usize>;
        impl<'de, const N: usize> Visitor<'de> for NumbersVisitor<N> {
            type Value = Numbers<N>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "a number or an array of {N} numbers")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
                Ok(Numbers::One(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
                Ok(Numbers::One(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
                Ok(Numbers::One(v as f64))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut values = [0.0; N];
                for (i, value) in values.iter_mut().enumerate() {
                    *value = seq.next_element()?.ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                if seq.next_element::<f64>()?.is_some() {
                    return Err(de::Error::invalid_length(N + 1, &self));
                }
                Ok(Numbers::Each(values))
            }
        }
        deserializer.deserialize_any(NumbersVisitor::<N>)
    }
}

impl<const N: usize> Numbers<N> {
    /// The `N` components; a single number is repeated `N` times.
    pub fn to_array(self) -> [f64; N] {
        match self {
            Numbers::One(v) => [v; N],
            Numbers::Each(values) => values,
        }
    }
}
