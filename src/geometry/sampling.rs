//! Sampling a surface as seen from a reference point: the result every
//! shape's `sample_from` returns, and the change of measure from area to
//! solid angle that all but the sphere use.

use super::hit::AreaSample;
use glam::DVec3;

/// A point chosen on a surface as seen from a reference point.
#[derive(Clone, Copy, Debug)]
pub struct ShapeSample {
    /// The chosen surface point, world space.
    pub point: DVec3,
    /// Conservative absolute error bound of `point`, per axis.
    pub point_error: DVec3,
    /// Unit outward normal at `point`.
    pub normal: DVec3,
    /// |`point` − the reference point|, to within `point_error` (a sphere
    /// gives the distance along its sampled direction). A ray aimed along
    /// (`point` − reference) / `distance` reaches `point` at t = `distance`.
    pub distance: f64,
    /// Density per unit solid angle at the reference point.
    pub pdf: f64,
}

/// A uniform area sample turned into a solid-angle sample: the density
/// 1/A per unit area is d²/(|cos θ| A) per unit solid angle, θ the angle
/// between the surface normal and the direction to the reference.
pub fn by_area(sample: AreaSample, area: f64, reference: DVec3) -> Option<ShapeSample> {
    let to_surface = sample.point - reference;
    let distance_squared = to_surface.length_squared();
    let distance = distance_squared.sqrt();
    // d²/(|cos θ| A) with |cos θ| = |n·(p − x)|/d is d³/(|n·(p − x)| A):
    // after the square root, a product and one division, where the cosine
    // of the normalised direction took a reciprocal, a product and a dot
    // product before the density's division. (Coordinates are at most 10¹²,
    // so d³ stays far inside the range of f64.)
    let projected = sample.normal.dot(to_surface).abs();
    if projected == 0.0 || distance_squared == 0.0 {
        return None;
    }
    Some(ShapeSample {
        point: sample.point,
        point_error: sample.point_error,
        normal: sample.normal,
        distance,
        pdf: distance_squared * distance / (projected * area),
    })
}

/// The density of [`by_area`] for the surface point `point` with normal
/// `normal`, per unit solid angle at `reference`.
pub fn pdf_by_area(area: f64, reference: DVec3, point: DVec3, normal: DVec3) -> f64 {
    let to_surface = point - reference;
    let distance_squared = to_surface.length_squared();
    // As in `by_area`: d³/(|n·(p − x)| A).
    let projected = normal.dot(to_surface).abs();
    if projected == 0.0 {
        return 0.0;
    }
    distance_squared * distance_squared.sqrt() / (projected * area)
}
