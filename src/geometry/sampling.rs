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
    /// |`point` − the reference point|.
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
    // One square root for the direction and the distance the caller needs
    // (`to_surface * (1 / distance)` is `normalize`'s own arithmetic).
    let distance = distance_squared.sqrt();
    let cos_surface = sample.normal.dot(-(to_surface * (1.0 / distance))).abs();
    if cos_surface == 0.0 || distance_squared == 0.0 {
        return None;
    }
    Some(ShapeSample {
        point: sample.point,
        point_error: sample.point_error,
        normal: sample.normal,
        distance,
        pdf: distance_squared / (cos_surface * area),
    })
}

/// The density of [`by_area`] for the surface point `point` with normal
/// `normal`, per unit solid angle at `reference`.
pub fn pdf_by_area(area: f64, reference: DVec3, point: DVec3, normal: DVec3) -> f64 {
    let to_surface = point - reference;
    let distance_squared = to_surface.length_squared();
    let cos_surface = normal.dot(to_surface.normalize()).abs();
    if cos_surface == 0.0 {
        return 0.0;
    }
    distance_squared / (cos_surface * area)
}
