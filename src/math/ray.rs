//! Rays and the floating-point-aware origin offset that keeps a spawned ray
//! from re-hitting the surface it leaves (pbrt-v4, section 6.8.6).

use glam::DVec3;

/// A ray `origin + t * direction`, `t > 0`. The direction is unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts (world space); for a spawned ray already offset off
    /// the surface, so intersection tests accept any `t > 0`.
    pub origin: DVec3,
    /// Unit-length direction, so `t` measures distance in scene units.
    pub direction: DVec3,
}

impl Ray {
    /// A ray from `origin` along `direction` (normalised here).
    pub fn new(origin: DVec3, direction: DVec3) -> Self {
        Self {
            origin,
            direction: direction.normalize(),
        }
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + t * self.direction
    }

    /// A ray leaving a surface point whose position carries the absolute
    /// error bound `point_error`, offset along the normal so that it cannot
    /// hit the same surface again.
    pub fn spawn(point: DVec3, point_error: DVec3, normal: DVec3, direction: DVec3) -> Self {
        Self {
            origin: offset_ray_origin(point, point_error, normal, direction),
            direction: direction.normalize(),
        }
    }
}

/// Bound on the relative error of `n` floating-point operations,
/// `n ε / (1 - n ε)` with ε half the machine epsilon (Higham 2002; pbrt-v4 6.8.1).
pub const fn gamma(n: u32) -> f64 {
    let e = f64::EPSILON * 0.5 * n as f64;
    e / (1.0 - e)
}

/// Moves `point` off its surface along `normal`, towards the side `direction`
/// leaves on, by just more than the point's error bound, then rounds the
/// result away from the surface so the offset survives the addition.
pub fn offset_ray_origin(point: DVec3, point_error: DVec3, normal: DVec3, direction: DVec3) -> DVec3 {
    let distance = normal.abs().dot(point_error);
    let mut offset = distance * normal;
    if direction.dot(normal) < 0.0 {
        offset = -offset;
    }
    let mut origin = point + offset;
    for axis in 0..3 {
        if offset[axis] > 0.0 {
            origin[axis] = origin[axis].next_up();
        } else if offset[axis] < 0.0 {
            origin[axis] = origin[axis].next_down();
        }
    }
    origin
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_moves_to_the_side_of_the_direction() {
        let p = DVec3::new(1e5, 2.0, -3.0);
        let err = p.abs() * gamma(5);
        let n = DVec3::X;
        let out = offset_ray_origin(p, err, n, DVec3::new(1.0, 0.0, 0.0));
        let inward = offset_ray_origin(p, err, n, DVec3::new(-1.0, 0.0, 0.0));
        assert!(out.x > p.x + err.x * 0.99);
        assert!(inward.x < p.x - err.x * 0.99);
    }

    #[test]
    fn gamma_is_small_and_increasing() {
        assert!(gamma(1) > 0.0 && gamma(1) < gamma(2) && gamma(7) < 1e-14);
    }
}
