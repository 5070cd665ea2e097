//! Textures: colours that vary over a surface. Every material colour is one.

use super::ShadingPoint;
use crate::color::Color;

#[derive(Clone, Debug)]
pub enum Texture {
    Constant(Color),
}

impl Texture {
    #[inline]
    pub fn evaluate(&self, _at: &ShadingPoint) -> Color {
        match self {
            Texture::Constant(c) => *c,
        }
    }
}
