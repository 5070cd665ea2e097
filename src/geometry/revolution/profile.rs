//! The parts of a surface of revolution: the Bezier segments of its profile,
//! each with its control points split into coordinate arrays, its arcs (the
//! segment cut into equal parameter ranges, each with its own control points
//! and bounding annulus), its bounding cylinder and its area table, and the
//! flat discs (caps) that may close its ends.

use super::ray_profile::range;
use crate::geometry::bezier::MAX_CONTROL_POINTS;
use crate::math::bernstein;
use crate::math::gamma;
use glam::DVec2;

/// How many times a curved segment is halved into arcs: 2³ = 8 arcs.
///
/// A ray crosses the thin annuli of two or three of them, so root isolation
/// starts on short arcs, where Descartes' rule decides at once, instead of
/// splitting the whole segment down to them for every ray; and the bounding
/// cylinder becomes the union of the arcs' annuli, which follows the curve
/// rather than its control polygon.
const ARC_HALVINGS: u32 = 3;

/// Most arcs a segment is cut into.
pub(super) const MAX_ARCS: usize = 1 << ARC_HALVINGS;

/// One Bezier piece of the profile with its bounds and area table.
#[derive(Clone, Debug)]
pub(super) struct Segment {
    /// Control points `(x, y)`: distance from the axis, height.
    pub(super) points: Vec<DVec2>,
    /// The heights as an array, the Bernstein coefficients of `y(t)` (zero
    /// beyond `degree`).
    pub(super) y: [f64; MAX_CONTROL_POINTS],
    pub(super) degree: usize,
    /// Bounding cylinder: the largest `r`, and the range of `z`, of its
    /// arcs' annuli (tighter than the control points' where they bulge).
    pub(super) radius: f64,
    pub(super) z_min: f64,
    pub(super) z_max: f64,
    /// Largest `|y|` of the control points.
    pub(super) height_size: f64,
    /// The segment cut into arcs, in order of `t` (one arc if it is straight).
    pub(super) arcs: Vec<Arc>,
    /// Area swept by `t ∈ [0, k/AREA_BINS]`, `k = 0…AREA_BINS`.
    pub(super) area_table: Vec<f64>,
}

/// The segment over `t ∈ [t0, t1]`, re-parameterised to `[0, 1]`: its
/// control points (by de Casteljau halving, within `x_error` and `y_error`
/// of the exact ones) and the annulus `inner_radius ≤ r ≤ radius`,
/// `z_min ≤ z ≤ z_max` that holds it (the convex hull of those control
/// points, widened by their error).
#[derive(Clone, Copy, Debug)]
pub(super) struct Arc {
    pub(super) t0: f64,
    pub(super) t1: f64,
    pub(super) x: [f64; MAX_CONTROL_POINTS],
    pub(super) y: [f64; MAX_CONTROL_POINTS],
    pub(super) x_error: f64,
    pub(super) y_error: f64,
    pub(super) inner_radius: f64,
    pub(super) radius: f64,
    pub(super) z_min: f64,
    pub(super) z_max: f64,
}

impl Arc {
    /// The arc of the control points `x`, `y` (`count` of them) over
    /// `[t0, t1]`, known to within `x_error` and `y_error`.
    fn new(
        t0: f64,
        t1: f64,
        x: [f64; MAX_CONTROL_POINTS],
        y: [f64; MAX_CONTROL_POINTS],
        count: usize,
        errors: (f64, f64),
    ) -> Self {
        let (x_error, y_error) = errors;
        let (x_low, x_high) = range(&x[..count]);
        let (y_low, y_high) = range(&y[..count]);
        Self {
            t0,
            t1,
            x,
            y,
            x_error,
            y_error,
            inner_radius: (x_low - x_error).max(0.0),
            radius: x_high + x_error,
            z_min: y_low - y_error,
            z_max: y_high + y_error,
        }
    }

    /// The two halves, `[t0, m]` and `[m, t1]`. Each de Casteljau level
    /// rounds an average of two coefficients, so a halving adds at most
    /// `γ(count)` times the largest coefficient to their error.
    fn halves(&self, count: usize) -> (Self, Self) {
        let (mut x_left, mut x_right) = ([0.0; MAX_CONTROL_POINTS], [0.0; MAX_CONTROL_POINTS]);
        let (mut y_left, mut y_right) = ([0.0; MAX_CONTROL_POINTS], [0.0; MAX_CONTROL_POINTS]);
        bernstein::split_half(&self.x[..count], &mut x_left, &mut x_right);
        bernstein::split_half(&self.y[..count], &mut y_left, &mut y_right);
        let largest = |values: &[f64], error: f64| values.iter().fold(0.0_f64, |m, v| m.max(v.abs())) + error;
        let errors = (
            self.x_error + gamma(count as u32) * largest(&self.x[..count], self.x_error),
            self.y_error + gamma(count as u32) * largest(&self.y[..count], self.y_error),
        );
        let middle = 0.5 * (self.t0 + self.t1);
        (
            Self::new(self.t0, middle, x_left, y_left, count, errors),
            Self::new(middle, self.t1, x_right, y_right, count, errors),
        )
    }
}

