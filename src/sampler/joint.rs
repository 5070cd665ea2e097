//! Sobol' dimensions 3 and 4 of a shuffled index: the second half of the
//! four-dimensional point a stream's first 2D draw starts.
//!
//! Burley's construction gives every 2D draw its own shuffle of the sample
//! index, so the draws of different dimensions pair up at random: each 2D
//! draw is stratified on its own, and an integrand's variation that comes
//! from two draws together (their interaction) is integrated at the plain
//! Monte Carlo rate. Where two draws interact strongly, drawing them as one
//! four-dimensional Sobol' point, with one shuffle, stratifies that too:
//! the first 2^m samples of a pixel then form a (t, m, 4)-net, not two
//! unrelated (0, m, 2)-nets. In a camera path the film position and the
//! first surface's light sample are such a pair: where the pixel's footprint
//! crosses a penumbra or a change of shading, what the light sample sees
//! depends on where in the pixel the ray landed.
//!
//! Dimensions 1 and 2 of the point are those of the 2D draws
//! ([`super::index_and_second_dimension`]); 3 and 4 are Sobol' dimensions
//! by the direction numbers of Joe & Kuo (2008, "Constructing Sobol'
//! sequences with better two-dimensional projections", the `new-joe-kuo-6`
//! table): primitive polynomials x² + x + 1 and x³ + x + 1. Like the first
//! two, each is a linear map over GF(2) of the index's bits, so one table
//! per byte gives both.

/// Direction numbers vⱼ (j = 1…32) of the Sobol' dimension with primitive
/// polynomial degree `degree`, inner coefficients `coefficients` (a₁…a₍ₛ₋₁₎,
/// a₁ the most significant bit) and initial odd integers `initial`
/// (m₁…mₛ): mᵢ = 2a₁mᵢ₋₁ ⊕ 2²a₂mᵢ₋₂ ⊕ … ⊕ 2ˢmᵢ₋ₛ ⊕ mᵢ₋ₛ (Bratley & Fox
/// 1988), vⱼ = mⱼ · 2³²⁻ʲ.
const fn direction_numbers(degree: usize, coefficients: u32, initial: &[u32]) -> [u32; 32] {
    let mut m = [0u32; 33];
    let mut i = 1;
    while i <= 32 {
        m[i] = if i <= degree {
            initial[i - 1]
        } else {
            let mut value = m[i - degree] ^ (m[i - degree] << degree);
            let mut k = 1;
            while k < degree {
                if (coefficients >> (degree - 1 - k)) & 1 == 1 {
                    value ^= m[i - k] << k;
                }
                k += 1;
            }
            value
        };
        i += 1;
    }
    let mut directions = [0u32; 32];
    let mut j = 1;
    while j <= 32 {
        directions[j - 1] = m[j] << (32 - j);
        j += 1;
    }
    directions
}

use super::sobol;

/// Joe & Kuo's dimension 3 (x² + x + 1; m = 1, 3) and 4 (x³ + x + 1; m = 1, 3, 1).
const THIRD: [u32; 32] = direction_numbers(2, 1, &[1, 3]);
const FOURTH: [u32; 32] = direction_numbers(3, 1, &[1, 3, 1]);

/// Per byte of the index: dimension 3 bit-reversed in the low half,
/// dimension 4 bit-reversed in the high half.
const THIRD_AND_FOURTH: [[u64; 256]; 4] = {
    let mut tables = [[0u64; 256]; 4];
    let mut byte = 0;
    while byte < 4 {
        let mut value = 0;
        while value < 256 {
            let index = (value as u32) << (8 * byte);
            let third = sobol(index, &THIRD).reverse_bits();
            let fourth = sobol(index, &FOURTH).reverse_bits();
            tables[byte][value] = third as u64 | (fourth as u64) << 32;
            value += 1;
        }
        byte += 1;
    }
    tables
};

/// Sobol' dimensions 3 and 4 of `index`, each bit-reversed (what the
/// Laine–Karras permutation of an Owen scramble takes).
#[inline]
pub(super) fn third_and_fourth_reversed(index: u32) -> (u32, u32) {
    let both = super::xor_of_byte_tables(&THIRD_AND_FOURTH, index);
    (both as u32, (both >> 32) as u32)
}

/// [`third_and_fourth_reversed`] by the definition, bit by bit.
#[cfg(test)]
pub(super) fn third_and_fourth_reversed_by_definition(index: u32) -> (u32, u32) {
    (sobol(index, &THIRD).reverse_bits(), sobol(index, &FOURTH).reverse_bits())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tables give the definition, and the definition gives the
    /// published start of the sequences (natural index order: the point of
    /// index i XORs vⱼ over i's set bits).
    #[test]
    fn tables_give_joe_and_kuo_dimensions() {
        let unit = |bits: u32| bits as f64 / 4_294_967_296.0;
        // Dimension 3: v = 1/2, 3/4, 3/8, …; dimension 4: v = 1/2, 3/4, 1/8, …
        let third: Vec<f64> = (0..8).map(|i| unit(sobol(i, &THIRD))).collect();
        let fourth: Vec<f64> = (0..8).map(|i| unit(sobol(i, &FOURTH))).collect();
        assert_eq!(third, [0.0, 0.5, 0.75, 0.25, 0.375, 0.875, 0.625, 0.125]);
        assert_eq!(fourth, [0.0, 0.5, 0.75, 0.25, 0.125, 0.625, 0.875, 0.375]);
        for index in (0..5_000u32).chain([u32::MAX, 0x8000_0000, 0x1234_5678]) {
            let index = index.wrapping_mul(0x9e37_79b9);
            assert_eq!(
                third_and_fourth_reversed(index),
                (sobol(index, &THIRD).reverse_bits(), sobol(index, &FOURTH).reverse_bits())
            );
        }
    }

    /// The four dimensions' first 2^m points are a digital net: each 2D
    /// projection puts at most 2^t points in each cell of every elementary
    /// grid of 2^m cells, t = 0 for the first draw's pair (a (0, m, 2)-net)
    /// and t = 1 for every other pair (Joe & Kuo chose their direction
    /// numbers for such two-dimensional projections).
    #[test]
    fn the_four_dimensions_are_stratified_in_pairs() {
        let dimension = |d: usize, i: u32| -> u32 {
            match d {
                0 => i.reverse_bits(),
                1 => super::super::index_and_second_dimension(i.reverse_bits()).1.reverse_bits(),
                2 => sobol(i, &THIRD),
                _ => sobol(i, &FOURTH),
            }
        };
        // The most points in one cell of any elementary grid of 2^m cells
        // over dimensions a and b, for the first 2^m points.
        let m = 8u32;
        let most_per_cell = |a: usize, b: usize| {
            (0..=m)
                .map(|log_x| {
                    let mut cells = vec![0u32; 1 << m];
                    for i in 0..1u32 << m {
                        let x = (u64::from(dimension(a, i)) >> (32 - log_x)) as usize;
                        let y = (u64::from(dimension(b, i)) >> (32 - (m - log_x))) as usize;
                        cells[(y << log_x) | x] += 1;
                    }
                    cells.into_iter().max().unwrap_or(0)
                })
                .max()
                .unwrap_or(0)
        };
        assert_eq!(most_per_cell(0, 1), 1, "the first draw's pair");
        for (a, b) in [(0, 2), (0, 3), (1, 2), (1, 3), (2, 3)] {
            let most = most_per_cell(a, b);
            assert!(most <= 2, "dimensions {a} and {b}: up to {most} points per cell");
        }
    }
}
