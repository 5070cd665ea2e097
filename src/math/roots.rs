//! Real roots of a polynomial on `[0, 1]` by Bernstein subdivision.
//!
//! Two properties of the Bernstein form (`math::bernstein`) carry the method:
//! - the graph lies in the convex hull of its coefficients, so if every
//!   coefficient has the same sign there is no root (de Casteljau's
//!   subdivision keeps this true on every sub-interval);
//! - Descartes' rule of signs holds in Bernstein form: the number of roots in
//!   the open interval is at most the number of sign variations `V` of the
//!   coefficients and has the same parity, so `V = 1` proves exactly one root
//!   (Lane and Riesenfeld 1981; Mourrain, Rouillier and Roy 2005).
//!
//! `isolate_roots` splits until one of them decides each piece, with
//! floating-point error bounds on the coefficients so a sign is trusted only
//! when it exceeds its error. A piece with `V = 1` and end values of opposite
//! sign is polished with safeguarded Newton iteration (Newton inside a
//! shrinking bisection bracket, so it always converges). Pieces narrower than
//! a minimum width that still may hold a root are reported as clusters
//! (double or nearly double roots, tangencies).
//!
//! The polynomial is seen through [`PolynomialPiece`], so a caller may keep
//! it in factored form (as the surface of revolution keeps `a² − D_z² x²` as
//! `a` and `x`) and form coefficients piece by piece; [`BernsteinPiece`] is
//! the plain case.

use crate::math::bernstein::{self, MAX_COEFFICIENTS};
use crate::math::gamma;

/// Number of sign changes in the sequence, skipping exact zeros.
pub fn sign_variations(coefficients: &[f64]) -> usize {
    let mut previous = 0.0;
    let mut variations = 0;
    for &c in coefficients.iter().filter(|c| **c != 0.0) {
        if previous != 0.0 && (c > 0.0) != (previous > 0.0) {
            variations += 1;
        }
        previous = c;
    }
    variations
}

/// A polynomial restricted to a parameter interval, as root isolation sees
/// it. The local parameter `τ ∈ [0, 1]` maps linearly onto the interval.
pub trait PolynomialPiece: Sized {
    /// Writes the Bernstein coefficients over this piece into `out` and
    /// returns their count and an absolute bound on their rounding error.
    fn coefficients(&self, out: &mut [f64; MAX_COEFFICIENTS]) -> (usize, f64);
    /// The values at `τ = 0` and `τ = 1`: the first and last Bernstein
    /// coefficients, bit for bit what `coefficients` would write there, but
    /// without forming the others.
    fn end_values(&self) -> (f64, f64);
    /// The two halves `τ ∈ [0, ½]` and `[½, 1]`.
    fn split_half(&self) -> (Self, Self);
    /// The polynomial and its `τ`-derivative at local parameter `τ`.
    fn evaluate_with_derivative(&self, tau: f64) -> (f64, f64);
}

/// One root (or cluster of roots) found by `isolate_roots`.
#[derive(Clone, Copy, Debug)]
pub struct IsolatedRoot {
    /// Local parameter in the piece that holds the root.
    pub tau: f64,
    /// Global parameter in `[0, 1]`.
    pub t: f64,
    /// Half-width of the interval of `t` known to hold the root.
    pub t_uncertainty: f64,
    /// The root could not be separated from its neighbours (a tangency).
    pub is_cluster: bool,
}

/// Upper limit on the pieces one call examines: a polynomial that vanishes
/// identically would otherwise be split down to the minimum width everywhere.
const PIECE_BUDGET: usize = 4096;

