//! Shapes: the closed set of surfaces a ray can hit, dispatched by `match`
//! (no virtual call per ray). Every shape answers the same questions:
//! nearest hit (distance, normals, uv), bounds, area, and uniform area sampling.

pub mod axis_box;
pub mod bezier;
pub mod hit;
pub mod mesh;
pub mod quad;
pub mod revolution;
pub mod sphere;
pub mod transform;
pub mod triangle;

pub use axis_box::AxisBox;
pub use hit::{AreaSample, SurfaceHit};
pub use mesh::Mesh;
pub use quad::Quad;
pub use revolution::Revolution;
pub use sphere::Sphere;
pub use transform::Transform;
pub use triangle::Triangle;

use crate::math::{Aabb, Ray};
use glam::DVec2;

/// One intersectable surface.
#[derive(Clone, Debug)]
pub enum Shape {
    Sphere(Sphere),
    Triangle(Triangle),
    AxisBox(AxisBox),
    Quad(Quad),
    /// Boxed: it carries its profile and sampling tables.
    Revolution(Box<Revolution>),
}

impl Shape {
    pub fn bounds(&self) -> Aabb {
        match self {
            Shape::Sphere(s) => s.bounds(),
            Shape::Triangle(t) => t.bounds(),
            Shape::AxisBox(b) => b.bounds,
            Shape::Quad(q) => q.bounds(),
            Shape::Revolution(r) => r.bounds(),
        }
    }

    pub fn area(&self) -> f64 {
        match self {
            Shape::Sphere(s) => s.area(),
            Shape::Triangle(t) => t.area(),
            Shape::AxisBox(b) => b.area(),
            Shape::Quad(q) => q.area(),
            Shape::Revolution(r) => r.area(),
        }
    }

    /// Nearest hit in `(0, t_max)`; `meshes` supplies triangles' shading data.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f64, meshes: &[Mesh]) -> Option<SurfaceHit> {
        match self {
            Shape::Sphere(s) => s.intersect(ray, t_max),
            Shape::Triangle(t) => {
                let hit = t.intersect_raw(ray, t_max)?;
                Some(t.surface_hit(&hit, &meshes[t.mesh as usize]))
            }
            Shape::AxisBox(b) => b.intersect(ray, t_max),
            Shape::Quad(q) => q.intersect(ray, t_max),
            Shape::Revolution(r) => r.intersect(ray, t_max),
        }
    }

    /// Distance to the nearest hit only: triangles skip their shading lookup.
    #[inline]
    pub fn hit_distance(&self, ray: &Ray, t_max: f64) -> Option<f64> {
        match self {
            Shape::Triangle(t) => t.intersect_raw(ray, t_max).map(|h| h.t),
            Shape::Sphere(s) => s.intersect(ray, t_max).map(|h| h.t),
            Shape::AxisBox(b) => b.intersect(ray, t_max).map(|h| h.t),
            Shape::Quad(q) => q.intersect(ray, t_max).map(|h| h.t),
            Shape::Revolution(r) => r.intersect(ray, t_max).map(|h| h.t),
        }
    }

    /// Uniform point on the surface, density `1 / area()`.
    pub fn sample_area(&self, u: DVec2) -> AreaSample {
        match self {
            Shape::Sphere(s) => s.sample_area(u),
            Shape::Triangle(t) => t.sample_area(u),
            Shape::AxisBox(b) => b.sample_area(u),
            Shape::Quad(q) => q.sample_area(u),
            Shape::Revolution(r) => r.sample_area(u),
        }
    }
}
