//! Four `f64` lanes in one AVX register, for code that runs only where an
//! [`Avx2`] proves the CPU has the instructions (the path loop's AVX2 copy,
//! `accel::kernel`). `wide::f64x4` is two SSE2 halves in the baseline
//! build the release binary is; these are one 256-bit operation each.
//!
//! A value can only be made from an [`Avx2`] (or from other values), so
//! every operation on one runs on a CPU that has the instructions; that is
//! what makes the intrinsics below sound. Comparisons give masks of all-ones
//! lanes, with the scalar operators' answers for NaN (`!=` true, the others
//! false), and [`F64x4::max`] ignores a NaN as `f64::max` does, so lanes
//! compute what the scalar code computes, bit for bit.

#![allow(unsafe_code)]

use crate::accel::Avx2;
use std::arch::x86_64::{
    __m256d, __m256i, _CMP_EQ_OQ, _CMP_GT_OQ, _CMP_LT_OQ, _CMP_NEQ_UQ, _CMP_UNORD_Q, _mm256_add_epi64, _mm256_add_pd,
    _mm256_and_pd, _mm256_andnot_pd, _mm256_blendv_pd, _mm256_castpd_si256, _mm256_castsi256_pd, _mm256_cmp_pd, _mm256_div_pd,
    _mm256_max_pd, _mm256_movemask_pd, _mm256_mul_pd, _mm256_or_pd, _mm256_set1_epi64x, _mm256_set1_pd, _mm256_slli_epi64,
    _mm256_sqrt_pd, _mm256_srli_epi64, _mm256_sub_epi64, _mm256_sub_pd, _mm256_xor_pd,
};
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Four `f64` lanes (or, from a comparison, four all-ones or all-zeros masks).
#[derive(Clone, Copy, Debug)]
pub struct F64x4(__m256d);

// SAFETY (every `unsafe` block below): an `F64x4` exists only where an
// `Avx2` did (`splat` and `new` take one; everything else is made from
// `F64x4`s), so the CPU has AVX2; the intrinsics touch no memory.

/// Comparison methods, one `vcmppd` predicate each.
macro_rules! comparisons {
    ($($(#[$doc:meta])* $name:ident, $predicate:ident;)*) => {
        $(
            $(#[$doc])*
            #[inline(always)]
            pub fn $name(self, other: Self) -> Self {
                Self(unsafe { _mm256_cmp_pd::<$predicate>(self.0, other.0) })
            }
        )*
    };
}

impl F64x4 {
    /// `value` in every lane.
    #[inline(always)]
    pub fn splat(avx2: Avx2, value: f64) -> Self {
        let _ = avx2;
        Self(unsafe { _mm256_set1_pd(value) })
    }

    /// The lanes of `lanes`.
    #[inline(always)]
    pub fn new(avx2: Avx2, lanes: [f64; 4]) -> Self {
        let _ = avx2;
        Self(bytemuck::cast(lanes))
    }

    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f64; 4] {
        bytemuck::cast(self.0)
    }

    /// `value` in every lane, from a vector that proves AVX2 (any other).
    #[inline(always)]
    pub fn splat_like(self, value: f64) -> Self {
        Self(unsafe { _mm256_set1_pd(value) })
    }

    #[inline(always)]
    fn bits(self) -> __m256i {
        unsafe { _mm256_castpd_si256(self.0) }
    }

    #[inline(always)]
    fn from_bits(bits: __m256i) -> Self {
        Self(unsafe { _mm256_castsi256_pd(bits) })
    }

    comparisons! {
        /// Lanes where `self == other` (false for NaN).
        cmp_eq, _CMP_EQ_OQ;
        /// Lanes where `self != other` (true for NaN, as the scalar operator).
        cmp_ne, _CMP_NEQ_UQ;
        /// Lanes where `self < other`.
        cmp_lt, _CMP_LT_OQ;
        /// Lanes where `self > other`.
        cmp_gt, _CMP_GT_OQ;
    }

    /// With `self` a mask: `when_set` where it is set, `otherwise` elsewhere.
    #[inline(always)]
    pub fn blend(self, when_set: Self, otherwise: Self) -> Self {
        Self(unsafe { _mm256_blendv_pd(otherwise.0, when_set.0, self.0) })
    }

    /// Whether any lane of the mask `self` is set.
    #[inline(always)]
    pub fn any(self) -> bool {
        unsafe { _mm256_movemask_pd(self.0) != 0 }
    }

    /// `|self|`: the sign bits cleared.
    #[inline(always)]
    pub fn abs(self) -> Self {
        Self(unsafe { _mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0) })
    }

    /// The magnitude of `self` with the sign of `sign`.
    #[inline(always)]
    pub fn copysign(self, sign: Self) -> Self {
        unsafe {
            let sign_bit = _mm256_set1_pd(-0.0);
            Self(_mm256_or_pd(
                _mm256_andnot_pd(sign_bit, self.0),
                _mm256_and_pd(sign_bit, sign.0),
            ))
        }
    }

    /// `f64::max` per lane: `self` where `other` is NaN, else `maxpd`
    /// (which gives `other` where `self` is NaN).
    #[inline(always)]
    pub fn max(self, other: Self) -> Self {
        unsafe {
            let other_nan = _mm256_cmp_pd::<_CMP_UNORD_Q>(other.0, other.0);
            Self(_mm256_blendv_pd(_mm256_max_pd(self.0, other.0), self.0, other_nan))
        }
    }

    /// The correctly rounded square root per lane.
    #[inline(always)]
    pub fn sqrt(self) -> Self {
        Self(unsafe { _mm256_sqrt_pd(self.0) })
    }

    /// `self` with its sign flipped where the mask `negate` is set.
    #[inline(always)]
    pub fn negate_where(self, negate: Self) -> Self {
        Self(unsafe { _mm256_xor_pd(self.0, _mm256_and_pd(negate.0, _mm256_set1_pd(-0.0))) })
    }

    /// The next representable value away from zero in each lane of the
    /// mask `moving` whose sign is `toward`'s, toward zero where the signs
    /// differ (`math::ray::offset_ray_origin`'s one-ulp step on the bits:
    /// ±1 on the integer the bits spell). Only for finite, non-zero lanes.
    #[inline(always)]
    pub fn step_bits(self, toward: Self, moving: Self) -> Self {
        unsafe {
            let sign_differs = _mm256_srli_epi64::<63>(_mm256_castpd_si256(_mm256_xor_pd(self.0, toward.0)));
            let step = _mm256_sub_epi64(_mm256_set1_epi64x(1), _mm256_slli_epi64::<1>(sign_differs));
            let step = _mm256_castsi256_pd(step);
            Self::from_bits(_mm256_add_epi64(self.bits(), Self(_mm256_and_pd(step, moving.0)).bits()))
        }
    }
}

macro_rules! binary {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for F64x4 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                Self(unsafe { $intrinsic(self.0, other.0) })
            }
        }
    };
}

