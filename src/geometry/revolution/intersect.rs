//! The nearest hit of a ray with a surface of revolution.
//!
//! The ray is taken into the rotated local frame (`LocalRay`); caps are
//! tried first (they are cheap, and a near cap hit prunes the profile), then
//! each segment inside whose bounding cylinder the ray passes, arc by arc,
//! in the order the ray enters their annuli (`segment_hits`). Only the
//! nearest hit matters, so
//! the search keeps the nearest verified hit so far and root isolation skips
//! every piece of the profile whose hits can only be farther
//! (`RayProfilePiece::nearest_parameter`). Together with stopping Newton once
//! the polynomial is below its rounding error, this halved the instructions
//! per ray (callgrind, `examples/revolution_cost.rs`).
//!
//! # Precision
//! Roots are polished to a few ulps of `t`, and every hit carries error
//! bounds built from `γ(n)` terms and the root's uncertainty; hits closer
//! than their own error bound are rejected, so a ray starting on the surface
//! does not find its own origin. Rays that pass within about `1e-15 ×` the
//! object's size of tangency may be reported as hit or miss.

use super::local_ray::LocalRay;
use super::profile::{Arc, Cap, Segment};
use super::{Revolution, profile_normal};
use crate::geometry::bezier;
use crate::geometry::hit::SurfaceHit;
use crate::math::{Ray, gamma};
use glam::{DVec2, DVec3};
use std::cell::Cell;
use std::f64::consts::TAU;

/// A candidate hit before the nearest one is chosen.
#[derive(Clone, Copy, Debug)]
pub(super) struct Candidate {
    /// Ray parameter (local and world alike).
    pub(super) s: f64,
    pub(super) surface: CandidateSurface,
}

/// Which part of the surface a candidate lies on, and where.
#[derive(Clone, Copy, Debug)]
pub(super) enum CandidateSurface {
    Profile { segment: usize, t: f64, t_uncertainty: f64 },
    Cap { cap: usize },
}

