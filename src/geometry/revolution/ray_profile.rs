//! The ray–profile polynomial of a surface of revolution, kept as its
//! factors for root isolation.
//!
//! In the rotated frame of `LocalRay`, where the ray is at height `y(t)`,
//! `D_z (o + s h) = a(t)` with `a(t) = h (y(t) − O_z) + D_z o`, and the
//! surface condition `(o + s h)² + δ² = x(t)²` becomes, multiplied by `D_z²`,
//!
//! `F(t) = a(t)² − D_z² (x(t)² − δ²) = 0`,
//!
//! that is `(D_x(y − O_z) + D_z O_x)² + (D_y(y − O_z) + D_z O_y)² = D_z² x²`
//! in a rotated frame: a polynomial of degree `2n` that never divides by `D_z`.
//!
//! Roots are isolated by Bernstein subdivision with Descartes' rule of signs
//! (`math::roots::isolate_roots`). The factors `a` and `x` (degree `n`) are
//! subdivided, not `F`: the coefficients of `F` on a small piece are formed
//! from the piece's own factors, so their error is relative to the piece's
//! size. Near-horizontal rays make `F` nearly a perfect square, `a² ≈ D_z² x²`,
//! and expanding it once on `[0, 1]` would lose every digit there. Isolated
//! roots are polished by safeguarded Newton on `F`. Pieces are sized to the
//! profile's degree (`N` coefficients), since they are copied at every split.

use super::local_ray::LocalRay;
use crate::geometry::bezier;
use crate::math::bernstein::{MAX_COEFFICIENTS, binomial_row};
use crate::math::gamma;
use crate::math::roots::PolynomialPiece;

// `F` has degree `2n` for a segment of degree `n`: it must fit the Bernstein
// coefficient buffers of root isolation.
const _: () = assert!(2 * bezier::MAX_DEGREE < MAX_COEFFICIENTS);

/// Smallest and largest of the coefficients.
pub(super) fn range(coefficients: &[f64]) -> (f64, f64) {
    // Plain comparisons rather than f64::min/max, whose NaN rule costs
    // extra instructions on this hot path; a NaN coefficient is skipped
    // either way (every comparison with it is false).
    let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
    for &c in coefficients {
        if c < low {
            low = c;
        }
        if c > high {
            high = c;
        }
    }
    (low, high)
}

/// `F = a² − D_z² (x − δ)(x + δ)` on a sub-interval of `t`, as its factors'
/// Bernstein coefficients there (see the module docs for why the factors).
#[derive(Clone, Copy, Debug)]
pub(super) struct RayProfilePiece<const N: usize> {
    pub(super) a: [f64; N],
    pub(super) x: [f64; N],
    pub(super) count: usize,
    /// Smallest and largest of the `a` and of the `x` coefficients.
    pub(super) a_range: (f64, f64),
    pub(super) x_range: (f64, f64),
    pub(super) dz_squared: f64,
    pub(super) across: f64,
    /// Width of the piece in `t`.
    pub(super) width: f64,
    /// Error bounds of the coefficients from subdivision.
    pub(super) a_error: f64,
    pub(super) x_error: f64,
    /// Bound on the rounding of the initial `a_i = h (y_i − O_z) + D_z o`.
    pub(super) a_rounding: f64,
}

/// Pieces of at most this many coefficients are built with exactly `N`
/// (see `Segment::intersect`), so their loops have bounds known at compile
/// time and unroll.
pub(super) const MAX_EXACT_SIZE: usize = 8;

impl<const N: usize> RayProfilePiece<N> {
    /// The number of coefficients of both factors.
    #[inline(always)]
    fn len(&self) -> usize {
        if N <= MAX_EXACT_SIZE { N } else { self.count.min(N) }
    }

    /// `F`'s Bernstein coefficient at an end of the piece, from the factors'
    /// coefficients there (`c_0 = a_0² − D_z² x_0² + D_z² δ²`, likewise `c_2n`).
    fn end_value(&self, a: f64, x: f64) -> f64 {
        (a * a - self.dz_squared * (x * x)) + self.dz_squared * self.across * self.across
    }

