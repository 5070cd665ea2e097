//! The four-lane watertight test in AVX instructions, for the AVX2 copy of
//! the traversal: one 256-bit operation where `wide`'s four `f64` lanes are
//! two SSE2 halves in a baseline build. Every step is the portable test's
//! ([`super::intersect_portable`]), with the same operands in the same
//! order, and its comparisons and NaN-ignoring maxima give the same lanes,
//! so the answers are the same bit for bit.

use super::super::super::triangle::TriangleRay;
use super::super::LeafData;
use super::Candidates;
use crate::accel::Avx2;
use crate::math::gamma;
use std::arch::x86_64::{
    __m128, __m256d, _CMP_EQ_OQ, _CMP_GE_OQ, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_LT_OQ, _CMP_UNORD_Q, _mm256_add_pd, _mm256_and_pd,
    _mm256_blendv_pd, _mm256_cmp_pd, _mm256_cvtps_pd, _mm256_div_pd, _mm256_max_pd, _mm256_movemask_pd, _mm256_mul_pd,
    _mm256_or_pd, _mm256_set1_pd, _mm256_setzero_pd, _mm256_sub_pd,
};

/// [`super::intersect`] in AVX instructions; `avx2` proves the CPU has them.
#[inline(always)]
pub(super) fn intersect(avx2: Avx2, ray: &TriangleRay, leaf: &LeafData, t_max: f64) -> Option<Candidates> {
    let _ = avx2;
    // SAFETY: an `Avx2` exists only if this CPU has AVX2 (`Avx2::detect`).
    #[allow(unsafe_code)]
    unsafe {
        intersect_inlined(ray, leaf, t_max)
    }
}

/// Lanes where `a < b`, as all-ones masks (the predicates below are
/// ordered and quiet: false where either lane is NaN, as SSE2's `cmpltpd`).
#[target_feature(enable = "avx2")]
#[inline]
fn less(a: __m256d, b: __m256d) -> __m256d {
    _mm256_cmp_pd::<_CMP_LT_OQ>(a, b)
}

#[target_feature(enable = "avx2")]
#[inline]
fn greater(a: __m256d, b: __m256d) -> __m256d {
    _mm256_cmp_pd::<_CMP_GT_OQ>(a, b)
}

/// `|a|`: the sign bit cleared, as `wide`'s `abs`.
#[target_feature(enable = "avx2")]
#[inline]
fn abs(a: __m256d) -> __m256d {
    _mm256_and_pd(a, _mm256_set1_pd(f64::from_bits(i64::MAX as u64)))
}

/// `wide`'s NaN-ignoring `a.max(b)`: `a` where `b` is NaN, else `maxpd`
/// (which gives `b` where `a` is NaN).
#[target_feature(enable = "avx2")]
#[inline]
fn max(a: __m256d, b: __m256d) -> __m256d {
    _mm256_blendv_pd(_mm256_max_pd(a, b), a, _mm256_cmp_pd::<_CMP_UNORD_Q>(b, b))
}

/// The largest magnitude of three, as the portable test takes it.
#[target_feature(enable = "avx2")]
#[inline]
fn max_abs(a: __m256d, b: __m256d, c: __m256d) -> __m256d {
    max(max(abs(a), abs(b)), abs(c))
}

/// Lane bits of a mask.
#[target_feature(enable = "avx2")]
#[inline]
fn bits(mask: __m256d) -> u32 {
    _mm256_movemask_pd(mask) as u32
}

fn to_array(lanes: __m256d) -> [f64; 4] {
    bytemuck::cast(lanes)
}

