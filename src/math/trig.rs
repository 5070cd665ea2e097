//! Cosine and sine of the angles sampling draws: azimuths 2π·u of a
//! uniform u, and the concentric disk map's angles within an eighth of a
//! turn of an axis.
//!
//! The C library's `sincos` handles any argument, which costs a range
//! reduction against π to hundreds of bits and a few branches; these angles
//! need neither. A turn fraction u reduces to quarter turns *exactly* (4u
//! minus its nearest integer is exact in binary floating point), and a
//! quarter turn's symmetries (swapping cosine and sine, flipping signs) are
//! exact too, so only |x| ≤ π/4 is ever evaluated, by truncated Taylor
//! series whose remainder lies far below an ulp. Vectorising renderers
//! evaluate their own polynomial sines for the same reason (Mitsuba 3's
//! Dr.Jit; Cephes' reduction to octants, Moshier 1989).

use std::f64::consts::FRAC_PI_2;

/// 1/n! for n = 0 … 18, each correctly rounded (n! itself is exact in `f64`
/// up to 22!, so only the division rounds). Public for code that evaluates
/// the same series in SIMD lanes (`integrator::path::diffuse_lanes`).
pub const INVERSE_FACTORIALS: [f64; 19] = {
    let mut table = [1.0; 19];
    let mut factorial = 1.0;
    let mut n = 1;
    while n < 19 {
        factorial *= n as f64;
        table[n] = 1.0 / factorial;
        n += 1;
    }
    table
};

/// (cos x, sin x) for |x| ≤ π/4, within one ulp of the C library's
/// (measured over 2·10⁶ points of [0, π/4]).
///
/// Taylor series to x¹⁶ and x¹⁷: the first omitted terms, x¹⁸/18! and
/// x¹⁹/19!, are below 3·10⁻¹⁸ and 9·10⁻²⁰ at π/4, where cos and sin are
/// 0.707, so truncation costs under 0.03 ulp; the rest is the evaluation's rounding.
/// Outside |x| ≤ π/4 the truncation error grows quickly: use
/// [`cos_sin_turns`] for larger angles.
#[inline]
pub fn cos_sin_eighth(x: f64) -> (f64, f64) {
    let f = &INVERSE_FACTORIALS;
    let (x2, x4) = (x * x, x * x * (x * x));
    let x8 = x4 * x4;
    // sin x = x (1 − x²/3! + x⁴/5! − …), cos x = 1 − x²/2! + x⁴/4! − …,
    // each tail a polynomial of degree 7 in x², by Estrin's scheme (Knuth,
    // TAOCP vol. 2, §4.6.4): pairs of terms side by side, then pairs of
    // pairs, so the chain of dependent operations is three multiply-adds
    // deep instead of Horner's eight. A sampled direction is on a path's
    // critical path (the next ray waits for it), so the latency counts.
    let sin_tail = ((-f[3] + x2 * f[5]) + x4 * (-f[7] + x2 * f[9])) + x8 * ((-f[11] + x2 * f[13]) + x4 * (-f[15] + x2 * f[17]));
    let cos_tail = ((-f[2] + x2 * f[4]) + x4 * (-f[6] + x2 * f[8])) + x8 * ((-f[10] + x2 * f[12]) + x4 * (-f[14] + x2 * f[16]));
    (1.0 + x2 * cos_tail, x + x * (x2 * sin_tail))
}

/// 1.5 · 2⁵²: adding it rounds any |t| < 2⁵¹ to an integer (to nearest,
/// ties to even) and leaves that integer, modulo 2⁵¹, in the low bits.
const ROUNDING_SHIFTER: f64 = 6_755_399_441_055_744.0;

/// The shifter rounds quarter-turn counts below 2⁵¹ (2⁴⁹ turns) in magnitude.
const REDUCTION_LIMIT: f64 = 2_251_799_813_685_248.0;

