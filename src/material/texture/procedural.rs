//! Procedural patterns: colours computed from where the point is, no file.

use crate::color::Color;
use glam::{DVec2, DVec3};

/// Alternating squares of two colours, one square per unit of mapped
/// coordinates: colour `(⌊u⌋ + ⌊v⌋) mod 2`.
#[inline]
pub fn checker(colors: &[Color; 2], uv: DVec2) -> Color {
    let parity = (uv.x.floor() as i64).wrapping_add(uv.y.floor() as i64).rem_euclid(2);
    colors[parity as usize]
}

/// A linear ramp between two colours along a world-space axis: `colors[0]`
/// where `point·axis ≤ from`, `colors[1]` where it is ≥ `to`, linear between.
#[derive(Clone, Debug)]
pub struct Gradient {
    /// The colours at `from` and at `to`.
    pub colors: [Color; 2],
    /// Unit direction of the ramp.
    pub axis: DVec3,
    /// Where along `axis` (as `point·axis`) the ramp starts: `colors[0]`.
    pub from: f64,
    /// Where along `axis` the ramp ends: `colors[1]`.
    pub to: f64,
}

impl Gradient {
    /// `None` if the axis is zero or `from == to`.
    pub fn new(colors: [Color; 2], axis: DVec3, from: f64, to: f64) -> Option<Self> {
        let axis = axis.try_normalize()?;
        (from != to && from.is_finite() && to.is_finite()).then_some(Self { colors, axis, from, to })
    }

    /// The colour at world-space `point`.
    #[inline]
    pub fn evaluate(&self, point: DVec3) -> Color {
        let t = ((point.dot(self.axis) - self.from) / (self.to - self.from)).clamp(0.0, 1.0);
        // Clamp maps NaN to NaN; a NaN point reads the start colour instead.
        let t = if t.is_nan() { 0.0 } else { t };
        self.colors[0].lerp(self.colors[1], t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checker_alternates_including_negative_coordinates() {
        let colors = [Color::ZERO, Color::ONE];
        assert_eq!(checker(&colors, DVec2::new(0.5, 0.5)), Color::ZERO);
        assert_eq!(checker(&colors, DVec2::new(1.5, 0.5)), Color::ONE);
        assert_eq!(checker(&colors, DVec2::new(-0.5, 0.5)), Color::ONE);
        assert_eq!(checker(&colors, DVec2::new(-0.5, -0.5)), Color::ZERO);
    }

    #[test]
    fn gradient_is_linear_between_its_ends_and_constant_beyond() {
        let g = Gradient::new([Color::X, Color::Z], DVec3::new(0.0, 2.0, 0.0), 1.0, 3.0);
        let g = g.unwrap_or_else(|| panic!("valid gradient"));
        // Linear interpolation of exact binary fractions: exact to 1e-15.
        assert!((g.evaluate(DVec3::new(7.0, 1.5, -2.0)) - Color::new(0.75, 0.0, 0.25)).length() < 1e-15);
        assert_eq!(g.evaluate(DVec3::new(0.0, -4.0, 0.0)), Color::X);
        assert_eq!(g.evaluate(DVec3::new(0.0, 40.0, 0.0)), Color::Z);
        assert!(Gradient::new([Color::X, Color::Z], DVec3::ZERO, 0.0, 1.0).is_none());
        assert!(Gradient::new([Color::X, Color::Z], DVec3::Y, 1.0, 1.0).is_none());
    }
}
