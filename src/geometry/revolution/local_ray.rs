//! A ray in the local frame of a surface of revolution, described in the
//! frame rotated about the axis so that its horizontal direction is `+x'`:
//! the ray is `(o + s h, δ, o_z + s D_z)` with `h = |D_xy|`, `o = O·D̂_xy`
//! and `δ` the signed distance of the ray's vertical plane from the axis.
//! A vertical ray (`h = 0`) uses `D̂_xy = x̂`.

use crate::math::gamma;
use glam::{DVec2, DVec3};

/// The ray in local space, with the rotated-frame quantities of the module
/// docs.
#[derive(Clone, Copy, Debug)]
pub(super) struct LocalRay {
    pub(super) origin: DVec3,
    pub(super) direction: DVec3,
    /// `h = |D_xy|`.
    pub(super) horizontal_speed: f64,
    /// `o = O_xy · D̂_xy`: minus the ray parameter (times `h`) of the closest
    /// approach to the axis.
    pub(super) along: f64,
    /// `δ`: signed distance from the axis to the ray's vertical plane.
    pub(super) across: f64,
    /// Error bound of `along` and `across`.
    pub(super) frame_error: f64,
}

impl LocalRay {
    /// The ray from the local `origin` along the local `direction`.
    pub(super) fn new(origin: DVec3, direction: DVec3) -> Self {
        let horizontal_speed = super::axis_distance(direction.x, direction.y);
        let unit = if horizontal_speed > 0.0 {
            DVec2::new(direction.x, direction.y) / horizontal_speed
        } else {
            DVec2::X
        };
        Self {
            origin,
            direction,
            horizontal_speed,
            along: origin.x * unit.x + origin.y * unit.y,
            across: origin.y * unit.x - origin.x * unit.y,
            frame_error: gamma(8) * (origin.x.abs() + origin.y.abs()),
        }
    }

    /// The range of `s` where the ray is inside the cylinder `r ≤ radius`,
    /// `z ∈ [z_min, z_max]`, or `None` if it never is.
    pub(super) fn cylinder_span(&self, radius: f64, z_min: f64, z_max: f64) -> Option<(f64, f64)> {
        let (mut low, mut high) = (f64::NEG_INFINITY, f64::INFINITY);
        if self.horizontal_speed > 0.0 {
            let remaining = (radius - self.across.abs()) * (radius + self.across.abs());
            if remaining < 0.0 {
                return None;
            }
            let half = remaining.sqrt() / self.horizontal_speed;
            let center = -self.along / self.horizontal_speed;
            (low, high) = (center - half, center + half);
        } else if super::axis_distance(self.origin.x, self.origin.y) > radius {
            return None;
        }
        let dz = self.direction.z;
        if dz != 0.0 {
            let (a, b) = ((z_min - self.origin.z) / dz, (z_max - self.origin.z) / dz);
            (low, high) = (low.max(a.min(b)), high.min(a.max(b)));
        } else if self.origin.z < z_min || self.origin.z > z_max {
            return None;
        }
        // Widen by the rounding of the quotients above.
        let slack = 1e-9 * (low.abs().min(high.abs()) + 1.0);
        (low <= high).then_some((low - slack, high + slack))
    }
}
