//! The scene's specular balls: spheres of smooth, non-dispersive glass and
//! of mirror of one colour, which the path tracer connects lights through
//! and off (see `integrator::path::ball_connection`).

use super::Scene;
use crate::color::Color;
use crate::geometry::{BallOptics, Bounce};
use crate::material::{Material, Texture};

/// More specular balls than this and the connections are not made at all:
/// each costs a root scan per ball per connected shading point.
pub const MAX_SPECULAR_BALLS: usize = 8;

/// A sphere of glass whose index does not vary with wavelength, or of a
/// mirror whose colour does not vary over it. The glass is denser than
/// the space around it (index above 1): light entering a bubble of lower
/// index can be totally reflected, which the connection's paths through
/// do not model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularBall {
    /// The sphere's primitive id in the scene.
    pub primitive: u32,
    /// Its geometry (and index of refraction, for glass).
    pub optics: BallOptics,
    /// How connections meet it: through the glass, off the mirror.
    pub bounce: Bounce,
    /// The glass's colour, applied at each crossing, or the mirror's.
    pub tint: Color,
    /// No other primitive reaches inside the ball, so nothing can block a
    /// path across it.
    pub hollow: bool,
}

/// Every specular ball of `scene`, or none if there are more than [`MAX_SPECULAR_BALLS`].
pub(super) fn specular_balls(scene: &Scene) -> Vec<SpecularBall> {
    let mut balls: Vec<SpecularBall> = (0..scene.primitive_count() as u32)
        .filter_map(|primitive| {
            let (center, radius) = scene.primitive_sphere(primitive)?;
            if !(radius > 0.0 && radius.is_finite() && center.is_finite()) {
                return None;
            }
            let (bounce, ior, tint) = match *scene.material_of(primitive) {
                Material::Glass {
                    ior,
                    tint,
                    dispersion: None,
                } if ior > 1.0 && ior.is_finite() => (Bounce::Through, ior, tint),
                Material::Mirror {
                    tint: Texture::Constant(tint),
                } => (Bounce::Off, 1.0, tint),
                _ => return None,
            };
            Some(SpecularBall {
                primitive,
                optics: BallOptics { center, radius, ior },
                bounce,
                tint,
                hollow: true,
            })
        })
        .collect();
    if balls.len() > MAX_SPECULAR_BALLS {
        return Vec::new();
    }
    if !balls.is_empty() {
        mark_reached_inside(scene, &mut balls);
    }
    balls
}

/// Clears `hollow` on each ball that the bounds of another primitive come
/// nearer than its radius to the centre of (touching it from outside, as a
/// floor a ball rests on, does not count). One pass over the primitives,
/// each one's bounds computed once for all the balls.
fn mark_reached_inside(scene: &Scene, balls: &mut [SpecularBall]) {
    for primitive in 0..scene.primitive_count() as u32 {
        let bounds = scene.primitive_bounds(primitive);
        for ball in balls.iter_mut().filter(|ball| ball.primitive != primitive) {
            let BallOptics { center, radius, .. } = ball.optics;
            let nearest = center.clamp(bounds.min, bounds.max);
            if (nearest - center).length() < radius * (1.0 - 1e-9) {
                ball.hollow = false;
            }
        }
    }
}