/// (cos 2πu, sin 2πu): the direction at azimuth `u` turns, to within
/// about an ulp of the exact values. `u` is reduced to the nearest quarter turn q and a
/// remainder r, |r| ≤ 1/8, both exactly; the result is (cos, sin) of 2πr
/// turned by q right angles. Arguments of 2⁴⁹ turns and more (and
/// non-finite ones) take the library's path.
#[inline]
pub fn cos_sin_turns(u: f64) -> (f64, f64) {
    let quarters = 4.0 * u;
    if quarters.is_nan() || quarters.abs() >= REDUCTION_LIMIT {
        let (sin, cos) = (std::f64::consts::TAU * u).sin_cos();
        return (cos, sin);
    }
    let shifted = quarters + ROUNDING_SHIFTER;
    let nearest = shifted - ROUNDING_SHIFTER;
    // Exact: `quarters` and `nearest` are multiples of quarters' ulp (or
    // equal, when that ulp exceeds 1), and |remainder| ≤ ½.
    let remainder = quarters - nearest;
    let (cos, sin) = cos_sin_eighth(remainder * FRAC_PI_2);
    // Turning by q right angles maps (c, s) to (c, s), (−s, c), (−c, −s),
    // (s, −c): a swap for odd q and sign flips, as bit masks (q is a coin
    // toss per sample, which a branch would mispredict).
    let q = shifted.to_bits() & 3;
    let swap = (q & 1).wrapping_neg();
    let (cos_bits, sin_bits) = (cos.to_bits(), sin.to_bits());
    let first = cos_bits ^ ((cos_bits ^ sin_bits) & swap);
    let second = sin_bits ^ ((cos_bits ^ sin_bits) & swap);
    let cos_sign = ((q ^ (q >> 1)) & 1) << 63;
    let sin_sign = (q >> 1) << 63;
    (f64::from_bits(first ^ cos_sign), f64::from_bits(second ^ sin_sign))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_4, TAU};

    /// Within `ulps` units in the last place of `expected`, counting from
    /// the ulp of 1 for values below it (an absolute 2⁻⁵³·ulps there: near
    /// a zero of sin or cos the reference's own error is absolute).
    fn close(actual: f64, expected: f64, ulps: f64) -> bool {
        let scale = expected.abs().max(1.0);
        (actual - expected).abs() <= ulps * scale * f64::EPSILON / 2.0
    }

    #[test]
    fn the_eighth_turn_kernel_matches_the_library() {
        let n = 200_000;
        for i in 0..=n {
            let x = FRAC_PI_4 * (2.0 * i as f64 / n as f64 - 1.0);
            let (cos, sin) = cos_sin_eighth(x);
            assert!(close(cos, x.cos(), 2.0), "cos {x}: {cos} against {}", x.cos());
            // sin x ~ x: measured relative to sin x itself.
            assert!((sin - x.sin()).abs() <= 2.0 * f64::EPSILON * x.sin().abs(), "sin {x}");
        }
        assert_eq!(cos_sin_eighth(0.0), (1.0, 0.0));
        // Odd and even: signs follow the argument exactly.
        let (c, s) = cos_sin_eighth(-0.3);
        assert_eq!((c, s), (cos_sin_eighth(0.3).0, -cos_sin_eighth(0.3).1));
    }

    #[test]
    fn turns_match_the_library_all_round_the_circle() {
        let n = 400_000;
        for i in 0..=n {
            let u = i as f64 / n as f64 + 1e-7 * (i % 7) as f64;
            let (cos, sin) = cos_sin_turns(u);
            let (library_sin, library_cos) = (TAU * u).sin_cos();
            // The library rounds 2πu first (half an ulp of up to 2π, an
            // absolute ≈ 4.4·10⁻¹⁶): both are within that of the truth.
            assert!(
                (cos - library_cos).abs() < 1e-15 && (sin - library_sin).abs() < 1e-15,
                "u = {u}"
            );
            assert!((cos * cos + sin * sin - 1.0).abs() < 4.0 * f64::EPSILON, "u = {u}");
        }
    }

    #[test]
    fn quarter_turns_are_exact_and_signs_follow_the_quadrant() {
        assert_eq!(cos_sin_turns(0.0), (1.0, 0.0));
        assert_eq!(cos_sin_turns(0.25), (-0.0, 1.0));
        assert_eq!(cos_sin_turns(0.5), (-1.0, -0.0));
        assert_eq!(cos_sin_turns(0.75), (0.0, -1.0));
        assert_eq!(cos_sin_turns(1.0), (1.0, 0.0));
        assert_eq!(cos_sin_turns(-0.25), (0.0, -1.0));
        // One sample per octant: the signs of (cos, sin) are the octant's.
        for octant in 0..8 {
            let u = (octant as f64 + 0.5) / 8.0;
            let (cos, sin) = cos_sin_turns(u);
            let angle = TAU * u;
            assert_eq!(
                (cos > 0.0, sin > 0.0),
                (angle.cos() > 0.0, angle.sin() > 0.0),
                "octant {octant}"
            );
        }
    }

    #[test]
    fn huge_and_non_finite_turns_take_the_library_path() {
        let u = 3.0e15;
        let (cos, sin) = cos_sin_turns(u);
        let (library_sin, library_cos) = (TAU * u).sin_cos();
        assert_eq!((cos.to_bits(), sin.to_bits()), (library_cos.to_bits(), library_sin.to_bits()));
        let (cos, sin) = cos_sin_turns(f64::NAN);
        assert!(cos.is_nan() && sin.is_nan());
        let (cos, sin) = cos_sin_turns(f64::INFINITY);
        assert!(cos.is_nan() && sin.is_nan());
    }
}
