//! Parallelograms `corner + a·edge_u + b·edge_v`, a, b in [0, 1]: the usual
//! rectangular area light and the walls of a Cornell box.

use super::hit::{AreaSample, SurfaceHit};
use crate::math::{Aabb, Ray, gamma};
use glam::{DVec2, DVec3};

/// A parallelogram `corner + a·edge_u + b·edge_v`, a, b in [0, 1]. It is
/// one-sided only for emission (see `normal`); rays hit both sides, and uv
/// is (a, b).
#[derive(Clone, Copy, Debug)]
pub struct Quad {
    /// The corner where a = b = 0, world space.
    pub corner: DVec3,
    /// The side along which `a` (and u) grows.
    pub edge_u: DVec3,
    /// The side along which `b` (and v) grows.
    pub edge_v: DVec3,
    /// Unit normal `edge_u × edge_v`: the emitting side of a quad light.
    pub normal: DVec3,
    /// `|edge_u × edge_v|`, kept because every light sample's density needs it.
    area: f64,
}

impl Quad {
    /// The parallelogram with the given corner and sides, its normal
    /// `edge_u × edge_v` normalised (so the edges must not be parallel).
    pub fn new(corner: DVec3, edge_u: DVec3, edge_v: DVec3) -> Self {
        Self {
            corner,
            edge_u,
            edge_v,
            normal: edge_u.cross(edge_v).normalize(),
            area: edge_u.cross(edge_v).length(),
        }
    }

    /// World-space bounds of the four corners.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(&[
            self.corner,
            self.corner + self.edge_u,
            self.corner + self.edge_v,
            self.corner + self.edge_u + self.edge_v,
        ])
    }

    /// Area `|edge_u × edge_v|`.
    pub fn area(&self) -> f64 {
        self.area
    }

    /// Plane hit, then the parallelogram coordinates by Cramer's rule.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<SurfaceHit> {
        let (t, a, b) = self.solve(ray, t_max)?;
        Some(self.surface_hit(t, a, b))
    }

    /// The hit record at distance `t` and coordinates `a`, `b` (as
    /// [`Quad::solve`] found them).
    #[inline]
    pub fn surface_hit(&self, t: f64, a: f64, b: f64) -> SurfaceHit {
        let point = self.corner + a * self.edge_u + b * self.edge_v;
        let point_error = gamma(6) * (self.corner.abs() + (a * self.edge_u).abs() + (b * self.edge_v).abs());
        SurfaceHit {
            t,
            point,
            point_error,
            geometric_normal: self.normal,
            shading_normal: self.normal,
            uv: DVec2::new(a, b),
        }
    }

    /// Distance to the hit before `t_max`, without its record (shadow rays).
    #[inline(always)]
    pub fn hit_distance(&self, ray: &Ray, t_max: f64) -> Option<f64> {
        self.solve(ray, t_max).map(|(t, _, _)| t)
    }

    /// The ray parameter and the hit's coordinates along the two edges
    /// (Möller & Trumbore 1997, with the second barycentric test made a
    /// parallelogram's: both coordinates in [0, 1]). Inlined into the BVH's
    /// leaf loop, where a call per candidate would cost as much as the test.
    #[inline(always)]
    pub fn solve(&self, ray: &Ray, t_max: f64) -> Option<(f64, f64, f64)> {
        let p = ray.direction.cross(self.edge_v);
        let det = self.edge_u.dot(p);
        if det == 0.0 {
            return None;
        }
        let inverse_det = 1.0 / det;
        let s = ray.origin - self.corner;
        let a = s.dot(p) * inverse_det;
        if !(0.0..=1.0).contains(&a) {
            return None;
        }
        let q = s.cross(self.edge_u);
        let b = ray.direction.dot(q) * inverse_det;
        if !(0.0..=1.0).contains(&b) {
            return None;
        }
        let t = self.edge_v.dot(q) * inverse_det;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        Some((t, a, b))
    }

    /// Uniform point; density `1 / area`.
    #[inline]
    pub fn sample_area(&self, u: DVec2) -> AreaSample {
        let point = self.corner + u.x * self.edge_u + u.y * self.edge_v;
        AreaSample {
            point,
            point_error: gamma(6) * (self.corner.abs() + (u.x * self.edge_u).abs() + (u.y * self.edge_v).abs()),
            normal: self.normal,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_inside_misses_outside_and_parallel() {
        let q = Quad::new(DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.0, 0.0, 1.0));
        assert_eq!(q.normal, DVec3::new(0.0, -1.0, 0.0));
        let hit = q.intersect(&Ray::new(DVec3::new(1.0, 3.0, 0.5), -DVec3::Y), f64::INFINITY);
        let hit = hit.map(|h| (h.t, h.uv));
        assert!(matches!(hit, Some((t, uv)) if (t - 3.0).abs() < 1e-12 && (uv - DVec2::new(0.5, 0.5)).length() < 1e-12));
        assert!(
            q.intersect(&Ray::new(DVec3::new(3.0, 3.0, 0.5), -DVec3::Y), f64::INFINITY)
                .is_none()
        );
        assert!(
            q.intersect(&Ray::new(DVec3::new(1.0, 0.0, -1.0), DVec3::Z), f64::INFINITY)
                .is_none()
        );
        assert!((q.area() - 2.0).abs() < 1e-12);
    }
}
