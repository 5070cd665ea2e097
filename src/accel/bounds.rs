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
/// when `x` is an `f32`), from one conversion and the neighbours' bit
/// patterns (ray origins are finite and within `f32`'s range, which the
/// scene's coordinate limit ensures).
///
/// Whether the conversion rounded up or down is a coin toss per ray, which
/// a branch would mispredict half the time, so it is read from the sign
/// bit of the difference (a rounded difference has the sign of the exact
/// one) and applied as a mask. One ulp towards +∞ is +1 on the bits of a
/// positive number and −1 on those of a negative one. Zero needs no
/// special case: the conversion keeps the sign, so a negative `x` rounds
/// up only to −0 (whose −1 step gives the smallest negative subnormal)
/// and a positive one down only to +0 (whose +1 step gives the smallest
/// positive one).
#[inline(always)]
pub fn bracket(x: f64) -> (f32, f32) {
    let rounded = x as f32;
    let back = f64::from(rounded);
    let bits = rounded.to_bits();
    let step = sign_mask32(bits) | 1;
    let rounded_up = sign_mask64(x - back);
    let rounded_down = sign_mask64(back - x);
    let down = bits.wrapping_sub(step & rounded_up);
    let up = bits.wrapping_add(step & rounded_down);
    (f32::from_bits(down), f32::from_bits(up))
}

/// All ones when the sign bit of `bits` is set, else zero.
#[inline(always)]
pub fn sign_mask32(bits: u32) -> u32 {
    ((bits as i32) >> 31) as u32
}

/// All ones when `x` is negative (its sign bit is set), else zero.
#[inline(always)]
fn sign_mask64(x: f64) -> u32 {
    ((x.to_bits() as i64) >> 63) as u32
}

/// The largest `f32` not above `x`.
#[inline]
pub fn round_down(x: f64) -> f32 {
    let rounded = x as f32;
    let bits = rounded.to_bits();
    let step = sign_mask32(bits) | 1;
    f32::from_bits(bits.wrapping_sub(step & all_ones_if(f64::from(rounded) > x)))
}

/// The smallest `f32` not below `x`. Like [`bracket`], without a branch on
/// which way the conversion rounded (the traversal rounds every new
/// nearest-hit distance, and which way it goes is a coin toss).
#[inline]
pub fn round_up(x: f64) -> f32 {
    let rounded = x as f32;
    let bits = rounded.to_bits();
    let step = sign_mask32(bits) | 1;
    f32::from_bits(bits.wrapping_add(step & all_ones_if(f64::from(rounded) < x)))
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
