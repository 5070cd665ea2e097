//! Rays and the floating-point-aware origin offset that keeps a spawned ray
//! from re-hitting the surface it leaves (pbrt-v4, section 6.8.6).

use glam::DVec3;
use wide::{CmpGt, CmpLt, f64x4, u64x4};

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
    // Always inlined, like `offset_ray_origin`: out of line, its vectors
    // went through memory (see there).
    #[inline(always)]
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
/// result away from the surface so the offset survives the addition
/// (pbrt-v4 6.8.6).
///
/// The same values as stepping each coordinate with `next_up` where its
/// offset is positive and `next_down` where it is negative, but without
/// their branches: which side a spawned ray leaves on, and which way each
/// coordinate steps, are coin tosses per ray that mispredicted 0.86 times
/// per call on the Cornell box. The three coordinates go through together
/// in SIMD lanes; done one by one in scalar code the bit operations cost
/// more than the mispredictions saved.
///
/// Always inlined: called out of line it received its vectors through
/// memory, and reading the normal's y and z as one 16-byte pair, which
/// the caller had written as two smaller stores, waited for those stores
/// to reach the cache (a load spanning two stores cannot be forwarded from
/// the store buffer): a third of its time on an AMD EPYC (docs/performance.md).
#[inline(always)]
pub fn offset_ray_origin(point: DVec3, point_error: DVec3, normal: DVec3, direction: DVec3) -> DVec3 {
    let distance = normal.abs().dot(point_error);
    // Negating a float flips its sign bit: a mask of that bit negates the
    // offset when the direction leaves on the side opposite the normal.
    let negate = u64::from(direction.dot(normal) < 0.0) << 63;
    let offset = distance * normal;
    // The three coordinates side by side (a fourth lane idles at 0).
    let offset = bytemuck::cast::<u64x4, f64x4>(
        u64x4::new([offset.x.to_bits(), offset.y.to_bits(), offset.z.to_bits(), 0]) ^ u64x4::new([negate, negate, negate, 0]),
    );
    let origin = f64x4::new([point.x, point.y, point.z, 0.0]) + offset;
    // One ulp further in the direction of the offset's sign: up is one more
    // in the magnitude's bits for a positive number, one less for a negative
    // one, and down the reverse, so the step is +1 exactly when the signs
    // agree. Coordinates whose offset is zero (or NaN) do not move.
    let (origin_bits, offset_bits) = (bytemuck::cast::<f64x4, u64x4>(origin), bytemuck::cast::<f64x4, u64x4>(offset));
    let sign_differs = (origin_bits ^ offset_bits) >> 63;
    let step = u64x4::splat(1) - (sign_differs << 1);
    let moving = offset.abs().cmp_gt(f64x4::ZERO);
    let moves: u64x4 = bytemuck::cast(moving);
    let stepped: u64x4 = origin_bits + (step & moves);
    // Zero and non-finite coordinates step differently (from ±0 to the
    // smallest subnormal of the offset's sign; infinities and NaN stay).
    // A moving coordinate is zero only when the sum cancels exactly, and
    // non-finite only for non-finite input: they take the library's way.
    let magnitude = origin.abs();
    let ordinary = magnitude.cmp_gt(f64x4::ZERO) & magnitude.cmp_lt(f64x4::splat(f64::INFINITY));
    if (moving & !ordinary).any() {
        let [x, y, z, _] = origin.to_array();
        let [dx, dy, dz, _] = offset.to_array();
        return DVec3::new(step_by_library(x, dx), step_by_library(y, dy), step_by_library(z, dz));
    }
    let [x, y, z, _] = stepped.to_array();
    DVec3::new(f64::from_bits(x), f64::from_bits(y), f64::from_bits(z))
}

/// One coordinate's step, by the library's `next_up` and `next_down`.
fn step_by_library(coordinate: f64, offset: f64) -> f64 {
    if offset > 0.0 {
        coordinate.next_up()
    } else if offset < 0.0 {
        coordinate.next_down()
    } else {
        coordinate
    }
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

    /// The definition: step each coordinate with the library's `next_up`
    /// or `next_down` by its offset's sign, after negating the offset when
    /// the direction leaves on the normal's far side.
    fn offset_by_definition(point: DVec3, point_error: DVec3, normal: DVec3, direction: DVec3) -> DVec3 {
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

    #[test]
    fn offsets_step_exactly_as_next_up_and_next_down() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || crate::math::xorshift64(&mut state);
        // Coordinates of every sign and size, exact zeros, and the values
        // whose steps are special (the smallest subnormals, the largest
        // finite numbers, infinities).
        let special = [0.0, -0.0, 5e-324, -5e-324, f64::MAX, -f64::MAX, f64::INFINITY, 1.0, -1.0];
        let coordinate = |next: &mut dyn FnMut() -> u64| {
            let r = next();
            match r % 8 {
                0 => special[(r >> 8) as usize % special.len()],
                1 => ((r >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 1e-300,
                _ => ((r >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2f64.powi((r >> 3) as i32 % 40 - 10),
            }
        };
        for _ in 0..300_000 {
            let point = DVec3::new(coordinate(&mut next), coordinate(&mut next), coordinate(&mut next));
            let error = DVec3::new(coordinate(&mut next), coordinate(&mut next), coordinate(&mut next)).abs() * 1e-6;
            // Normals along an axis (two zero components, of either sign) or general.
            let r = next();
            let normal = if r % 3 == 0 {
                let mut n = DVec3::ZERO;
                n[(r >> 8) as usize % 3] = if r & 16 == 0 { 1.0 } else { -1.0 };
                n * if r & 32 == 0 { 1.0 } else { -1.0 }
            } else {
                DVec3::new(coordinate(&mut next), coordinate(&mut next), coordinate(&mut next))
            };
            let direction = DVec3::new(coordinate(&mut next), coordinate(&mut next), coordinate(&mut next));
            let fast = offset_ray_origin(point, error, normal, direction);
            let exact = offset_by_definition(point, error, normal, direction);
            for axis in 0..3 {
                assert!(
                    fast[axis].to_bits() == exact[axis].to_bits() || (fast[axis].is_nan() && exact[axis].is_nan()),
                    "axis {axis}: {fast} against {exact} for {point} {error} {normal} {direction}"
                );
            }
        }
    }

    #[test]
    fn gamma_is_small_and_increasing() {
        assert!(gamma(1) > 0.0 && gamma(1) < gamma(2) && gamma(7) < 1e-14);
    }
}
