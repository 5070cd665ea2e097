//! Four of a stream's Sobol' 2D draws at once, in AVX2 lanes.
//!
//! A scalar 2D draw is a chain of about seventy integer operations: two
//! SplitMix64 finalisers (the dimension's seed and its scramble), three
//! Laine–Karras permutations, four table loads and a 64-bit bit reversal.
//! A stream reads its first 2D draws (a path's film position, lens and
//! first bounces' light point and direction; a photon's point, direction
//! and first bounces) at fixed dimensions, so they can be computed
//! together when the stream starts, where that pays (see
//! `Sampler::draw_ahead`'s callers): the same operations on four
//! dimensions' values side by side, 64-bit lanes for the finalisers and
//! 32-bit lanes for the permutations; 117 instructions in the release
//! build, for what takes about 280 one at a time. The joint dimension's
//! lane (`super::JOINT_DIMENSION`) reads the first draw's shuffled index,
//! computed one by one beside the lanes.
//!
//! The results are those of [`super::Sampler::next_2d`] bit for bit: every
//! step is integer arithmetic modulo 2³² or 2⁶⁴.

/// The Sobol' 2D draws of `dimensions` (each at most
/// [`super::SOBOL_DIMENSIONS`]; [`super::JOINT_DIMENSION`]'s as the second
/// half of its four-dimensional point) of the stream with `stream_seed` and the
/// bit-reversed sample index `reversed_index`, as 32-bit fixed-point
/// values: x then y of each dimension in turn ([`super::to_unit`] makes
/// them the draws).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
pub(super) fn sobol_2d_four(stream_seed: u64, reversed_index: u32, dimensions: [u32; 4]) -> [u32; 8] {
    use std::arch::x86_64::*;

    // 64-bit products modulo 2⁶⁴ from AVX2's 32 × 32 → 64-bit multiply:
    // (h·2³² + l)(H·2³² + L) ≡ l·L + ((h·L + l·H) mod 2³²)·2³².
    let times = |z: __m256i, factor: u64| {
        let (low, high) = (
            _mm256_set1_epi64x(factor as u32 as i64),
            _mm256_set1_epi64x((factor >> 32) as i64),
        );
        let cross = _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64::<32>(z), low), _mm256_mul_epu32(z, high));
        _mm256_add_epi64(_mm256_mul_epu32(z, low), _mm256_slli_epi64::<32>(cross))
    };
    // `super::mix64`, lane by lane.
    let mix64 = |z: __m256i| {
        let z = times(_mm256_xor_si256(z, _mm256_srli_epi64::<30>(z)), 0xbf58_476d_1ce4_e5b9);
        let z = times(_mm256_xor_si256(z, _mm256_srli_epi64::<27>(z)), 0x94d0_49bb_1331_11eb);
        _mm256_xor_si256(z, _mm256_srli_epi64::<31>(z))
    };
    // `super::laine_karras_permutation` in each 32-bit lane.
    let laine_karras = |x: __m256i, seed: __m256i| {
        let mut x = _mm256_add_epi32(x, seed);
        for factor in [0x6c50_b47c_u32, 0xb82f_1e52, 0xc7af_e638, 0x8d22_f6e6] {
            x = _mm256_xor_si256(x, _mm256_mullo_epi32(x, _mm256_set1_epi32(factor as i32)));
        }
        x
    };
    // Each 32-bit lane's bits reversed: its bytes in reverse order
    // (`vpshufb`), then each byte's two nibbles swapped and reversed by
    // table lookups (`vpshufb` again, sixteen entries).
    let reverse_bits = |x: __m256i| {
        #[rustfmt::skip]
        let bytes = _mm256_setr_epi8(
            3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12,
            3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12,
        );
        #[rustfmt::skip]
        let reversed_nibble = _mm256_setr_epi8(
            0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf,
            0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf,
        );
        let reversed_nibble_high = _mm256_slli_epi16::<4>(reversed_nibble);
        let x = _mm256_shuffle_epi8(x, bytes);
        let nibbles = _mm256_set1_epi8(0x0f);
        let low = _mm256_and_si256(x, nibbles);
        let high = _mm256_and_si256(_mm256_srli_epi16::<4>(x), nibbles);
        _mm256_or_si256(
            _mm256_shuffle_epi8(reversed_nibble_high, low),
            _mm256_shuffle_epi8(reversed_nibble, high),
        )
    };

    let [d0, d1, d2, d3] = dimensions.map(|d| (stream_seed ^ u64::from(d).wrapping_mul(super::DIMENSION_FACTOR)) as i64);
    let dimension_seed = mix64(_mm256_setr_epi64x(d0, d1, d2, d3));
    // The shuffled index (`Sampler::shuffled_index`) in each 64-bit lane's
    // low half: the reversed sample index Laine–Karras permuted by the
    // seed's low half, then reversed back. (The high halves, until they
    // are replaced below, hold values nothing reads: every step before
    // then works within 32-bit lanes.)
    let shuffled_reversed = laine_karras(_mm256_set1_epi64x(i64::from(reversed_index)), dimension_seed);
    let index = reverse_bits(shuffled_reversed);
    // Sobol' dimension 1 of the index, bit-reversed: its bit k is the parity
    // of the index's set bits j with k ⊆ j (the generator matrix is
    // Pascal's triangle mod 2, by Lucas's theorem), the superset sum over
    // GF(2) of the index's bits, taken one bit of k at a time.
    let superset_step =
        |x: __m256i, shifted: __m256i, mask: u32| _mm256_xor_si256(x, _mm256_and_si256(shifted, _mm256_set1_epi32(mask as i32)));
    let second = superset_step(index, _mm256_srli_epi32::<1>(index), 0x5555_5555);
    let second = superset_step(second, _mm256_srli_epi32::<2>(second), 0x3333_3333);
    let second = superset_step(second, _mm256_srli_epi32::<4>(second), 0x0f0f_0f0f);
    let second = superset_step(second, _mm256_srli_epi32::<8>(second), 0x00ff_00ff);
    let second = superset_step(second, _mm256_srli_epi32::<16>(second), 0x0000_ffff);
    // (index, second) as the low and high halves of each 64-bit lane, the
    // halves of the scramble (`mix64` of the dimension's seed) beside them.
    let low_halves = _mm256_set1_epi64x(0xffff_ffff);
    let mut pairs = _mm256_or_si256(_mm256_and_si256(index, low_halves), _mm256_slli_epi64::<32>(second));
    // The joint dimension's lane (if any) takes Sobol' dimensions 3 and 4
    // of the index shuffled for the first draw instead: computed one by one
    // beside the lanes' chain, which it joins only here.
    if let Some(lane) = dimensions.iter().position(|&d| d == super::JOINT_DIMENSION) {
        let (third, fourth) = super::joint_dimensions_reversed(stream_seed, reversed_index);
        let joint = _mm256_set1_epi64x((u64::from(third) | u64::from(fourth) << 32) as i64);
        let in_lane = _mm256_cmpeq_epi64(_mm256_setr_epi64x(0, 1, 2, 3), _mm256_set1_epi64x(lane as i64));
        pairs = _mm256_blendv_epi8(pairs, joint, in_lane);
    }
    let points = reverse_bits(laine_karras(pairs, mix64(dimension_seed)));
    bytemuck::cast(points)
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use crate::sampler::{Sampler, SamplerKind, mix64, to_unit};

    #[test]
    fn four_lanes_equal_four_scalar_draws() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let mut checked = 0;
        for stream in 0..4_000u64 {
            let pixel = mix64(stream);
            let sample = match stream % 4 {
                0 => stream as u32,
                1 => u32::MAX - stream as u32,
                _ => mix64(stream ^ 77) as u32,
            };
            let sampler = Sampler::new(SamplerKind::Sobol, pixel, sample, stream % 7);
            let dimensions = [1, 2, 4, 5].map(|d| (d + stream as u32 % 7).min(super::super::SOBOL_DIMENSIONS));
            // SAFETY: the CPU has AVX2 (checked above).
            #[allow(unsafe_code)]
            let lanes = unsafe { sobol_2d_four(sampler.stream_seed, sampler.reversed_index, dimensions) };
            for (lane, &dimension) in dimensions.iter().enumerate() {
                let mut scalar = sampler.clone();
                scalar.dimension = dimension - 1;
                let expected = scalar.next_2d();
                let drawn = (to_unit(lanes[2 * lane]), to_unit(lanes[2 * lane + 1]));
                assert_eq!(
                    drawn.0.to_bits(),
                    expected.x.to_bits(),
                    "stream {stream}, dimension {dimension}"
                );
                assert_eq!(
                    drawn.1.to_bits(),
                    expected.y.to_bits(),
                    "stream {stream}, dimension {dimension}"
                );
                checked += 1;
            }
        }
        assert_eq!(checked, 16_000);
    }
}