    /// `a`, `da/dτ`, `x` and `dx/dτ` at `τ`, by de Casteljau's algorithm on
    /// both factors at once (as `bernstein::evaluate_with_derivative`).
    fn factors_at(&self, tau: f64) -> (f64, f64, f64, f64) {
        let count = self.len();
        if count < 2 {
            return (self.a[0], 0.0, self.x[0], 0.0);
        }
        let (mut a, mut x) = (self.a, self.x);
        let s = 1.0 - tau;
        for width in (2..count).rev() {
            for i in 0..width {
                a[i] = s * a[i] + tau * a[i + 1];
                x[i] = s * x[i] + tau * x[i + 1];
            }
        }
        let degree = (count - 1) as f64;
        (
            s * a[0] + tau * a[1],
            degree * (a[1] - a[0]),
            s * x[0] + tau * x[1],
            degree * (x[1] - x[0]),
        )
    }

    /// A lower bound on the ray parameter `s` of every surface point this
    /// piece of the profile can hold (`−∞` if none can be given), so that a
    /// piece entirely beyond the nearest hit so far can be skipped.
    ///
    /// On the surface `D_z (o + s h) = a(t)` (the ray's height is `y(t)`), so
    /// `s = (a / D_z − o) / h` ranges over the convex hull of the piece's `a`
    /// coefficients; and `|o + s h| ≤ x(t)` (the ray's distance to the axis),
    /// so `s ≥ (−o − max x) / h`. Both bounds are widened by their rounding.
    pub(super) fn nearest_parameter(&self, ray: &LocalRay) -> f64 {
        let h = ray.horizontal_speed;
        if h <= 0.0 {
            return f64::NEG_INFINITY;
        }
        let dz = ray.direction.z;
        let (a_low, a_high) = self.a_range;
        let x_high = self.x_range.1;
        let a_slack = self.a_error + self.a_rounding + gamma(4) * a_low.abs().max(a_high.abs());
        let x_max = x_high + self.x_error + gamma(4) * x_high.abs();
        let o = ray.along.abs() + ray.frame_error;
        // Radial bound; its own rounding is a few ulps of the terms.
        let radial = (-ray.along - x_max) / h - gamma(4) * (o + x_max) / h;
        if dz == 0.0 {
            return radial;
        }
        let nearest_a = if dz > 0.0 { a_low - a_slack } else { a_high + a_slack };
        let a_over_dz = nearest_a / dz;
        let height = (a_over_dz - ray.along) / h - (gamma(4) * (a_over_dz.abs() + o) + ray.frame_error) / h;
        radial.max(height)
    }
}

