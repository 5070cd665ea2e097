//! Planar Bezier curves: evaluation and derivative (de Casteljau), the
//! hodograph, subdivision, and the direction of travel where the derivative
//! vanishes. A curve is its control points `P_0 … P_n`,
//! `c(t) = Σ P_k C(n,k) t^k (1−t)^(n−k)` (Farin, "Curves and Surfaces for
//! CAGD", ch. 5); each coordinate is a polynomial in Bernstein form
//! (`math::bernstein`).

use crate::math::gamma;
use glam::DVec2;

/// Most control points one Bezier segment may have.
pub const MAX_CONTROL_POINTS: usize = 16;
/// Highest degree of a segment's curve.
pub const MAX_DEGREE: usize = MAX_CONTROL_POINTS - 1;

/// The point of the curve at `t` (de Casteljau).
pub fn evaluate(points: &[DVec2], t: f64) -> DVec2 {
    evaluate_with_derivative(points, t).0
}

/// The point and the first derivative `dc/dt` at `t`. The derivative comes
/// from the last de Casteljau level: `c'(t) = n (b₁ − b₀)` (Farin, eq. 5.20).
pub fn evaluate_with_derivative(points: &[DVec2], t: f64) -> (DVec2, DVec2) {
    let count = points.len().min(MAX_CONTROL_POINTS);
    let mut level = [DVec2::ZERO; MAX_CONTROL_POINTS];
    level[..count].copy_from_slice(&points[..count]);
    if count == 1 {
        return (level[0], DVec2::ZERO);
    }
    for width in (2..count).rev() {
        for i in 0..width {
            level[i] = level[i].lerp(level[i + 1], t);
        }
    }
    let degree = (count - 1) as f64;
    (level[0].lerp(level[1], t), degree * (level[1] - level[0]))
}

/// Control points of the derivative curve (the hodograph), `n (P_{i+1} − P_i)`.
pub fn hodograph(points: &[DVec2]) -> Vec<DVec2> {
    let degree = points.len().saturating_sub(1) as f64;
    points.windows(2).map(|pair| degree * (pair[1] - pair[0])).collect()
}

/// Splits the curve at `t` into the control polygons of `[0, t]` and `[t, 1]`.
pub fn split(points: &[DVec2], t: f64) -> (Vec<DVec2>, Vec<DVec2>) {
    let mut level = points.to_vec();
    let mut left = Vec::with_capacity(points.len());
    let mut right = Vec::with_capacity(points.len());
    while let Some(&first) = level.first() {
        left.push(first);
        right.push(*level.last().unwrap_or(&first));
        level = level.windows(2).map(|pair| pair[0].lerp(pair[1], t)).collect();
    }
    right.reverse();
    (left, right)
}

/// Unit direction of travel of the curve at `t`, also where `c'(t) = 0`.
///
/// If the first `k − 1` derivatives vanish at `t₀`, Taylor's theorem gives
/// `c'(t) ≈ c⁽ᵏ⁾(t₀) (t − t₀)^(k−1) / (k−1)!`, so the direction is that of the
/// first non-zero derivative, reversed for odd `k − 1` when the curve arrives
/// at `t₀` from below (we take the side inside `[0, 1]`: from below at
/// `t > ½`). `None` only for a curve collapsed to one point.
pub fn tangent_direction(points: &[DVec2], t: f64) -> Option<DVec2> {
    let size = points.iter().fold(0.0_f64, |m, p| m.max(p.abs().max_element()));
    let degree = points.len().saturating_sub(1);
    // Common case first, without building the hodographs.
    let (_, first_derivative) = evaluate_with_derivative(points, t);
    let first_noise = gamma(4 * MAX_CONTROL_POINTS as u32) * 2.0 * degree as f64 * size;
    if first_derivative.length() > first_noise {
        return Some(first_derivative.normalize());
    }
    let mut derivative_points = hodograph(points);
    let mut order = 1;
    // Scale of the k-th derivative's control points, n!/(n−k)! · 2^k · size.
    let mut scale = size;
    while !derivative_points.is_empty() {
        scale *= 2.0 * (degree + 1 - order) as f64;
        let derivative = evaluate(&derivative_points, t);
        // Below this the derivative is rounding noise of differences of points.
        let noise = gamma(4 * MAX_CONTROL_POINTS as u32) * scale;
        if derivative.length() > noise {
            let from_below = t > 0.5 && order % 2 == 0;
            let direction = derivative.normalize();
            return Some(if from_below { -direction } else { direction });
        }
        derivative_points = hodograph(&derivative_points);
        order += 1;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn de_casteljau_matches_power_form() {
        // Cubic with control points on y = t³ in Bernstein form: (0, 0, 0, 1).
        let points = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(3.0, 1.0),
        ];
        for t in [0.0, 0.25, 0.5, 0.9, 1.0] {
            let (point, derivative) = evaluate_with_derivative(&points, t);
            assert!((point - DVec2::new(3.0 * t, t * t * t)).length() < 1e-15);
            assert!((derivative - DVec2::new(3.0, 3.0 * t * t)).length() < 1e-14);
        }
    }

    #[test]
    fn split_pieces_reproduce_the_curve() {
        let points = [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 1.0),
            DVec2::new(-1.0, 3.0),
            DVec2::new(1.0, 1.0),
        ];
        let (left, right) = split(&points, 0.3);
        for u in [0.0, 0.4, 1.0] {
            assert!((evaluate(&left, u) - evaluate(&points, 0.3 * u)).length() < 1e-14);
            assert!((evaluate(&right, u) - evaluate(&points, 0.3 + 0.7 * u)).length() < 1e-14);
        }
    }

    #[test]
    fn tangent_of_a_curve_with_repeated_end_points_uses_the_next_derivative() {
        let points = [
            DVec2::new(0.0, 0.0),
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(1.0, 1.0),
        ];
        assert!((tangent_direction(&points, 0.0).expect("defined") - DVec2::X).length() < 1e-15);
        assert!((tangent_direction(&points, 1.0).expect("defined") - DVec2::Y).length() < 1e-15);
        assert!(tangent_direction(&[DVec2::ONE, DVec2::ONE], 0.5).is_none());
    }
}