impl Revolution {
    /// The nearest intersection with `0 < t < t_max`, if any.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<SurfaceHit> {
        self.nearest(ray, t_max)
            .map(|(local, candidate)| self.surface_hit(&local, candidate))
    }

    /// The distance to that intersection, without its record: what a
    /// shadow ray needs. The record's angle, profile point, tangent, normal
    /// and error bounds (an `atan2`, a `sin_cos`, a distance from the axis and two Bézier
    /// evaluations) cost as much as a few pieces of root isolation.
    pub fn hit_distance(&self, ray: &Ray, t_max: f64) -> Option<f64> {
        self.nearest(ray, t_max).map(|(_, candidate)| candidate.s)
    }

    /// The nearest candidate with `0 < t < t_max`, and the ray in the local frame.
    fn nearest(&self, ray: &Ray, t_max: f64) -> Option<(LocalRay, Candidate)> {
        let local = LocalRay::new(
            self.world_to_local.transform_point3(ray.origin),
            self.world_to_local.transform_vector3(ray.direction),
        );
        if local.horizontal_speed == 0.0 && local.direction.z == 0.0 {
            return None;
        }
        // Cheap rejection by the bounding cylinder of the whole profile.
        let margin = 1e-9 * self.size;
        let (_, exit) = local.cylinder_span(self.radius * (1.0 + 1e-9) + margin, self.z_min - margin, self.z_max + margin)?;
        if exit < 0.0 {
            return None;
        }
        // `cutoff` is the nearest hit so far (or `t_max`): root isolation
        // drops the parts of the profile that can only hold farther hits.
        let cutoff = Cell::new(t_max);
        let mut best: Option<Candidate> = None;
        let mut consider = |candidate: Candidate| {
            if candidate.s < cutoff.get() {
                best = Some(candidate);
                cutoff.set(candidate.s);
            }
        };
        // Caps first: they are cheap, and a near cap hit prunes the profile.
        for (index, cap) in self.caps.iter().enumerate() {
            if let Some(s) = cap.intersect(&local) {
                consider(Candidate {
                    s,
                    surface: CandidateSurface::Cap { cap: index },
                });
            }
        }
        for (index, segment) in self.segments.iter().enumerate() {
            let Some((entry, exit)) = segment.span(&local, margin) else {
                continue;
            };
            if exit < 0.0 || entry >= cutoff.get() {
                continue;
            }
            segment.intersect(&local, index, self.size, (entry, exit), &cutoff, &mut consider);
        }
        best.map(|candidate| (local, candidate))
    }

    /// Builds the reported hit for the chosen candidate.
    fn surface_hit(&self, ray: &LocalRay, candidate: Candidate) -> SurfaceHit {
        let on_ray = ray.origin + candidate.s * ray.direction;
        let radial = super::axis_distance(on_ray.x, on_ray.y);
        let phi = if radial > 0.0 {
            on_ray.y.atan2(on_ray.x).rem_euclid(TAU)
        } else {
            0.0
        };
        let (sin_phi, cos_phi) = phi.sin_cos();
        let (local_point, local_normal, v, local_error) = match candidate.surface {
            CandidateSurface::Profile {
                segment,
                t,
                t_uncertainty,
            } => {
                let curve = &self.segments[segment];
                let (point, derivative) = bezier::evaluate_with_derivative(&curve.points, t);
                let tangent = bezier::tangent_direction(&curve.points, t).unwrap_or(DVec2::Y);
                // Project the ray point, in the (r, z) plane, onto the
                // profile's tangent line at t: removes the error normal to the
                // surface, to first order.
                let normal_2d = DVec2::new(tangent.y, -tangent.x);
                let offset = DVec2::new(radial, on_ray.z) - point;
                let projected = DVec2::new(radial, on_ray.z) - offset.dot(normal_2d) * normal_2d;
                let r = projected.x.max(0.0);
                let local = DVec3::new(r * cos_phi, r * sin_phi, projected.y);
                let normal = profile_normal(&curve.points, t, point.x.min(r), cos_phi, sin_phi);
                let error = gamma(4 * curve.degree as u32 + 16) * (self.size + r + projected.y.abs())
                    + derivative.length() * t_uncertainty
                    + gamma(8) * (ray.origin.abs().max_element() + (candidate.s * ray.direction).abs().max_element());
                let v = (segment as f64 + t) / self.segments.len() as f64;
                (local, normal, v, error)
            }
            CandidateSurface::Cap { cap } => {
                let cap = self.caps[cap];
                let local = DVec3::new(on_ray.x, on_ray.y, cap.z);
                let error =
                    gamma(8) * (radial + ray.origin.abs().max_element() + (candidate.s * ray.direction).abs().max_element());
                (
                    local,
                    DVec3::new(0.0, 0.0, cap.side),
                    if cap.side < 0.0 { 0.0 } else { 1.0 },
                    error,
                )
            }
        };
        let (point, point_error) = self.to_world_with_error(local_point, DVec3::splat(local_error));
        let normal = (self.normal_to_world * local_normal).normalize();
        SurfaceHit {
            t: candidate.s,
            point,
            point_error,
            geometric_normal: normal,
            shading_normal: normal,
            uv: DVec2::new(phi / TAU, v),
        }
    }
}

impl Cap {
    /// Ray parameter of the hit with the disc, if beyond its error bound.
    pub(super) fn intersect(&self, ray: &LocalRay) -> Option<f64> {
        let dz = ray.direction.z;
        if dz == 0.0 {
            return None;
        }
        let s = (self.z - ray.origin.z) / dz;
        let s_error = 2.0 * gamma(3) * (self.z.abs() + ray.origin.z.abs()) / dz.abs();
        let point = ray.origin + s * ray.direction;
        (s > s_error && super::axis_distance(point.x, point.y) <= self.radius).then_some(s)
    }
}

impl Arc {
    /// A lower bound on the ray parameters `s ≥ 0` at which the ray is
    /// inside this arc's annulus, or `None` if it never is there.
    pub(super) fn entry(&self, ray: &LocalRay, margin: f64) -> Option<f64> {
        let (entry, exit) = ray.cylinder_span(self.radius * (1.0 + 1e-9) + margin, self.z_min - margin, self.z_max + margin)?;
        if exit < 0.0 {
            return None;
        }
        // The squared distance to the axis, `(o + s h)² + δ²`, is convex in
        // `s`: if it is below the inner radius at both ends of the span, it
        // is below it throughout, and the ray passes through the hole.
        let inner = self.inner_radius * (1.0 - 1e-9) - margin;
        if inner > 0.0 {
            let across = ray.across.abs();
            let inside_hole = |s: f64| {
                let along = ray.along + s * ray.horizontal_speed;
                // Rounding of the square, and of `o` and `δ` (`frame_error`).
                let extent = ray.along.abs() + (s * ray.horizontal_speed).abs() + across;
                let slack = gamma(8) * extent * extent + 3.0 * extent * ray.frame_error;
                along * along + across * across + slack < inner * inner
            };
            if inside_hole(entry.max(0.0)) && inside_hole(exit) {
                return None;
            }
        }
        Some(entry)
    }
}