binary!(Add, add, _mm256_add_pd);
binary!(Sub, sub, _mm256_sub_pd);
binary!(Mul, mul, _mm256_mul_pd);
binary!(Div, div, _mm256_div_pd);
binary!(BitAnd, bitand, _mm256_and_pd);
binary!(BitOr, bitor, _mm256_or_pd);

impl Neg for F64x4 {
    type Output = Self;
    /// The sign bits flipped, as the scalar `-x`.
    #[inline(always)]
    fn neg(self) -> Self {
        Self(unsafe { _mm256_xor_pd(self.0, _mm256_set1_pd(-0.0)) })
    }
}

impl Not for F64x4 {
    type Output = Self;
    /// Every bit flipped (a mask's complement).
    #[inline(always)]
    fn not(self) -> Self {
        Self(unsafe { _mm256_xor_pd(self.0, _mm256_castsi256_pd(_mm256_set1_epi64x(-1))) })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each operation gives the scalar operator's lanes, NaN, infinities
    /// and signed zeros included.
    #[test]
    fn lanes_match_the_scalar_operators() {
        let Some(avx2) = Avx2::detect() else {
            eprintln!("no AVX2 on this CPU");
            return;
        };
        let values = [
            0.0,
            -0.0,
            1.5,
            -2.25,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            1e-310,
            3.0e300,
            -7.0,
        ];
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
        let mask = |set: bool| if set { f64::from_bits(u64::MAX) } else { 0.0 };
        for chunk_a in values.chunks(2) {
            for &b in &values {
                let a = [chunk_a[0], chunk_a[chunk_a.len() - 1], -chunk_a[0], b];
                let (x, y) = (F64x4::new(avx2, a), F64x4::splat(avx2, b));
                for (lane, &p) in a.iter().enumerate() {
                    let q = b;
                    let checks = [
                        ((x + y).to_array()[lane], p + q),
                        ((x - y).to_array()[lane], p - q),
                        ((x * y).to_array()[lane], p * q),
                        ((x / y).to_array()[lane], p / q),
                        ((-x).to_array()[lane], -p),
                        (x.abs().to_array()[lane], p.abs()),
                        (x.sqrt().to_array()[lane], p.sqrt()),
                        (x.copysign(y).to_array()[lane], p.copysign(q)),
                        (x.cmp_eq(y).to_array()[lane], mask(p == q)),
                        (x.cmp_ne(y).to_array()[lane], mask(p != q)),
                        (x.cmp_lt(y).to_array()[lane], mask(p < q)),
                        (x.cmp_gt(y).to_array()[lane], mask(p > q)),
                    ];
                    for (index, (got, expected)) in checks.into_iter().enumerate() {
                        assert!(
                            same(got, expected),
                            "check {index}: {p:?}, {q:?}: {got:?} against {expected:?}"
                        );
                    }
                    // Zeros of either sign may come out of `max` either way.
                    let (got, expected) = (x.max(y).to_array()[lane], p.max(q));
                    assert!(same(got, expected) || (got == 0.0 && expected == 0.0), "max {p:?} {q:?}");
                }
            }
        }
    }
}
