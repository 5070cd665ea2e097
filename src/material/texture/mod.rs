//! Textures: colours that vary over a surface. Every reflectance of a material
//! (diffuse albedo, glossy and mirror tint) is one.
//!
//! A texture is a pattern (constant, image, checker, gradient) read through a
//! [`Mapping`] from the [`ShadingPoint`]. Images are decoded once per file and
//! shared by `Arc` ([`ImageCache`]); a constant costs one `match`.

pub mod image;
pub mod mapping;
pub mod procedural;

pub use image::{Image, ImageCache, ImageError, Wrap};
pub use mapping::{Mapping, PlanarProjection, Projection, SphereProjection};
pub use procedural::Gradient;

use super::ShadingPoint;
use crate::color::Color;
use std::sync::Arc;

/// A reflectance (linear RGB) that may vary over a surface, evaluated at a
/// [`ShadingPoint`].
#[derive(Clone, Debug)]
pub enum Texture {
    /// The same colour everywhere.
    Constant(Color),
    /// `wrap` is per axis (u, v): a globe repeats around but clamps at the poles.
    Image {
        /// The decoded picture, shared by every texture that uses the file.
        image: Arc<Image>,
        /// Where on the picture a point falls.
        mapping: Mapping,
        /// What happens outside [0, 1] in u and in v.
        wrap: [Wrap; 2],
    },
    /// Squares of two colours alternating in the mapped coordinates (see
    /// [`procedural::checker`]).
    Checker {
        /// The colours of even and odd squares.
        colors: [Color; 2],
        /// Where in the pattern a point falls; its `scale` sets the squares
        /// per unit.
        mapping: Mapping,
    },
    /// Along a world-space axis; no mapping.
    Gradient(Gradient),
}

impl Texture {
    /// True if the texture is one colour everywhere (reads nothing of the point).
    pub fn is_constant(&self) -> bool {
        matches!(self, Texture::Constant(_))
    }

    /// The reflectance at `at`. A constant is read where it is needed; the
    /// patterns are a call away (the whole `match` inlined into every BSDF
    /// was too large to inline, which cost a call per constant too).
    #[inline(always)]
    pub fn evaluate(&self, at: &ShadingPoint) -> Color {
        match self {
            Texture::Constant(c) => *c,
            pattern => pattern.evaluate_pattern(at),
        }
    }

    /// [`Texture::evaluate`] for the textures that vary.
    #[inline(never)]
    fn evaluate_pattern(&self, at: &ShadingPoint) -> Color {
        match self {
            Texture::Constant(c) => *c,
            Texture::Image { image, mapping, wrap } => image.bilinear(mapping.map(at), *wrap),
            Texture::Checker { colors, mapping } => procedural::checker(colors, mapping.map(at)),
            Texture::Gradient(gradient) => gradient.evaluate(at.point),
        }
    }
}
