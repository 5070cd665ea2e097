//! Deterministic numerical integration: adaptive Simpson quadrature in one
//! dimension and, nested, over rectangles. The χ² sampling tests integrate
//! densities over histogram bins with it (as Nori's `chi2test` does), where
//! the integrand may be peaked (a glossy lobe) or jump (a cone's rim).

/// ∫ₐᵇ f(x) dx by adaptive Simpson quadrature: an interval is halved until
/// its two halves' Simpson estimates agree with the whole's to 15 × the
/// interval's share of `tolerance` (the error of the refined estimate is
/// about 1/15 of that difference, Lyness 1969), or `max_depth` halvings are
/// reached; the refined estimate is then Richardson-corrected.
///
/// Like any rule that samples the integrand, it can miss a feature narrower
/// than its first five points leave between them; subdivide such domains
/// first (as [`integrate_rectangle`]'s callers do by binning).
pub fn adaptive_simpson(f: &mut impl FnMut(f64) -> f64, a: f64, b: f64, tolerance: f64, max_depth: u32) -> f64 {
    let (fa, fm, fb) = (f(a), f(0.5 * (a + b)), f(b));
    let whole = simpson(a, b, fa, fm, fb);
    refine(f, Interval { a, b, fa, fm, fb }, whole, tolerance, max_depth)
}

/// ∫∫ f(x, y) dy dx over [x0, x1] × [y0, y1]: adaptive Simpson in x of the
/// adaptive Simpson integral in y, each to `tolerance` over its range (the
/// inner one scaled by the outer width, so the total error budget holds).
pub fn integrate_rectangle(
    f: &mut impl FnMut(f64, f64) -> f64,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    tolerance: f64,
    max_depth: u32,
) -> f64 {
    let inner_tolerance = tolerance / (x1 - x0).abs().max(f64::MIN_POSITIVE);
    let mut row = |x: f64| adaptive_simpson(&mut |y| f(x, y), y0, y1, inner_tolerance, max_depth);
    adaptive_simpson(&mut row, x0, x1, tolerance, max_depth)
}

/// An interval with its integrand values at both ends and the midpoint.
struct Interval {
    a: f64,
    b: f64,
    fa: f64,
    fm: f64,
    fb: f64,
}

fn simpson(a: f64, b: f64, fa: f64, fm: f64, fb: f64) -> f64 {
    (b - a) / 6.0 * (fa + 4.0 * fm + fb)
}

fn refine(f: &mut impl FnMut(f64) -> f64, i: Interval, whole: f64, tolerance: f64, depth: u32) -> f64 {
    let m = 0.5 * (i.a + i.b);
    let (left_mid, right_mid) = (0.5 * (i.a + m), 0.5 * (m + i.b));
    let (f_left, f_right) = (f(left_mid), f(right_mid));
    let left = simpson(i.a, m, i.fa, f_left, i.fm);
    let right = simpson(m, i.b, i.fm, f_right, i.fb);
    let difference = left + right - whole;
    if depth == 0 || difference.abs() <= 15.0 * tolerance {
        return left + right + difference / 15.0;
    }
    let left_interval = Interval {
        a: i.a,
        b: m,
        fa: i.fa,
        fm: f_left,
        fb: i.fm,
    };
    let right_interval = Interval {
        a: m,
        b: i.b,
        fa: i.fm,
        fm: f_right,
        fb: i.fb,
    };
    refine(f, left_interval, left, 0.5 * tolerance, depth - 1) + refine(f, right_interval, right, 0.5 * tolerance, depth - 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Smooth integrands with known integrals, to the requested tolerance
    /// (Simpson's error bound is conservative here, so 10× the tolerance is safe).
    #[test]
    fn smooth_integrals_reach_the_tolerance() {
        let sine = adaptive_simpson(&mut f64::sin, 0.0, PI, 1e-10, 30);
        assert!((sine - 2.0).abs() < 1e-9);
        let gaussian = adaptive_simpson(&mut |x: f64| (-x * x).exp(), -8.0, 8.0, 1e-10, 30);
        assert!((gaussian - PI.sqrt()).abs() < 1e-9);
        // ∫₀¹∫₀² x y² dy dx = ½ · 8/3: a cubic is integrated exactly at once.
        let mut evaluations = 0;
        let product = integrate_rectangle(
            &mut |x, y| {
                evaluations += 1;
                x * y * y
            },
            (0.0, 1.0),
            (0.0, 2.0),
            1e-12,
            30,
        );
        assert!((product - 4.0 / 3.0).abs() < 1e-12);
        assert!(evaluations <= 9 * 5, "{evaluations} evaluations for a polynomial");
    }

    /// A jump is refined towards, not smeared: the quarter disk's area to 1e-6,
    /// and a peak narrow against the domain (width 1e-2 in [−1, 1]) is found.
    #[test]
    fn discontinuities_and_peaks_are_refined() {
        let mut inside = |x: f64, y: f64| if x * x + y * y <= 1.0 { 1.0 } else { 0.0 };
        let quarter = integrate_rectangle(&mut inside, (0.0, 1.0), (0.0, 1.0), 1e-8, 24);
        assert!((quarter - PI / 4.0).abs() < 1e-6, "{quarter}");
        let width: f64 = 1e-2;
        let peak = adaptive_simpson(&mut |x: f64| width / (PI * (x * x + width * width)), -1.0, 1.0, 1e-10, 40);
        assert!((peak - 2.0 / PI * (1.0 / width).atan()).abs() < 1e-8, "{peak}");
    }
}