/// Finds every real root of the piece's polynomial in `τ ∈ [0, 1]`
/// (mapped to `t ∈ [t0, t1]`) and reports each, left to right, to `on_root`
/// with the piece that holds it. Pieces narrower than `minimum_width` (in
/// `t`) that may still hold roots are reported once as a cluster at their
/// midpoint, as is a piece on which the polynomial is zero within its
/// error bound.
///
/// `skip` is asked about every piece before it is examined; a piece for
/// which it answers `true` is dropped with its roots. A nearest-hit search
/// uses it to drop pieces whose roots can only be farther than the best hit
/// found so far (its answer may change as roots are reported).
pub fn isolate_roots<P: PolynomialPiece>(
    piece: &P,
    t0: f64,
    t1: f64,
    minimum_width: f64,
    skip: &mut impl FnMut(&P) -> bool,
    on_root: &mut impl FnMut(&P, IsolatedRoot),
) {
    let (start, end) = piece.end_values();
    // Roots exactly at the ends of the whole interval; inner split points are
    // reported where they are created.
    if start == 0.0 {
        on_root(piece, exact_root(0.0, t0, t0, t1));
    }
    let mut budget = PIECE_BUDGET;
    isolate_recursive(piece, t0, t1, minimum_width, &mut budget, skip, on_root);
    if end == 0.0 {
        on_root(piece, exact_root(1.0, t1, t0, t1));
    }
}

fn exact_root(tau: f64, t: f64, t0: f64, t1: f64) -> IsolatedRoot {
    IsolatedRoot {
        tau,
        t,
        t_uncertainty: f64::EPSILON * (t0.abs() + t1.abs()),
        is_cluster: false,
    }
}

fn isolate_recursive<P: PolynomialPiece>(
    piece: &P,
    t0: f64,
    t1: f64,
    minimum_width: f64,
    budget: &mut usize,
    skip: &mut impl FnMut(&P) -> bool,
    on_root: &mut impl FnMut(&P, IsolatedRoot),
) {
    if *budget == 0 || skip(piece) {
        return;
    }
    *budget -= 1;
    let mut buffer = [0.0; MAX_COEFFICIENTS];
    let (count, error) = piece.coefficients(&mut buffer);
    if count == 0 {
        return;
    }
    let coefficients = &buffer[..count];
    let (first, last) = (coefficients[0], coefficients[count - 1]);

    // Step 1: discard the piece if every coefficient (ignoring exact zeros at
    // the ends, which are roots at the ends reported elsewhere) has a certain
    // sign, the same for all.
    let leading_zeros = coefficients.iter().take_while(|&&c| c == 0.0).count();
    let trailing_zeros = coefficients[leading_zeros..].iter().rev().take_while(|&&c| c == 0.0).count();
    let inner = &coefficients[leading_zeros..count - trailing_zeros];
    let all_positive = inner.iter().all(|&c| c > error);
    let all_negative = inner.iter().all(|&c| c < -error);
    if inner.is_empty() || all_positive || all_negative {
        return;
    }
    let width = t1 - t0;

    // Step 2: the polynomial is zero within its error on the whole piece (a
    // tangency below the rounding level, or a ray running inside the
    // surface): one cluster for the whole piece, no further splitting.
    if inner.iter().all(|&c| c.abs() <= error) {
        on_root(
            piece,
            IsolatedRoot {
                tau: 0.5,
                t: t0 + 0.5 * width,
                t_uncertainty: 0.5 * width,
                is_cluster: true,
            },
        );
        return;
    }

    // Step 3: exactly one root, bracketed by end values of opposite sign.
    if sign_variations(coefficients) == 1 && first * last < 0.0 {
        let (tau, tau_uncertainty) = polish_root(piece, first, last, error);
        on_root(
            piece,
            IsolatedRoot {
                tau,
                t: t0 + tau * width,
                t_uncertainty: tau_uncertainty * width + f64::EPSILON * t1.abs(),
                is_cluster: false,
            },
        );
        return;
    }

    // Step 4: too narrow to split further: a cluster of roots or a tangency.
    let middle = t0 + 0.5 * width;
    if width <= minimum_width || middle <= t0 || middle >= t1 {
        on_root(
            piece,
            IsolatedRoot {
                tau: 0.5,
                t: middle,
                t_uncertainty: 0.5 * width,
                is_cluster: true,
            },
        );
        return;
    }

    // Step 5: split in half and recurse, left first; a root exactly at the
    // split point is reported once, here.
    let (left, right) = piece.split_half();
    isolate_recursive(&left, t0, middle, minimum_width, budget, skip, on_root);
    if right.end_values().0 == 0.0 {
        on_root(&right, exact_root(0.0, middle, t0, t1));
    }
    isolate_recursive(&right, middle, t1, minimum_width, budget, skip, on_root);
}