impl<const N: usize> PolynomialPiece for RayProfilePiece<N> {
    fn coefficients(&self, out: &mut [f64; MAX_COEFFICIENTS]) -> (usize, f64) {
        let n = self.len() - 1;
        // Quick exclusion from the factors' ranges (convex hull): if
        // min a² − D_z²(max x² − δ²) > 0, or max a² − D_z²(min x² − δ²) < 0,
        // F keeps one sign; report two coefficients of that sign.
        let (a_low, a_high) = self.a_range;
        let (x_low, x_high) = self.x_range;
        let a_error = self.a_error + gamma(4) * a_high.abs().max(a_low.abs());
        let x_error = self.x_error + gamma(4) * x_high.abs().max(x_low.abs());
        let a_min = if a_low > a_error {
            a_low - a_error
        } else if a_high < -a_error {
            -a_high - a_error
        } else {
            0.0
        };
        let a_max = a_high.abs().max(a_low.abs()) + a_error;
        let x_min = if x_low > x_error { x_low - x_error } else { 0.0 };
        let x_max = x_high.abs().max(x_low.abs()) + x_error;
        let delta_squared = self.across * self.across;
        let slack = gamma(16) * (a_max * a_max + self.dz_squared * (x_max * x_max + delta_squared));
        let lowest = a_min * a_min - self.dz_squared * (x_max * x_max - delta_squared);
        let highest = a_max * a_max - self.dz_squared * (x_min * x_min - delta_squared);
        if lowest > slack || highest < -slack {
            let value = if lowest > slack { lowest } else { highest };
            out[0] = value;
            out[1] = value;
            return (2, 0.0);
        }
        // Scaled factors C(n,i) a_i, then c_k = Σ_{i+j=k} (…) / C(2n,k); the
        // sum is symmetric in i and j, so each pair i < j is formed once and
        // doubled (exact in binary).
        let count = self.len();
        let mut a_scaled = [0.0; N];
        let mut x_scaled = [0.0; N];
        for ((i, &weight), (a, x)) in binomial_row(n)
            .iter()
            .enumerate()
            .take(count)
            .zip(a_scaled.iter_mut().zip(&mut x_scaled))
        {
            *a = weight * self.a[i];
            *x = weight * self.x[i];
        }
        let (a_largest, x_largest) = (a_high.abs().max(a_low.abs()), x_high.abs().max(x_low.abs()));
        out[..=2 * n].fill(0.0);
        for i in 0..count {
            out[2 * i] += a_scaled[i] * a_scaled[i] - self.dz_squared * (x_scaled[i] * x_scaled[i]);
            for j in i + 1..count {
                out[i + j] += 2.0 * (a_scaled[i] * a_scaled[j] - self.dz_squared * (x_scaled[i] * x_scaled[j]));
            }
        }
        let constant = self.dz_squared * delta_squared;
        for (value, &weight) in out[..=2 * n].iter_mut().zip(binomial_row(2 * n)) {
            *value = *value / weight + constant;
        }
        // The ends exactly as `end_values` gives them.
        out[0] = self.end_value(self.a[0], self.x[0]);
        out[2 * n] = self.end_value(self.a[n], self.x[n]);
        // The weights C(n,i)C(n,j)/C(2n,k) sum to 1 over i + j = k
        // (Vandermonde), so each coefficient is a convex combination.
        let magnitude = a_largest * a_largest + self.dz_squared * (x_largest * x_largest + delta_squared);
        let error = gamma(2 * n as u32 + 8) * magnitude
            + 2.0 * a_largest * self.a_error
            + 2.0 * self.dz_squared * x_largest * self.x_error;
        (2 * n + 1, error)
    }

    fn end_values(&self) -> (f64, f64) {
        let n = self.len() - 1;
        (self.end_value(self.a[0], self.x[0]), self.end_value(self.a[n], self.x[n]))
    }

    fn split_half(&self) -> (Self, Self) {
        let mut left = *self;
        let mut right = *self;
        let count = self.len();
        // de Casteljau at ½ on both factors (as `bernstein::split`):
        // the left edge of the triangle is the left half, the right edge the
        // right half.
        let (mut a, mut x) = (self.a, self.x);
        for step in 0..count {
            let last = count - 1 - step;
            left.a[step] = a[0];
            left.x[step] = x[0];
            right.a[last] = a[last];
            right.x[last] = x[last];
            for i in 0..last {
                a[i] = 0.5 * a[i] + 0.5 * a[i + 1];
                x[i] = 0.5 * x[i] + 0.5 * x[i + 1];
            }
        }
        let a_largest = self.a_range.0.abs().max(self.a_range.1.abs());
        let x_largest = self.x_range.0.abs().max(self.x_range.1.abs());
        for half in [&mut left, &mut right] {
            half.a_range = range(&half.a[..count]);
            half.x_range = range(&half.x[..count]);
            half.width = 0.5 * self.width;
            half.a_error += gamma(count as u32) * a_largest;
            half.x_error += gamma(count as u32) * x_largest;
        }
        (left, right)
    }

    fn evaluate_with_derivative(&self, tau: f64) -> (f64, f64) {
        let (a, a_slope, x, x_slope) = self.factors_at(tau);
        let delta = self.across.abs();
        (
            a * a - self.dz_squared * ((x - delta) * (x + delta)),
            2.0 * (a * a_slope - self.dz_squared * x * x_slope),
        )
    }
}
