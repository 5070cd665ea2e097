//! Surfaces of revolution of Bezier profiles: a chain of planar Bezier
//! segments `(x(t), y(t))` rotated about the local z axis, so a surface point
//! is `(x(t) cos φ, x(t) sin φ, y(t))`, with optional flat caps.
//!
//! This file holds the surface itself: construction, placement, bounds and
//! normals. Its parts (profile segments and cap discs) are in `profile`, its
//! area and area sampling in `area`, and the nearest hit of a ray in
//! `intersect`, which takes the ray into the rotated frame of `local_ray` and
//! finds, segment by segment (`segment_hits`), the roots of the ray–profile
//! polynomial of `ray_profile`.
//!
//! # Conventions
//! - Profile points need `x ≥ 0` (the surface would otherwise fold through
//!   the axis). Outward is to the right of the profile's direction of travel
//!   in the `(x, y)` plane: the 2-D normal is `(y', −x')`, so a profile
//!   running upwards at `x > 0` faces away from the axis. On the axis the
//!   normal is `∓z` by the sign of `x'`. Where `c'(t) = 0` the tangent comes
//!   from the next non-vanishing derivative (`bezier::tangent_direction`).
//! - Caps close that orientation: the disc at the chain's start faces `−z`,
//!   the one at its end `+z`.
//! - `uv = (φ / 2π, (segment + t) / segments)`; caps use `v = 0` (start) and
//!   `v = 1` (end).
//! - The ray is taken into local space without renormalising its direction,
//!   so the local `s` is the world `t`. The transform must be a similarity
//!   (rotation, uniform scale, translation, optionally a mirror) so that
//!   `area` and `sample_area` are exact in world space.

mod area;
mod intersect;
mod local_ray;
mod profile;
mod ray_profile;
mod segment_hits;

use crate::geometry::bezier::{self, MAX_CONTROL_POINTS};
use crate::math::{Aabb, gamma};
use glam::{DAffine3, DMat3, DVec2, DVec3};
use profile::{Cap, Segment};

/// √(x² + y²), a point's distance from the axis. Not `f64::hypot`: that
/// is a library call (5% of vase.toml's time under `perf`), rounding once
/// where this rounds three times, within 2u relative, which each error
/// bound that uses it covers (the tightest, `LocalRay::frame_error`,
/// allows 8u for its 5u). Below 10⁻¹⁴⁰ the squares would lose precision to
/// underflow, so there (and on the axis) it is `hypot` after all, a
/// branch that is never taken in practice.
#[inline]
fn axis_distance(x: f64, y: f64) -> f64 {
    let distance = (x * x + y * y).sqrt();
    if distance < 1e-140 { x.hypot(y) } else { distance }
}

/// A Bezier profile rotated about the local z axis, placed by an affine map.
#[derive(Clone, Debug)]
pub struct Revolution {
    segments: Vec<Segment>,
    caps: Vec<Cap>,
    local_to_world: DAffine3,
    world_to_local: DAffine3,
    /// Inverse transpose of the linear part, for normals.
    normal_to_world: DMat3,
    /// Componentwise absolute value of the linear part, for error bounds.
    absolute_linear: DMat3,
    /// Uniform scale factor of the similarity transform.
    scale_factor: f64,
    /// Bounding cylinder of the whole profile: the segments' cylinders.
    radius: f64,
    z_min: f64,
    z_max: f64,
    /// Largest absolute control-point coordinate: the scale of rounding errors.
    size: f64,
    /// Cumulative local areas: segments first, then caps.
    cumulative_area: Vec<f64>,
}

impl Revolution {
    /// A surface of revolution of the profile chain `segments` (each 2 to
    /// `MAX_CONTROL_POINTS` control points `(x, y)`, `x ≥ 0`), with discs
    /// closing its ends if `caps`, placed by the similarity `local_to_world`.
    pub fn new(segments: Vec<Vec<DVec2>>, caps: bool, local_to_world: DAffine3) -> Result<Self, String> {
        if segments.is_empty() {
            return Err("a surface of revolution needs at least one profile segment".into());
        }
        for (index, points) in segments.iter().enumerate() {
            if points.len() < 2 || points.len() > MAX_CONTROL_POINTS {
                return Err(format!(
                    "profile segment {index} has {} control points; each segment needs 2 to {MAX_CONTROL_POINTS}",
                    points.len()
                ));
            }
            if let Some(point) = points.iter().find(|p| !p.is_finite()) {
                return Err(format!("profile segment {index} has a non-finite control point {point}"));
            }
            if let Some(point) = points.iter().find(|p| p.x < 0.0) {
                return Err(format!(
                    "profile segment {index} has control point {point} with x < 0; profiles must stay on one side of the axis"
                ));
            }
        }
        let linear = local_to_world.matrix3;
        if !linear.is_finite() || !local_to_world.translation.is_finite() {
            return Err("the transform of a surface of revolution must be finite".into());
        }
        // A similarity has MᵀM = k² I; only then are areas scaled by k².
        let gram = linear.transpose() * linear;
        let scale_squared = gram.x_axis.x;
        let off_identity = (gram - DMat3::from_diagonal(DVec3::splat(scale_squared))).abs();
        if scale_squared.is_nan()
            || scale_squared <= 0.0
            || off_identity.to_cols_array().iter().any(|&e| e > 1e-9 * scale_squared)
        {
            return Err("the transform of a surface of revolution must be a similarity (rotation, uniform scale, translation); bake other scales into the profile".into());
        }
        let world_to_local = local_to_world.inverse();

        let segments: Vec<Segment> = segments.into_iter().map(Segment::new).collect();
        let mut cap_list = Vec::new();
        if caps {
            let first = segments[0].points[0];
            let last_segment = &segments[segments.len() - 1];
            let last = last_segment.points[last_segment.points.len() - 1];
            for (point, side) in [(first, -1.0), (last, 1.0)] {
                if point.x > 0.0 {
                    cap_list.push(Cap {
                        z: point.y,
                        radius: point.x,
                        side,
                    });
                }
            }
        }
        let mut cumulative_area = Vec::with_capacity(segments.len() + cap_list.len());
        let mut total = 0.0;
        for area in segments.iter().map(Segment::area).chain(cap_list.iter().map(Cap::area)) {
            total += area;
            cumulative_area.push(total);
        }
        if total.is_nan() || total <= 0.0 {
            return Err("the profile sweeps no area (it lies on the axis or is a single point)".into());
        }
        let radius = segments.iter().fold(0.0_f64, |m, s| m.max(s.radius));
        let z_min = segments.iter().fold(f64::INFINITY, |m, s| m.min(s.z_min));
        let z_max = segments.iter().fold(f64::NEG_INFINITY, |m, s| m.max(s.z_max));
        // The scale of rounding errors is that of the coefficients, the
        // control points, which may reach beyond the curve.
        let size = segments
            .iter()
            .flat_map(|segment| &segment.points)
            .fold(0.0_f64, |m, p| m.max(p.x.abs()).max(p.y.abs()));
        Ok(Self {
            size,
            segments,
            caps: cap_list,
            local_to_world,
            world_to_local,
            normal_to_world: world_to_local.matrix3.transpose(),
            absolute_linear: linear.abs(),
            scale_factor: scale_squared.sqrt(),
            radius,
            z_min,
            z_max,
            cumulative_area,
        })
    }