/// Safeguarded Newton iteration on `τ ∈ [0, 1]` where `p(0) = value_at_0` and
/// `p(1) = value_at_1` have opposite signs (Numerical Recipes' `rtsafe`):
/// a Newton step is taken when it stays inside the bracket and at least
/// halves the previous step, otherwise the bracket is bisected.
///
/// `noise` bounds the rounding error of an evaluated `p`. Where `|p(τ)|` is
/// below it the sign of `p` carries no information: such a value does not
/// move the bracket, and once Newton's steps stop shrinking there the
/// iteration ends, since bisecting on noisy signs (down to the last bit, as
/// plain `rtsafe` would) cannot improve the root. Returns the root and the
/// size of the last step (or the bracket, if smaller) as its uncertainty;
/// an answer that ends in the noise is first confirmed (`confirm_in_noise`).
fn polish_root<P: PolynomialPiece>(piece: &P, value_at_0: f64, value_at_1: f64, noise: f64) -> (f64, f64) {
    let (mut low, mut high) = (0.0_f64, 1.0_f64);
    let low_is_negative = value_at_0 < 0.0;
    // Start from the secant (regula falsi) point, well inside the bracket.
    let mut tau = (value_at_0 / (value_at_0 - value_at_1)).clamp(0.05, 0.95);
    let mut previous_step = 1.0_f64;
    for _ in 0..200 {
        let (value, derivative) = piece.evaluate_with_derivative(tau);
        let in_noise = value.abs() <= noise;
        if !in_noise {
            if (value < 0.0) == low_is_negative {
                low = tau;
            } else {
                high = tau;
            }
        }
        let newton = tau - value / derivative;
        let step_ok = newton.is_finite() && newton > low && newton < high && (newton - tau).abs() < 0.5 * previous_step;
        if in_noise && (value == 0.0 || !step_ok) {
            let step = if newton.is_finite() {
                (newton - tau).abs()
            } else {
                high - low
            };
            let claimed = claimed_uncertainty(step, (low, high));
            return (
                tau,
                confirm_in_noise(piece, tau, claimed, derivative, (low, high), low_is_negative, noise),
            );
        }
        let next = if step_ok { newton } else { 0.5 * (low + high) };
        let step = (next - tau).abs();
        previous_step = step;
        tau = next;
        // Converged: the step is at the rounding level of τ, or the bracket
        // has closed.
        if step <= 2.0 * f64::EPSILON * tau.abs().max(f64::MIN_POSITIVE) || high - low <= 4.0 * f64::EPSILON {
            let claimed = claimed_uncertainty(step, (low, high));
            if !in_noise {
                return (tau, claimed);
            }
            // τ moved by a few ulps since `derivative` was taken.
            return (
                tau,
                confirm_in_noise(piece, tau, claimed, derivative, (low, high), low_is_negative, noise),
            );
        }
    }
    (tau, (tau - low).max(high - tau))
}

/// The uncertainty a Newton step of size `step` claims for its root: twice
/// the step, at least a few ulps, at most the bracket.
fn claimed_uncertainty(step: f64, (low, high): (f64, f64)) -> f64 {
    (2.0 * step).max(4.0 * f64::EPSILON).min(high - low)
}

