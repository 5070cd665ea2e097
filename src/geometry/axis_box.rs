//! Axis-aligned boxes as solid objects (six faces), intersected by the slab
//! method with the exit face reported for rays that start inside.

use super::hit::{AreaSample, SurfaceHit};
use crate::math::{Aabb, Ray, gamma};
use glam::{DVec2, DVec3};

/// A solid axis-aligned box in world space: normals point out of the
/// box, uv runs 0..1 across each face.
#[derive(Clone, Copy, Debug)]
pub struct AxisBox {
    /// The box's extent in world space.
    pub bounds: Aabb,
}

impl AxisBox {
    /// Total area of the six faces.
    pub fn area(&self) -> f64 {
        self.bounds.surface_area()
    }

    /// Nearest hit in `(0, t_max)`: the entry face, or the exit face when the
    /// ray starts inside. The hit coordinate is snapped onto the face plane,
    /// so its error bound is zero along that axis.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<SurfaceHit> {
        let (axis, t) = self.solve(ray, t_max)?;
        Some(self.surface_hit(ray, axis, t))
    }

    /// The hit record at distance `t` on a face normal to `axis` (as
    /// [`AxisBox::solve`] found them).
    #[inline]
    pub fn surface_hit(&self, ray: &Ray, axis: usize, t: f64) -> SurfaceHit {
        let mut point = ray.at(t);
        // Snap the coordinate of the face that was hit onto the face plane.
        let center = self.bounds.centroid();
        let positive = point[axis] > center[axis];
        point[axis] = if positive {
            self.bounds.max[axis]
        } else {
            self.bounds.min[axis]
        };
        let mut normal = DVec3::ZERO;
        normal[axis] = if positive { 1.0 } else { -1.0 };
        let mut point_error = gamma(3) * (ray.origin.abs() + (t * ray.direction).abs());
        point_error[axis] = 0.0;
        SurfaceHit {
            t,
            point,
            point_error,
            geometric_normal: normal,
            shading_normal: normal,
            uv: self.face_uv(point, axis),
        }
    }

    /// Distance to the hit before `t_max`, without its record (shadow rays).
    #[inline(always)]
    pub fn hit_distance(&self, ray: &Ray, t_max: f64) -> Option<f64> {
        self.solve(ray, t_max).map(|(_, t)| t)
    }

    /// The slab test (Kay & Kajiya 1986): the axis of the face hit and the
    /// distance to it; the exit face when the origin is inside.
    #[inline(always)]
    pub fn solve(&self, ray: &Ray, t_max: f64) -> Option<(usize, f64)> {
        let inverse = DVec3::ONE / ray.direction;
        let t0 = (self.bounds.min - ray.origin) * inverse;
        let t1 = (self.bounds.max - ray.origin) * inverse;
        let near = t0.min(t1);
        let far = t0.max(t1);
        let (enter_axis, enter) = max_with_axis(near);
        let (exit_axis, exit) = min_with_axis(far);
        if enter > exit {
            return None;
        }
        if enter > 0.0 && enter < t_max {
            Some((enter_axis, enter))
        } else if exit > 0.0 && exit < t_max && enter <= 0.0 {
            Some((exit_axis, exit))
        } else {
            None
        }
    }

    fn face_uv(&self, point: DVec3, axis: usize) -> DVec2 {
        let o = self.bounds.offset(point);
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        DVec2::new(o[a], o[b])
    }

    /// Uniform point over the six faces; density `1 / area`.
    pub fn sample_area(&self, u: DVec2) -> AreaSample {
        let d = self.bounds.extent();
        let face_areas = [d.y * d.z, d.y * d.z, d.z * d.x, d.z * d.x, d.x * d.y, d.x * d.y];
        let total: f64 = face_areas.iter().sum();
        let mut pick = u.x * total;
        let mut face = 5;
        for (i, a) in face_areas.iter().enumerate() {
            if pick < *a {
                face = i;
                break;
            }
            pick -= a;
        }
        let reused = (pick / face_areas[face]).clamp(0.0, 1.0);
        let axis = face / 2;
        let positive = face % 2 == 1;
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut point = DVec3::ZERO;
        point[axis] = if positive {
            self.bounds.max[axis]
        } else {
            self.bounds.min[axis]
        };
        point[a] = self.bounds.min[a] + reused * d[a];
        point[b] = self.bounds.min[b] + u.y * d[b];
        let mut normal = DVec3::ZERO;
        normal[axis] = if positive { 1.0 } else { -1.0 };
        AreaSample {
            point,
            point_error: gamma(3) * point.abs(),
            normal,
        }
    }
}

fn max_with_axis(v: DVec3) -> (usize, f64) {
    let mut best = (0, v.x);
    for axis in 1..3 {
        if v[axis] > best.1 || best.1.is_nan() {
            best = (axis, v[axis]);
        }
    }
    best
}

fn min_with_axis(v: DVec3) -> (usize, f64) {
    let mut best = (0, v.x);
    for axis in 1..3 {
        if v[axis] < best.1 || best.1.is_nan() {
            best = (axis, v[axis]);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box() -> AxisBox {
        AxisBox {
            bounds: Aabb::new(DVec3::splat(-1.0), DVec3::splat(1.0)),
        }
    }

    #[test]
    fn hits_faces_from_outside_and_inside() {
        let b = unit_box();
        let hit = b.intersect(&Ray::new(DVec3::new(0.2, 0.3, 5.0), -DVec3::Z), f64::INFINITY);
        let hit = hit.map(|h| (h.t, h.geometric_normal));
        assert!(matches!(hit, Some((t, n)) if (t - 4.0).abs() < 1e-12 && n == DVec3::Z));
        let inside = b.intersect(&Ray::new(DVec3::ZERO, DVec3::X), f64::INFINITY);
        let inside = inside.map(|h| (h.t, h.geometric_normal));
        assert!(matches!(inside, Some((t, n)) if (t - 1.0).abs() < 1e-12 && n == DVec3::X));
        let miss = b.intersect(&Ray::new(DVec3::new(0.0, 2.0, 5.0), -DVec3::Z), f64::INFINITY);
        assert!(miss.is_none());
    }
}
