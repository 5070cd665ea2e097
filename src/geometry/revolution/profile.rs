//! The parts of a surface of revolution: the Bezier segments of its profile,
//! each with its control points split into coordinate arrays, its bounding
//! cylinder and its area table, and the flat discs (caps) that may close its
//! ends.

use crate::geometry::bezier::MAX_CONTROL_POINTS;
use glam::DVec2;

/// One Bezier piece of the profile with its bounds and area table.
#[derive(Clone, Debug)]
pub(super) struct Segment {
    /// Control points `(x, y)`: distance from the axis, height.
    pub(super) points: Vec<DVec2>,
    /// The same coordinates as arrays, the Bernstein coefficients of `x(t)`
    /// and `y(t)` (zero beyond `degree`).
    pub(super) x: [f64; MAX_CONTROL_POINTS],
    pub(super) y: [f64; MAX_CONTROL_POINTS],
    pub(super) degree: usize,
    /// Bounding cylinder: largest `x`, and the range of `y`.
    pub(super) radius: f64,
    pub(super) z_min: f64,
    pub(super) z_max: f64,
    /// Largest `|y|` of the control points.
    pub(super) height_size: f64,
    /// Area swept by `t ∈ [0, k/AREA_BINS]`, `k = 0…AREA_BINS`.
    pub(super) area_table: Vec<f64>,
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
        let radius = points.iter().fold(0.0_f64, |m, p| m.max(p.x));
        let z_min = points.iter().fold(f64::INFINITY, |m, p| m.min(p.y));
        let z_max = points.iter().fold(f64::NEG_INFINITY, |m, p| m.max(p.y));
        let mut segment = Self {
            points,
            x,
            y,
            degree,
            radius,
            z_min,
            z_max,
            height_size: z_min.abs().max(z_max.abs()),
            area_table: Vec::new(),
        };
        segment.area_table = segment.tabulate_area();
        segment
    }
}
