//! Single-precision boxes for the BVH, rounded outward from the exact
//! double-precision bounds of what they hold, so that a box test can only
//! accept more than the exact test would (Ize 2013, "Robust BVH ray
//! traversal"; pbrt-v4 §6.8.2).

use crate::math::Aabb;

/// An axis-aligned box in `f32`; `EMPTY` is the identity of `union`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds32 {
    /// Lower corner, rounded towards −∞ from the exact bound.
    pub min: [f32; 3],
    /// Upper corner, rounded towards +∞ from the exact bound.
    pub max: [f32; 3],
}

impl Bounds32 {
    /// The box containing nothing (`min = +∞`, `max = −∞`).
    pub const EMPTY: Bounds32 = Bounds32 {
        min: [f32::INFINITY; 3],
        max: [f32::NEG_INFINITY; 3],
    };

    /// The smallest `f32` box containing `aabb`.
    pub fn enclosing(aabb: &Aabb) -> Self {
        Self {
            min: std::array::from_fn(|axis| round_down(aabb.min[axis])),
            max: std::array::from_fn(|axis| round_up(aabb.max[axis])),
        }
    }

    /// The smallest box containing both.
    #[inline]
    pub fn union(&self, other: &Bounds32) -> Self {
        Self {
            min: std::array::from_fn(|axis| pick_min(self.min[axis], other.min[axis])),
            max: std::array::from_fn(|axis| pick_max(self.max[axis], other.max[axis])),
        }
    }

    /// The smallest box containing this one and `point`.
    #[inline]
    pub fn include(&self, point: [f32; 3]) -> Self {
        Self {
            min: std::array::from_fn(|axis| pick_min(self.min[axis], point[axis])),
            max: std::array::from_fn(|axis| pick_max(self.max[axis], point[axis])),
        }
    }

    /// max − min per axis (negative for an empty box).
    pub fn extent(&self) -> [f32; 3] {
        std::array::from_fn(|axis| self.max[axis] - self.min[axis])
    }

    /// Half the surface area: the SAH only compares areas.
    #[inline]
    pub fn half_area(&self) -> f32 {
        let [x, y, z] = self.extent();
        if x < 0.0 || y < 0.0 || z < 0.0 {
            return 0.0;
        }
        x * y + y * z + z * x
    }

    /// Whether `other` lies entirely inside this box (faces may touch).
    pub fn contains(&self, other: &Bounds32) -> bool {
        (0..3).all(|axis| self.min[axis] <= other.min[axis] && other.max[axis] <= self.max[axis])
    }

    /// The same box in double precision (exactly: every `f32` is an `f64`).
    pub fn to_aabb(self) -> Aabb {
        Aabb {
            min: glam::DVec3::from_array(self.min.map(f64::from)),
            max: glam::DVec3::from_array(self.max.map(f64::from)),
        }
    }
}

/// `a < b ? a : b`: one instruction, unlike `f32::min`'s NaN rules.
#[inline(always)]
fn pick_min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

#[inline(always)]
fn pick_max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// The largest `f32` not above `x` and the smallest not below it (equal
/// when `x` is an `f32`): [`round_down`] and [`round_up`], which share
/// their conversion once inlined.
#[inline(always)]
pub fn bracket(x: f64) -> (f32, f32) {
    (round_down(x), round_up(x))
}

/// The largest `f32` not above `x`.
#[inline(always)]
pub fn round_down(x: f64) -> f32 {
    let (bits, step) = nearest_and_step(x);
    f32::from_bits(bits.wrapping_sub(step & all_ones_if(f64::from(f32::from_bits(bits)) > x)))
}

/// The smallest `f32` not below `x`.
#[inline(always)]
pub fn round_up(x: f64) -> f32 {
    let (bits, step) = nearest_and_step(x);
    f32::from_bits(bits.wrapping_add(step & all_ones_if(f64::from(f32::from_bits(bits)) < x)))
}

/// The bits of `x` rounded to the nearest `f32`, and the change to them
/// that moves one ulp towards +∞: +1 for a positive number, −1 (all ones)
/// for a negative one.
///
/// The roundings apply that step under a mask rather than behind a
/// branch: which way the conversion rounded is a coin toss per ray (for
/// ray origins and every new nearest-hit distance), so a branch would be
/// mispredicted half the time. Zero needs no special case: the
/// conversion keeps the sign, so a negative `x` rounds up only to −0
/// (whose −1 step gives the smallest negative subnormal) and a positive
/// one down only to +0 (whose +1 step gives the smallest positive one).
#[inline(always)]
fn nearest_and_step(x: f64) -> (u32, u32) {
    let bits = (x as f32).to_bits();
    (bits, sign_mask32(bits) | 1)
}

/// All ones when the sign bit of `bits` is set, else zero.
#[inline(always)]
pub fn sign_mask32(bits: u32) -> u32 {
    ((bits as i32) >> 31) as u32
}

/// All ones when `condition` holds, else zero.
#[inline(always)]
fn all_ones_if(condition: bool) -> u32 {
    u32::from(condition).wrapping_neg()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outward_rounding_brackets_the_value() {
        for x in [0.1, -0.1, 1e-30, -7.3e12, 1.0 / 3.0, 3.0, 1e-50, -1e-50, 0.0, -0.0] {
            let (down, up) = (round_down(x), round_up(x));
            assert_eq!(bracket(x), (down, up), "{x}");
            assert!(f64::from(down) <= x && x <= f64::from(up), "{x}: {down} {up}");
            assert!(up == down || up == down.next_up(), "{x}: one ulp apart");
        }
        for x in [1e300, -1e300] {
            assert!(f64::from(round_down(x)) <= x && x <= f64::from(round_up(x)));
        }
        assert_eq!(round_down(0.5), 0.5);
        assert_eq!(round_up(0.5), 0.5);
    }
}
