//! Texture mappings: where on a picture (or pattern) a shading point falls.
//!
//! Every mapping returns coordinates in the image convention of
//! [`super::image`] (v = 0 at the bottom of the picture), then multiplied by
//! `scale` so a pattern can tile.

use crate::geometry::Sphere;
use crate::material::ShadingPoint;
use glam::{DMat3, DVec2, DVec3};
use std::f64::consts::{PI, TAU};

/// A projection followed by a per-axis tiling factor.
#[derive(Clone, Debug)]
pub struct Mapping {
    /// How the shading point becomes (u, v).
    pub projection: Projection,
    /// Repetitions per unit of the projected coordinates.
    pub scale: DVec2,
}

impl Default for Mapping {
    fn default() -> Self {
        Self {
            projection: Projection::Uv,
            scale: DVec2::ONE,
        }
    }
}

/// How a shading point becomes texture coordinates, before scaling.
#[derive(Clone, Debug)]
pub enum Projection {
    /// The shape's own parameterisation: a quad's [0, 1]², a mesh's OBJ uv,
    /// a revolution's (angle / 2π, t). Any shape has one.
    Uv,
    /// Equirectangular (longitude, latitude) of the direction from a centre,
    /// north (+y) at the top of the picture, longitude 0 towards +z.
    Sphere(SphereProjection),
    /// Affine coordinates in a parallelogram: `origin + a·edge_u + b·edge_v`
    /// maps to (a, b) whatever shape carries the point.
    Planar(PlanarProjection),
}

/// An equirectangular (latitude–longitude) projection, as for a globe.
#[derive(Clone, Debug)]
pub struct SphereProjection {
    /// World → globe rotation (the inverse of the globe's turn); `None` when unturned.
    pub to_globe: Option<DMat3>,
    /// Project from this point; `None` reads the direction off a Sphere
    /// shape's own uv, so one material serves spheres anywhere.
    pub center: Option<DVec3>,
}

impl SphereProjection {
    /// `rotation` turns the globe (world ← globe).
    pub fn new(rotation: Option<DMat3>, center: Option<DVec3>) -> Self {
        Self {
            to_globe: rotation.map(|r| r.transpose()),
            center,
        }
    }

    fn map(&self, at: &ShadingPoint) -> DVec2 {
        let shape_uv = match (self.center, self.to_globe) {
            // The Sphere shape already computed exactly this.
            (None, None) => at.uv,
            (None, Some(to_globe)) => Sphere::uv_of(to_globe * direction_of_sphere_uv(at.uv)),
            (Some(center), rotation) => {
                let d = (at.point - center).normalize_or_zero();
                Sphere::uv_of(rotation.map_or(d, |r| r * d))
            }
        };
        // Sphere uv has v = 0 at the north pole; pictures have v = 0 at the bottom.
        DVec2::new(shape_uv.x, 1.0 - shape_uv.y)
    }
}

/// Inverse of [`Sphere::uv_of`]: u = ½ + φ/2π, v = θ/π ⇒
/// d = (sin θ sin φ, cos θ, sin θ cos φ).
fn direction_of_sphere_uv(uv: DVec2) -> DVec3 {
    let longitude = (uv.x - 0.5) * TAU;
    let polar = uv.y * PI;
    let (sin_polar, cos_polar) = polar.sin_cos();
    DVec3::new(sin_polar * longitude.sin(), cos_polar, sin_polar * longitude.cos())
}

/// A projection onto a parallelogram's affine coordinates; see
/// [`Projection::Planar`].
#[derive(Clone, Debug)]
pub struct PlanarProjection {
    origin: DVec3,
    /// Dual basis of (edge_u, edge_v) within their plane: a = (p − origin)·dual_u.
    dual_u: DVec3,
    dual_v: DVec3,
}

impl PlanarProjection {
    /// `None` if the edges are parallel or zero.
    pub fn new(origin: DVec3, edge_u: DVec3, edge_v: DVec3) -> Option<Self> {
        // Solve the 2×2 Gram system so skewed parallelograms map exactly too;
        // the component along the normal is ignored.
        let (uu, uv, vv) = (edge_u.dot(edge_u), edge_u.dot(edge_v), edge_v.dot(edge_v));
        let det = uu * vv - uv * uv;
        if !(det.is_finite() && det > 1e-12 * uu * vv) {
            return None;
        }
        Some(Self {
            origin,
            dual_u: (vv * edge_u - uv * edge_v) / det,
            dual_v: (uu * edge_v - uv * edge_u) / det,
        })
    }

    fn map(&self, point: DVec3) -> DVec2 {
        let d = point - self.origin;
        DVec2::new(d.dot(self.dual_u), d.dot(self.dual_v))
    }
}

impl Mapping {
    /// The texture coordinates of `at`: the projection's (u, v), times
    /// `scale`.
    #[inline]
    pub fn map(&self, at: &ShadingPoint) -> DVec2 {
        let uv = match &self.projection {
            Projection::Uv => at.uv,
            Projection::Sphere(sphere) => sphere.map(at),
            Projection::Planar(plane) => plane.map(at.point),
        };
        uv * self.scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_uv_inverts_exactly() {
        for &d in &[
            DVec3::new(0.3, -0.5, 0.8),
            DVec3::new(-0.9, 0.1, -0.2),
            DVec3::new(0.0, 0.6, -0.8),
        ] {
            let d = d.normalize();
            // Round trip through trigonometric functions: a few ulps.
            assert!((direction_of_sphere_uv(Sphere::uv_of(d)) - d).length() < 1e-12);
        }
    }

    #[test]
    fn planar_recovers_skewed_coordinates() {
        let (origin, eu, ev) = (
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(1.0, 3.0, 0.0),
        );
        let plane = PlanarProjection::new(origin, eu, ev);
        let plane = plane.unwrap_or_else(|| panic!("edges are independent"));
        let p = origin + 0.3 * eu + 0.7 * ev + DVec3::new(0.0, 0.0, 5.0);
        assert!((plane.map(p) - DVec2::new(0.3, 0.7)).length() < 1e-12);
        assert!(PlanarProjection::new(origin, eu, 2.0 * eu).is_none());
    }
}
