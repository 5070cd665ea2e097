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

#[derive(Clone, Debug)]
pub enum Texture {
    Constant(Color),
    /// `wrap` is per axis (u, v): a globe repeats around but clamps at the poles.
    Image {
        image: Arc<Image>,
        mapping: Mapping,
        wrap: [Wrap; 2],
    },
    Checker {
        colors: [Color; 2],
        mapping: Mapping,
    },
    /// Along a world-space axis; no mapping.
    Gradient(Gradient),
}

impl Texture {
    #[inline]
    pub fn evaluate(&self, at: &ShadingPoint) -> Color {
        match self {
            Texture::Constant(c) => *c,
            Texture::Image { image, mapping, wrap } => image.bilinear(mapping.map(at), *wrap),
            Texture::Checker { colors, mapping } => procedural::checker(colors, mapping.map(at)),
            Texture::Gradient(gradient) => gradient.evaluate(at.point),
        }
    }
}
