//! The four spheres' roots in AVX instructions, for the AVX2 copies of the
//! leaf tests: one 256-bit operation where `wide`'s four `f64` lanes are two
//! SSE2 halves in a baseline build. Every step is [`Spheres::roots`]'s, with
//! the same operands in the same order (sign flips, `copysign` and the
//! selects as the same bit operations), so the roots are the same bit for bit.

use super::{Roots, Spheres};
use crate::math::Ray;
use std::arch::x86_64::{
    __m256d, _CMP_LT_OQ, _mm256_add_pd, _mm256_and_pd, _mm256_blendv_pd, _mm256_cmp_pd, _mm256_div_pd, _mm256_movemask_pd,
    _mm256_mul_pd, _mm256_or_pd, _mm256_set1_pd, _mm256_sqrt_pd, _mm256_sub_pd, _mm256_xor_pd,
};

impl Spheres {
    /// [`Spheres::roots`] in AVX instructions.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(super) fn roots_avx2(&self, ray: &Ray, first: u32, count: u32) -> Option<Roots> {
        let (add, sub, mul) = (_mm256_add_pd, _mm256_sub_pd, _mm256_mul_pd);
        let first = first as usize;
        let lanes = |k: usize| -> Option<__m256d> {
            let four: &[f64; 4] = self.values[k].get(first..)?.first_chunk()?;
            Some(bytemuck::cast(*four))
        };
        let [center_x, center_y, center_z, radius] = [lanes(0)?, lanes(1)?, lanes(2)?, lanes(3)?];
        let [d_x, d_y, d_z] = [
            _mm256_set1_pd(ray.direction.x),
            _mm256_set1_pd(ray.direction.y),
            _mm256_set1_pd(ray.direction.z),
        ];
        let [o_x, o_y, o_z] = [
            _mm256_set1_pd(ray.origin.x),
            _mm256_set1_pd(ray.origin.y),
            _mm256_set1_pd(ray.origin.z),
        ];
        let sign = _mm256_set1_pd(-0.0);

        let (f_x, f_y, f_z) = (sub(o_x, center_x), sub(o_y, center_y), sub(o_z, center_z));
        let b = add(add(mul(f_x, d_x), mul(f_y, d_y)), mul(f_z, d_z));
        let radius_squared = mul(radius, radius);
        let c = sub(add(add(mul(f_x, f_x), mul(f_y, f_y)), mul(f_z, f_z)), radius_squared);
        let (closest_x, closest_y, closest_z) = (sub(f_x, mul(b, d_x)), sub(f_y, mul(b, d_y)), sub(f_z, mul(b, d_z)));
        let discriminant = sub(
            radius_squared,
            add(
                add(mul(closest_x, closest_x), mul(closest_y, closest_y)),
                mul(closest_z, closest_z),
            ),
        );
        let negative = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LT_OQ>(discriminant, _mm256_set1_pd(0.0))) as u32;
        let mask = !negative & 0xf & ((1 << count) - 1);
        if mask == 0 {
            return None;
        }
        // q = −b − copysign(√discriminant, b), `copysign` as `wide`'s: the
        // magnitude's bits with the sign's sign bit.
        let magnitude = _mm256_and_pd(_mm256_sqrt_pd(discriminant), _mm256_set1_pd(f64::from_bits(u64::MAX >> 1)));
        let q = sub(_mm256_xor_pd(b, sign), _mm256_or_pd(magnitude, _mm256_and_pd(b, sign)));
        let a = _mm256_div_pd(c, q);
        let a_nearer = _mm256_cmp_pd::<_CMP_LT_OQ>(a, q);
        Some(Roots {
            mask,
            near: bytemuck::cast(_mm256_blendv_pd(q, a, a_nearer)),
            far: bytemuck::cast(_mm256_blendv_pd(a, q, a_nearer)),
        })
    }
}
