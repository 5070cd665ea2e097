//! Axis-aligned bounding boxes and the slab test used by the BVH.

use super::ray::gamma;
use glam::DVec3;

/// An axis-aligned box; `Aabb::EMPTY` is the identity for `union`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner (per-axis minimum); `+∞` on every axis for the empty box.
    pub min: DVec3,
    /// Upper corner (per-axis maximum); `-∞` on every axis for the empty box.
    pub max: DVec3,
}

impl Default for Aabb {
    /// The empty box.
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The box containing nothing (`min = +∞`, `max = -∞`), the identity of
    /// `union`.
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    /// The box spanned by two opposite corners, given in any order.
    pub fn new(a: DVec3, b: DVec3) -> Self {
        Self {
            min: a.min(b),
            max: a.max(b),
        }
    }

    /// The smallest box containing every point (`EMPTY` for no points).
    pub fn from_points(points: &[DVec3]) -> Self {
        points.iter().fold(Self::EMPTY, |b, &p| b.include(p))
    }

    /// This box grown just enough to contain `p`.
    pub fn include(self, p: DVec3) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The smallest box containing both boxes.
    pub fn union(self, other: Aabb) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// True when some axis has `min > max`, as for `EMPTY`; a box of zero
    /// width (a point or a flat quad's bounds) is not empty.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// Side lengths `max - min`; zero (not negative or NaN) for an empty box.
    pub fn extent(&self) -> DVec3 {
        if self.is_empty() { DVec3::ZERO } else { self.max - self.min }
    }

    /// The box's centre; the BVH builder bins primitives by their bounds'
    /// centroids.
    pub fn centroid(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// Surface area, the cost measure of the surface area heuristic.
    pub fn surface_area(&self) -> f64 {
        let d = self.extent();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Index of the longest axis.
    pub fn largest_axis(&self) -> usize {
        let d = self.extent();
        if d.x >= d.y && d.x >= d.z {
            0
        } else if d.y >= d.z {
            1
        } else {
            2
        }
    }

    /// Position of `p` relative to the box, 0 at `min` and 1 at `max`.
    pub fn offset(&self, p: DVec3) -> DVec3 {
        let d = self.extent();
        let mut o = p - self.min;
        for axis in 0..3 {
            o[axis] = if d[axis] > 0.0 { o[axis] / d[axis] } else { 0.0 };
        }
        o
    }

    /// Slab test against `[0, t_max]`. `inverse_direction` is `1 / direction`
    /// per component. The far distance is enlarged by `1 + 2γ(3)` so a ray
    /// that grazes a box edge is never culled by rounding (pbrt-v4 6.1.2).
    /// A direction component of ±0 (infinite inverse) means the ray runs
    /// parallel to that slab: it is inside for all t or for none, decided by
    /// the origin alone (multiplying would give 0 · ∞ = NaN for a ray in the
    /// slab's plane). Plain comparisons rather than `f64::min`/`max`: one
    /// instruction each.
    #[inline]
    pub fn hit_distance(&self, origin: DVec3, inverse_direction: DVec3, t_max: f64) -> Option<f64> {
        let mut enter = 0.0;
        let mut exit = t_max;
        for axis in 0..3 {
            if inverse_direction[axis].is_infinite() {
                if origin[axis] < self.min[axis] || origin[axis] > self.max[axis] {
                    return None;
                }
                continue;
            }
            let a = (self.min[axis] - origin[axis]) * inverse_direction[axis];
            let b = (self.max[axis] - origin[axis]) * inverse_direction[axis];
            let (near, far) = if a > b { (b, a) } else { (a, b) };
            let far = far * (1.0 + 2.0 * gamma(3));
            if near > enter {
                enter = near;
            }
            if far < exit {
                exit = far;
            }
            if enter > exit {
                return None;
            }
        }
        Some(enter)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_test_hits_and_misses() {
        let b = Aabb::new(DVec3::splat(-1.0), DVec3::splat(1.0));
        let inv = |d: DVec3| DVec3::ONE / d;
        let hit = b.hit_distance(DVec3::new(-3.0, 0.0, 0.0), inv(DVec3::X), f64::INFINITY);
        assert_eq!(hit, Some(2.0));
        let miss = b.hit_distance(DVec3::new(-3.0, 2.0, 0.0), inv(DVec3::X), f64::INFINITY);
        assert_eq!(miss, None);
        let inside = b.hit_distance(DVec3::ZERO, inv(DVec3::new(1.0, 1.0, 0.0).normalize()), 10.0);
        assert_eq!(inside, Some(0.0));
        // Grazing along a face plane still counts as touching the box, also
        // with a negative-zero direction component (1 / -0 = -∞, 0 · ∞ = NaN).
        let grazing = b.hit_distance(DVec3::new(-3.0, 1.0, 0.0), inv(DVec3::X), 10.0);
        assert!(grazing.is_some());
        let negative_zero = b.hit_distance(DVec3::new(-3.0, 1.0, 0.0), inv(DVec3::new(1.0, -0.0, 0.0)), 10.0);
        assert_eq!(negative_zero, Some(2.0));
        let outside = b.hit_distance(DVec3::new(-3.0, 1.0 + 1e-12, 0.0), inv(DVec3::new(1.0, -0.0, 0.0)), 10.0);
        assert_eq!(outside, None);
    }

    #[test]
    fn surface_area_of_unit_cube() {
        let b = Aabb::new(DVec3::ZERO, DVec3::ONE);
        assert_eq!(b.surface_area(), 6.0);
        assert_eq!(Aabb::EMPTY.surface_area(), 0.0);
    }
}