/// A certified uncertainty for a root `τ` found where `|p|` is below
/// `noise`: the smallest tried `u` for which the values at `τ ± u` (or the
/// bracket's ends, already certain) have the bracket's signs beyond the
/// noise. The piece holds one root, which then lies between them. The
/// first `u` tried is the larger of `claimed` and twice the width of the
/// noise band, `noise / |p'(τ)|` (`derivative` is `p'` at or next to `τ`); each next one four times the last; the
/// last resort is the bracket.
///
/// Newton's last step measures how far the iteration moved, not where the
/// root is: where `p` stays within its noise over a long stretch (the
/// nearly double roots of a ray almost tangent to a surface), an answer can
/// land far from the root, on the wrong side of a nearby second one.
fn confirm_in_noise<P: PolynomialPiece>(
    piece: &P,
    tau: f64,
    claimed: f64,
    derivative: f64,
    (low, high): (f64, f64),
    low_is_negative: bool,
    noise: f64,
) -> f64 {
    let has_sign = |at: f64, negative: bool| {
        let (value, _) = piece.evaluate_with_derivative(at);
        value.abs() > noise && (value < 0.0) == negative
    };
    let bracket = (tau - low).max(high - tau);
    let band = 2.0 * noise / derivative.abs();
    let mut trial = if band.is_finite() { claimed.max(band) } else { bracket };
    while trial < bracket {
        let (left, right) = (tau - trial, tau + trial);
        if (left <= low || has_sign(left, low_is_negative)) && (right >= high || has_sign(right, !low_is_negative)) {
            return trial;
        }
        trial *= 4.0;
    }
    bracket
}

/// A plain Bernstein polynomial as a `PolynomialPiece`, carrying the error
/// bound accumulated by subdivision.
#[derive(Clone, Copy, Debug)]
pub struct BernsteinPiece {
    coefficients: [f64; MAX_COEFFICIENTS],
    count: usize,
    error: f64,
}

impl BernsteinPiece {
    /// A piece over `[0, 1]` whose coefficients are known to within `error`.
    pub fn new(coefficients: &[f64], error: f64) -> Self {
        assert!(!coefficients.is_empty() && coefficients.len() <= MAX_COEFFICIENTS);
        let mut stored = [0.0; MAX_COEFFICIENTS];
        stored[..coefficients.len()].copy_from_slice(coefficients);
        Self {
            coefficients: stored,
            count: coefficients.len(),
            error,
        }
    }

    /// The coefficients over this piece.
    pub fn coefficient_slice(&self) -> &[f64] {
        &self.coefficients[..self.count]
    }
}

impl PolynomialPiece for BernsteinPiece {
    fn coefficients(&self, out: &mut [f64; MAX_COEFFICIENTS]) -> (usize, f64) {
        out[..self.count].copy_from_slice(self.coefficient_slice());
        (self.count, self.error)
    }

    fn end_values(&self) -> (f64, f64) {
        (self.coefficients[0], self.coefficients[self.count - 1])
    }

    fn split_half(&self) -> (Self, Self) {
        let mut left = *self;
        let mut right = *self;
        bernstein::split_half(self.coefficient_slice(), &mut left.coefficients, &mut right.coefficients);
        // Each level adds at most n roundings of averages of the coefficients.
        let largest = self.coefficient_slice().iter().fold(0.0_f64, |m, c| m.max(c.abs()));
        let added = gamma(self.count as u32) * largest;
        left.error += added;
        right.error += added;
        (left, right)
    }