    /// World-space bounds: the transformed box around the control points.
    pub fn bounds(&self) -> Aabb {
        let corners: Vec<DVec3> = (0..8)
            .map(|i| {
                let local = DVec3::new(
                    if i & 1 == 0 { -self.radius } else { self.radius },
                    if i & 2 == 0 { -self.radius } else { self.radius },
                    if i & 4 == 0 { self.z_min } else { self.z_max },
                );
                self.local_to_world.transform_point3(local)
            })
            .collect();
        Aabb::from_points(&corners)
    }

    /// World position and per-axis error bound of a local point whose own
    /// error bound is `local_error` (pbrt-v4 6.8.3: `|M| e + γ(3)(|M||p| + |t|)`).
    fn to_world_with_error(&self, local: DVec3, local_error: DVec3) -> (DVec3, DVec3) {
        let point = self.local_to_world.transform_point3(local);
        let rounding = gamma(3) * (self.absolute_linear * local.abs() + self.local_to_world.translation.abs());
        (point, self.absolute_linear * local_error + rounding)
    }
}

/// Unit local normal of the profile surface at parameter `t`, angle `φ`:
/// the 2-D normal `(y', −x')` rotated by `φ`, or `∓z` on the axis.
fn profile_normal(points: &[DVec2], t: f64, radius: f64, cos_phi: f64, sin_phi: f64) -> DVec3 {
    let tangent = bezier::tangent_direction(points, t).unwrap_or(DVec2::Y);
    let normal_2d = DVec2::new(tangent.y, -tangent.x);
    if radius <= 0.0 {
        // On the axis every φ gives the same point: only ±z is consistent.
        return DVec3::new(0.0, 0.0, if normal_2d.y < 0.0 { -1.0 } else { 1.0 });
    }
    DVec3::new(normal_2d.x * cos_phi, normal_2d.x * sin_phi, normal_2d.y).normalize()
}

/// Shapes the unit tests of this module's files share.
#[cfg(test)]
mod test_shapes {
    use super::*;

    /// A 5-point vase profile closed at the bottom on the axis (a pole).
    pub(super) fn vase() -> Revolution {
        let profile = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.2, 0.1),
            DVec2::new(0.3, 0.9),
            DVec2::new(0.9, 1.4),
            DVec2::new(0.5, 2.0),
        ];
        Revolution::new(vec![profile], false, DAffine3::IDENTITY).expect("valid vase")
    }

    /// The cylinder `r = 1`, `z ∈ [−1, 1]`, with or without end discs.
    pub(super) fn cylinder(caps: bool) -> Revolution {
        let profile = vec![DVec2::new(1.0, -1.0), DVec2::new(1.0, 1.0)];
        Revolution::new(vec![profile], caps, DAffine3::IDENTITY).expect("valid cylinder")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_invalid_profiles() {
        let identity = DAffine3::IDENTITY;
        assert!(Revolution::new(vec![], false, identity).is_err());
        assert!(Revolution::new(vec![vec![DVec2::ONE]], false, identity).is_err());
        assert!(Revolution::new(vec![vec![DVec2::ONE, DVec2::new(-1.0, 0.0)]], false, identity).is_err());
        assert!(Revolution::new(vec![vec![DVec2::ONE, DVec2::new(f64::NAN, 0.0)]], false, identity).is_err());
        assert!(Revolution::new(vec![vec![DVec2::ZERO, DVec2::Y]], false, identity).is_err());
        let squash = DAffine3::from_scale(DVec3::new(1.0, 2.0, 1.0));
        assert!(Revolution::new(vec![vec![DVec2::ONE, DVec2::X]], false, squash).is_err());
    }
}