/// The test, always inlined into its caller (the AVX2 copy of the
/// traversal, compiled with these instructions) so that the intrinsics
/// are too. A function of its own compiled for AVX2 (`#[target_feature]`),
/// which needs no `unsafe`, stayed an out-of-line call per leaf, which
/// cost 5–9% more instructions per ray query (callgrind, `ray_cost`).
///
/// # Safety
/// The CPU must have AVX2. Nothing else here is unsafe: no pointers, only
/// the intrinsics, which are safe wherever those instructions exist.
#[inline(always)]
#[allow(unsafe_code)]
unsafe fn intersect_inlined(ray: &TriangleRay, leaf: &LeafData, t_max: f64) -> Option<Candidates> {
    // SAFETY: the caller's promise above.
    unsafe {
        let (add, sub, mul) = (_mm256_add_pd, _mm256_sub_pd, _mm256_mul_pd);
        let splat = _mm256_set1_pd;
        // Vertex i's coordinate on the permuted axis j, as anchor + offset
        // (each offset converted exactly from `f32`).
        let mut vertices = [[_mm256_setzero_pd(); 3]; 3];
        for (vertex, coordinates) in vertices.iter_mut().enumerate() {
            for (j, coordinate) in coordinates.iter_mut().enumerate() {
                let anchor = bytemuck::cast::<[f64; 4], __m256d>(leaf.anchors[j]);
                let offset = bytemuck::cast::<[f32; 4], __m128>(leaf.offsets(3 * vertex + ray.axes[j]));
                *coordinate = add(anchor, _mm256_cvtps_pd(offset));
            }
        }
        let origin = [splat(ray.origin[0]), splat(ray.origin[1]), splat(ray.origin[2])];
        let (shear_x, shear_y) = (splat(ray.shear_x), splat(ray.shear_y));
        // Translate to the ray origin, permute, shear so the ray is +z.
        let mut p = [[_mm256_setzero_pd(); 3]; 3];
        for (transformed, [x, y, z]) in p.iter_mut().zip(vertices) {
            let (x, y, z) = (sub(x, origin[0]), sub(y, origin[1]), sub(z, origin[2]));
            *transformed = [add(x, mul(shear_x, z)), add(y, mul(shear_y, z)), z];
        }
        let e0 = sub(mul(p[1][0], p[2][1]), mul(p[1][1], p[2][0]));
        let e1 = sub(mul(p[2][0], p[0][1]), mul(p[2][1], p[0][0]));
        let e2 = sub(mul(p[0][0], p[1][1]), mul(p[0][1], p[1][0]));
        let zero = _mm256_setzero_pd();
        let any_negative = _mm256_or_pd(_mm256_or_pd(less(e0, zero), less(e1, zero)), less(e2, zero));
        let any_positive = _mm256_or_pd(_mm256_or_pd(greater(e0, zero), greater(e1, zero)), greater(e2, zero));
        let det = add(add(e0, e1), e2);
        // Rejected: mixed signs, or a zero determinant.
        let rejected = bits(any_negative) & bits(any_positive) | bits(_mm256_cmp_pd::<_CMP_EQ_OQ>(det, zero));
        let mut mask = leaf.active() & !rejected;
        if mask == 0 {
            return None;
        }

        let shear_z = splat(ray.shear_z);
        let z = [mul(p[0][2], shear_z), mul(p[1][2], shear_z), mul(p[2][2], shear_z)];
        let t_scaled = add(add(mul(e0, z[0]), mul(e1, z[1])), mul(e2, z[2]));
        let (negative, positive) = (bits(less(det, zero)), bits(greater(det, zero)));
        let behind = negative & bits(_mm256_cmp_pd::<_CMP_GE_OQ>(t_scaled, zero))
            | positive & bits(_mm256_cmp_pd::<_CMP_LE_OQ>(t_scaled, zero));
        mask &= !behind;
        let bound = mul(splat(t_max), det);
        let beyond = negative & bits(less(t_scaled, bound)) | positive & bits(greater(t_scaled, bound));
        // As in the portable test: with no lane within `t_max`, nothing is hit.
        if mask & !beyond == 0 {
            return None;
        }

        let inverse_det = _mm256_div_pd(splat(1.0), det);
        let t = mul(t_scaled, inverse_det);
        // The conservative lower bound on t (pbrt-v4 §6.5.3).
        let max_z = max_abs(z[0], z[1], z[2]);
        let delta_z = mul(splat(gamma(3)), max_z);
        let max_x = max_abs(p[0][0], p[1][0], p[2][0]);
        let max_y = max_abs(p[0][1], p[1][1], p[2][1]);
        let delta_x = mul(splat(gamma(5)), add(max_x, max_z));
        let delta_y = mul(splat(gamma(5)), add(max_y, max_z));
        let delta_e = mul(
            splat(2.0),
            add(
                add(mul(mul(splat(gamma(2)), max_x), max_y), mul(delta_y, max_x)),
                mul(delta_x, max_y),
            ),
        );
        let max_e = max_abs(e0, e1, e2);
        let delta_t = mul(
            mul(
                splat(3.0),
                add(
                    add(mul(mul(splat(gamma(3)), max_e), max_z), mul(delta_e, max_z)),
                    mul(delta_z, max_e),
                ),
            ),
            abs(inverse_det),
        );
        mask &= !bits(_mm256_cmp_pd::<_CMP_LE_OQ>(t, delta_t));
        if mask & !beyond == 0 {
            return None;
        }
        Some(Candidates {
            mask,
            t_scaled: to_array(t_scaled),
            det: to_array(det),
            t: to_array(t),
            inverse_det: to_array(inverse_det),
            edges: [to_array(e0), to_array(e1), to_array(e2)],
        })
    }
}