impl Segment {
    /// The range of ray parameters inside this segment's bounding cylinder.
    fn span(&self, ray: &LocalRay, margin: f64) -> Option<(f64, f64)> {
        ray.cylinder_span(self.radius * (1.0 + 1e-9) + margin, self.z_min - margin, self.z_max + margin)
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_shapes::{cylinder, vase};
    use super::*;

    #[test]
    fn cylinder_hits_from_outside_inside_and_along_the_axis() {
        let shape = cylinder(false);
        let hit = shape
            .intersect(&Ray::new(DVec3::new(-3.0, 0.0, 0.5), DVec3::X), f64::INFINITY)
            .expect("hit");
        assert!((hit.t - 2.0).abs() < 1e-14);
        assert!((hit.geometric_normal - -DVec3::X).length() < 1e-14);
        let inside = shape
            .intersect(&Ray::new(DVec3::new(0.0, 0.0, 0.5), DVec3::Y), f64::INFINITY)
            .expect("hit");
        assert!((inside.t - 1.0).abs() < 1e-14 && (inside.geometric_normal - DVec3::Y).length() < 1e-14);
        // An open tube has nothing on its axis; with caps the axis ray hits the end disc.
        assert!(
            shape
                .intersect(&Ray::new(DVec3::new(0.0, 0.0, -5.0), DVec3::Z), f64::INFINITY)
                .is_none()
        );
        let capped = cylinder(true).intersect(&Ray::new(DVec3::new(0.0, 0.0, -5.0), DVec3::Z), f64::INFINITY);
        let capped = capped.expect("cap hit");
        assert!((capped.t - 4.0).abs() < 1e-14 && (capped.geometric_normal - -DVec3::Z).length() < 1e-14);
    }

    #[test]
    fn horizontal_rays_hit_like_their_tilted_neighbours() {
        let shape = vase();
        for dz in [0.0, 1e-12, -1e-12, 1e-16] {
            let ray = Ray::new(DVec3::new(-5.0, 0.2, 1.0), DVec3::new(1.0, 0.0, dz));
            let hit = shape.intersect(&ray, f64::INFINITY).expect("horizontal hit");
            let reference = shape.intersect(&Ray::new(DVec3::new(-5.0, 0.2, 1.0), DVec3::X), f64::INFINITY);
            assert!((hit.t - reference.expect("hit").t).abs() < 1e-9, "dz = {dz}");
        }
    }

    #[test]
    fn axis_ray_hits_the_pole_with_a_vertical_normal() {
        let shape = vase();
        let hit = shape
            .intersect(&Ray::new(DVec3::new(0.0, 0.0, -3.0), DVec3::Z), f64::INFINITY)
            .expect("pole");
        assert!((hit.t - 3.0).abs() < 1e-12, "{}", hit.t);
        assert_eq!(hit.geometric_normal, -DVec3::Z);
        // From inside, the pole is hit from above with the same outward normal.
        let inside = shape
            .intersect(&Ray::new(DVec3::new(0.0, 0.0, 0.5), -DVec3::Z), f64::INFINITY)
            .expect("pole");
        assert!((inside.t - 0.5).abs() < 1e-12 && inside.geometric_normal == -DVec3::Z);
    }

    #[test]
    fn hits_lie_on_the_surface_and_spawned_rays_leave_it() {
        let shape = vase();
        let mut hits = 0;
        for i in 0..400 {
            let angle = i as f64 * 0.7;
            let origin = DVec3::new(4.0 * angle.cos(), 4.0 * angle.sin(), 0.005 * i as f64);
            let target = DVec3::new(0.1 * (i % 7) as f64, 0.0, 0.3 + 0.003 * i as f64);
            let Some(hit) = shape.intersect(&Ray::new(origin, target - origin), f64::INFINITY) else {
                continue;
            };
            hits += 1;
            // Re-intersecting from the offset point never finds the same point.
            for direction in [hit.geometric_normal, -hit.geometric_normal, target - origin] {
                let spawned = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, direction);
                if let Some(again) = shape.intersect(&spawned, f64::INFINITY) {
                    assert!(again.t > 1e-9, "self-intersection at {} (ray {i})", again.t);
                }
            }
        }
        assert!(hits > 300);
    }
}