/// A flat disc closing one end of the profile.
#[derive(Clone, Copy, Debug)]
pub(super) struct Cap {
    /// Height of the disc and its radius.
    pub(super) z: f64,
    pub(super) radius: f64,
    /// `−1` for the start (faces `−z`), `+1` for the end.
    pub(super) side: f64,
}

impl Segment {
    /// A segment of the control points `points` (validated by `Revolution::new`).
    pub(super) fn new(points: Vec<DVec2>) -> Self {
        let degree = points.len() - 1;
        let mut x = [0.0; MAX_CONTROL_POINTS];
        let mut y = [0.0; MAX_CONTROL_POINTS];
        for (i, p) in points.iter().enumerate() {
            x[i] = p.x;
            y[i] = p.y;
        }
        let height_size = points.iter().fold(0.0_f64, |m, p| m.max(p.y.abs()));
        let mut arcs = vec![Arc::new(0.0, 1.0, x, y, degree + 1, (0.0, 0.0))];
        if degree > 1 {
            for _ in 0..ARC_HALVINGS {
                arcs = arcs
                    .iter()
                    .flat_map(|arc| {
                        let (left, right) = arc.halves(degree + 1);
                        [left, right]
                    })
                    .collect();
            }
        }
        let radius = arcs.iter().fold(0.0_f64, |m, arc| m.max(arc.radius));
        let z_min = arcs.iter().fold(f64::INFINITY, |m, arc| m.min(arc.z_min));
        let z_max = arcs.iter().fold(f64::NEG_INFINITY, |m, arc| m.max(arc.z_max));
        let mut segment = Self {
            points,
            y,
            degree,
            radius,
            z_min,
            z_max,
            height_size,
            arcs,
            area_table: Vec::new(),
        };
        segment.area_table = segment.tabulate_area();
        segment
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::bezier;

    /// Every point of the curve lies in the annulus of the arc that holds
    /// its parameter, and the bounding cylinder follows the curve: the
    /// vase of `scenes/vase.toml` reaches `r ≈ 2.973` while its control
    /// points reach 7.
    #[test]
    fn arcs_hold_the_curve_and_hug_it() {
        let profiles = [
            vec![[0.0, 0.0], [7.0, 0.4], [0.0, 5.0], [0.2, 5.5], [2.6, 7.5]],
            vec![[0.0, 0.0], [1.2, 0.1], [0.3, 0.9], [0.9, 1.4], [0.5, 2.0]],
            vec![[1.0, -1.0], [1.0, 1.0]],
            vec![[0.0, 0.0], [0.5, 0.0], [1.0, 2.0]],
        ];
        for profile in profiles {
            let points: Vec<DVec2> = profile.iter().map(|&[x, y]| DVec2::new(x, y)).collect();
            let segment = Segment::new(points.clone());
            assert_eq!(segment.arcs.len(), if points.len() == 2 { 1 } else { MAX_ARCS });
            let mut largest = 0.0_f64;
            for i in 0..=20_000 {
                let t = i as f64 / 20_000.0;
                let point = bezier::evaluate(&points, t);
                largest = largest.max(point.x);
                let holding: Vec<&Arc> = segment.arcs.iter().filter(|arc| arc.t0 <= t && t <= arc.t1).collect();
                assert!(!holding.is_empty() && holding.len() <= 2, "t = {t}");
                for arc in holding {
                    assert!(
                        arc.inner_radius <= point.x && point.x <= arc.radius && arc.z_min <= point.y && point.y <= arc.z_max,
                        "{points:?} at t = {t}: {point} outside {arc:?}"
                    );
                }
            }
            let control_radius = points.iter().fold(0.0_f64, |m, p| m.max(p.x));
            assert!(segment.radius >= largest);
            assert!(
                segment.radius - largest <= 0.02 * control_radius,
                "{points:?}: cylinder radius {} against the curve's {largest}",
                segment.radius
            );
        }
    }
}