    fn evaluate_with_derivative(&self, tau: f64) -> (f64, f64) {
        bernstein::evaluate_with_derivative(self.coefficient_slice(), tau)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bernstein coefficients of `Π (t − r_i)`, built by products of linear factors.
    fn from_roots(roots: &[f64]) -> Vec<f64> {
        let mut result = vec![1.0];
        for &root in roots {
            let mut next = vec![0.0; result.len() + 1];
            bernstein::product(&result, &[-root, 1.0 - root], &mut next);
            result = next;
        }
        result
    }

    fn roots_of(coefficients: &[f64]) -> Vec<IsolatedRoot> {
        let mut found = Vec::new();
        let error = gamma(4 * coefficients.len() as u32) * coefficients.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
        isolate_roots(
            &BernsteinPiece::new(coefficients, error),
            0.0,
            1.0,
            1e-13,
            &mut |_| false,
            &mut |_, root| found.push(root),
        );
        found
    }

    #[test]
    fn isolates_close_simple_roots() {
        let roots = [0.1, 0.1 + 1e-6, 0.5, 0.99];
        let found = roots_of(&from_roots(&roots));
        assert_eq!(found.len(), 4, "{found:?}");
        for (root, expected) in found.iter().zip(roots) {
            assert!(!root.is_cluster);
            // The pair 1e-6 apart has slope ≈ 4e-7: rounding of 1e-17 in the
            // value moves its roots by ≈ 1e-11.
            assert!((root.t - expected).abs() < 1e-10, "{} vs {expected}", root.t);
        }
    }

    #[test]
    fn finds_roots_at_the_ends_and_at_split_points() {
        let found = roots_of(&from_roots(&[0.0, 0.5, 1.0]));
        let ts: Vec<f64> = found.iter().map(|r| r.t).collect();
        assert_eq!(ts, vec![0.0, 0.5, 1.0]);
    }

    #[test]
    fn reports_a_double_root_as_a_cluster() {
        let found = roots_of(&from_roots(&[0.3, 0.3, 0.8]));
        assert!(found.iter().any(|r| r.is_cluster && (r.t - 0.3).abs() < 1e-7), "{found:?}");
        assert!(found.iter().any(|r| !r.is_cluster && (r.t - 0.8).abs() < 1e-15));
    }

    #[test]
    fn rootless_polynomials_report_nothing() {
        assert!(roots_of(&[1.0, -0.2, 0.9]).is_empty()); // minimum 0.35 > 0
        assert!(roots_of(&from_roots(&[-0.5, 1.5])).is_empty());
    }

    /// A root found where the polynomial is within its noise comes with an
    /// interval that holds it: near a triple root `8 (τ − 0.3)³` with noise
    /// 0.01 the values stay in the noise over `|τ − 0.3| ≲ 0.11`, and
    /// Newton stops there at 0.199 with a last step of 0.034, which once made
    /// `[0.132, 0.266]` the claimed interval. Then odd powers of random
    /// roots, scales and noise levels.
    #[test]
    fn roots_polished_in_the_noise_lie_within_their_uncertainty() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = move || (crate::math::xorshift64(&mut state) >> 11) as f64 / (1u64 << 53) as f64;
        let mut cases = vec![(0.3, 3, 8.0, 0.01)];
        for _ in 0..3000 {
            let power = [1, 3, 5][(uniform() * 3.0) as usize % 3];
            let scale = 10f64.powf(8.0 * uniform() - 4.0);
            let noise = scale * 10f64.powf(-12.0 + 10.0 * uniform());
            cases.push((0.02 + 0.96 * uniform(), power, scale, noise));
        }
        let mut checked = 0;
        for (root, power, scale, noise) in cases {
            let mut coefficients = from_roots(&vec![root; power]);
            coefficients.iter_mut().for_each(|c| *c *= scale);
            let (first, last) = (coefficients[0], coefficients[power]);
            // Root isolation polishes only brackets whose ends are beyond the noise.
            if first.abs() <= noise || last.abs() <= noise {
                continue;
            }
            let piece = BernsteinPiece::new(&coefficients, noise);
            let (tau, uncertainty) = polish_root(&piece, first, last, noise);
            assert!(
                (tau - root).abs() <= uncertainty,
                "root {root} of power {power}, scale {scale:e}, noise {noise:e}: {tau} ± {uncertainty}"
            );
            checked += 1;
        }
        assert!(checked > 2500, "{checked}");
    }
}
