//! Polynomials in Bernstein form on `[0, 1]`: evaluation and derivative (de
//! Casteljau), subdivision, products and powers, on coefficient slices.
//!
//! A polynomial of degree `n` is stored as its Bernstein coefficients
//! `c_0 … c_n`, `p(t) = Σ c_k C(n,k) t^k (1−t)^(n−k)` (Farin, "Curves and
//! Surfaces for CAGD", ch. 5). The values at the ends are `c_0` and `c_n`
//! exactly, and the graph lies in the convex hull of the points
//! `(k/n, c_k)`; `math::roots` isolates real roots from those two facts.

/// Highest degree handled: the square of a coordinate of a Bezier segment of
/// the highest degree `geometry::bezier` allows (15), so `2 · 15`.
pub const MAX_DEGREE: usize = 30;
/// Most coefficients a polynomial may have, `MAX_DEGREE + 1`.
pub const MAX_COEFFICIENTS: usize = MAX_DEGREE + 1;

/// Pascal's triangle up to row `MAX_DEGREE`; every entry is exact in `f64`.
const BINOMIAL: [[f64; MAX_COEFFICIENTS]; MAX_COEFFICIENTS] = binomial_table();

const fn binomial_table() -> [[f64; MAX_COEFFICIENTS]; MAX_COEFFICIENTS] {
    let mut table = [[0.0; MAX_COEFFICIENTS]; MAX_COEFFICIENTS];
    let mut n = 0;
    while n < MAX_COEFFICIENTS {
        table[n][0] = 1.0;
        let mut k = 1;
        while k <= n {
            table[n][k] = table[n - 1][k - 1] + if k < n { table[n - 1][k] } else { 0.0 };
            k += 1;
        }
        n += 1;
    }
    table
}

/// The binomial coefficient `C(n, k)` for `n ≤ MAX_DEGREE`.
pub fn binomial(n: usize, k: usize) -> f64 {
    if k > n { 0.0 } else { BINOMIAL[n][k] }
}

/// Row `n ≤ MAX_DEGREE` of Pascal's triangle, `C(n, k)` for every `k`
/// (zero beyond `k = n`), for loops that need a whole row.
pub fn binomial_row(n: usize) -> &'static [f64; MAX_COEFFICIENTS] {
    &BINOMIAL[n]
}

/// `p(t)` by de Casteljau's algorithm (backward stable, Farouki and Rajan 1987).
pub fn evaluate(coefficients: &[f64], t: f64) -> f64 {
    evaluate_with_derivative(coefficients, t).0
}

/// `p(t)` and `p'(t)`; the derivative is `n (b₁ − b₀)` at the last level.
pub fn evaluate_with_derivative(coefficients: &[f64], t: f64) -> (f64, f64) {
    let count = coefficients.len();
    assert!(
        count <= MAX_COEFFICIENTS,
        "Bernstein polynomial of degree above {}",
        MAX_COEFFICIENTS - 1
    );
    if count == 0 {
        return (0.0, 0.0);
    }
    if count == 1 {
        return (coefficients[0], 0.0);
    }
    let mut level = [0.0; MAX_COEFFICIENTS];
    level[..count].copy_from_slice(coefficients);
    let s = 1.0 - t;
    for width in (2..count).rev() {
        for i in 0..width {
            level[i] = s * level[i] + t * level[i + 1];
        }
    }
    let degree = (count - 1) as f64;
    (s * level[0] + t * level[1], degree * (level[1] - level[0]))
}

/// Splits at `t = ½`: `left` and `right` receive the coefficients over
/// `[0, ½]` and `[½, 1]`, each re-parameterised to `[0, 1]`.
pub fn split_half(coefficients: &[f64], left: &mut [f64], right: &mut [f64]) {
    split(coefficients, 0.5, left, right);
}

/// Splits at `t` (de Casteljau's triangle: its left edge is the left piece,
/// its right edge the right piece).
pub fn split(coefficients: &[f64], t: f64, left: &mut [f64], right: &mut [f64]) {
    let count = coefficients.len();
    assert!(count <= MAX_COEFFICIENTS && left.len() >= count && right.len() >= count);
    let mut level = [0.0; MAX_COEFFICIENTS];
    level[..count].copy_from_slice(coefficients);
    let s = 1.0 - t;
    for step in 0..count {
        left[step] = level[0];
        right[count - 1 - step] = level[count - 1 - step];
        for i in 0..count - 1 - step {
            level[i] = s * level[i] + t * level[i + 1];
        }
    }
}

/// Product of two Bernstein polynomials of degrees `m` and `n` into `out`
/// (length `m + n + 1`):
/// `c_k = Σ_{i+j=k} C(m,i) C(n,j) a_i b_j / C(m+n,k)` (Farouki and Rajan 1988).
pub fn product(a: &[f64], b: &[f64], out: &mut [f64]) {
    let (m, n) = (a.len() - 1, b.len() - 1);
    assert!(m + n < MAX_COEFFICIENTS && out.len() > m + n);
    out[..=m + n].fill(0.0);
    for (i, &ai) in a.iter().enumerate() {
        let weighted = ai * binomial(m, i);
        for (j, &bj) in b.iter().enumerate() {
            out[i + j] += weighted * binomial(n, j) * bj;
        }
    }
    for (k, value) in out[..=m + n].iter_mut().enumerate() {
        *value /= binomial(m + n, k);
    }
}

/// `p^k` in Bernstein form (degree `k n`, at most `MAX_DEGREE`).
pub fn power(coefficients: &[f64], power: usize) -> Vec<f64> {
    let mut result = vec![1.0];
    for _ in 0..power {
        let mut next = vec![0.0; result.len() + coefficients.len() - 1];
        product(&result, coefficients, &mut next);
        result = next;
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binomials_match_pascal() {
        assert_eq!(binomial(4, 2), 6.0);
        assert_eq!(binomial(30, 15), 155_117_520.0);
        assert_eq!(binomial(3, 5), 0.0);
    }

    #[test]
    fn products_and_powers_evaluate_as_products() {
        let a = [0.3, -1.0, 2.0];
        let b = [1.0, 0.5, -0.25, 4.0];
        let mut product_coefficients = [0.0; 6];
        product(&a, &b, &mut product_coefficients);
        let cube = power(&a, 3);
        for t in [0.0, 0.2, 0.7, 1.0] {
            let (pa, pb) = (evaluate(&a, t), evaluate(&b, t));
            assert!((evaluate(&product_coefficients, t) - pa * pb).abs() < 1e-14);
            assert!((evaluate(&cube, t) - pa * pa * pa).abs() < 1e-14);
        }
    }

    #[test]
    fn derivative_matches_finite_difference() {
        let c = [0.3, -1.0, 2.0, 0.1, -0.7];
        let (_, derivative) = evaluate_with_derivative(&c, 0.37);
        let h = 1e-6;
        let numeric = (evaluate(&c, 0.37 + h) - evaluate(&c, 0.37 - h)) / (2.0 * h);
        assert!((derivative - numeric).abs() < 1e-8);
    }
}
