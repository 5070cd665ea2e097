//! Shapes: the closed set of surfaces a ray can hit, dispatched by `match`
//! (no virtual call per ray). Every shape answers the same questions:
//! nearest hit (distance, normals, uv), bounds, area, uniform area sampling,
//! and sampling as seen from a reference point, with its density per unit
//! solid angle (pbrt-v4's `Shape::Sample(ctx, u)` and `PDF(ctx, wi)`):
//! lights only choose and weight, the shape knows its own best sampling.
//!
//! The scene stores triangles apart from this enum, in the BVH's leaf order
//! ([`triangles`]); `Shape::Triangle` describes one on its way there.

pub mod axis_box;
pub mod ball_optics;
pub mod bezier;
pub mod clipped_sphere;
pub mod hit;
pub mod mesh;
pub mod quad;
pub mod revolution;
pub mod sampling;
pub mod sphere;
pub mod spheres;
pub mod transform;
pub mod triangle;
pub mod triangles;

pub use axis_box::AxisBox;
pub use ball_optics::{BallOptics, BallPath, Bounce};
pub use clipped_sphere::ClippedSphere;
pub use hit::{AreaSample, ShapeHit, SurfaceHit};
pub use mesh::Mesh;
pub use quad::Quad;
pub use revolution::Revolution;
pub use sampling::ShapeSample;
pub use sphere::Sphere;
pub use transform::Transform;
pub use triangle::Triangle;

use crate::math::{Aabb, Ray};
use glam::{DVec2, DVec3};

/// One intersectable surface.
#[derive(Clone, Debug)]
pub enum Shape {
    /// A sphere (exact, not tessellated).
    Sphere(Sphere),
    /// A single triangle; meshes become many of these until the scene moves
    /// them into [`triangles::Triangles`].
    Triangle(Triangle),
    /// A solid axis-aligned box.
    AxisBox(AxisBox),
    /// A parallelogram, the usual area light.
    Quad(Quad),
    /// Boxed: it carries its profile and sampling tables.
    Revolution(Box<Revolution>),
}

impl Shape {
    /// World-space bounds, for the BVH.
    pub fn bounds(&self) -> Aabb {
        match self {
            Shape::Sphere(s) => s.bounds(),
            Shape::Triangle(t) => t.bounds(),
            Shape::AxisBox(b) => b.bounds,
            Shape::Quad(q) => q.bounds(),
            Shape::Revolution(r) => r.bounds(),
        }
    }

    /// Surface area in square scene units; uniform area sampling has density
    /// `1 / area()`.
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
    #[inline(always)]
    pub fn hit_distance(&self, ray: &Ray, t_max: f64) -> Option<f64> {
        match self {
            Shape::Triangle(t) => t.intersect_raw(ray, t_max).map(|h| h.t),
            Shape::Sphere(s) => s.hit_distance(ray, t_max),
            Shape::AxisBox(b) => b.hit_distance(ray, t_max),
            Shape::Quad(q) => q.hit_distance(ray, t_max),
            Shape::Revolution(r) => r.hit_distance(ray, t_max),
        }
    }

    /// Nearest hit in `(0, t_max)` as the test found it, without its
    /// record: for comparing candidates, then [`Shape::surface_hit`] for
    /// the nearest.
    #[inline(always)]
    pub fn nearest_hit(&self, ray: &Ray, t_max: f64) -> Option<ShapeHit> {
        match self {
            Shape::Quad(q) => q.solve(ray, t_max).map(|(t, a, b)| ShapeHit::Quad { t, a, b }),
            Shape::Sphere(s) => s.hit_distance(ray, t_max).map(ShapeHit::Sphere),
            Shape::AxisBox(b) => b.solve(ray, t_max).map(|(axis, t)| ShapeHit::AxisBox { t, axis }),
            Shape::Triangle(_) | Shape::Revolution(_) => self.hit_distance(ray, t_max).map(ShapeHit::Distance),
        }
    }

    /// The record of a hit [`Shape::nearest_hit`] found on this shape,
    /// the same as [`Shape::intersect`] would report for it: it is built
    /// from the test's own results, or (for other shapes) by the same test
    /// again with the bound just above the hit, which finds the same hit.
    /// Without `with_uv` a sphere's texture coordinates are left (0, 0).
    // Always inlined: compiled into each copy of the path loop (baseline,
    // AVX2: `accel::kernel`) rather than called from it in baseline code.
    #[inline(always)]
    pub fn surface_hit(&self, ray: &Ray, hit: ShapeHit, meshes: &[Mesh], with_uv: bool) -> Option<SurfaceHit> {
        match (self, hit) {
            (Shape::Quad(q), ShapeHit::Quad { t, a, b }) => Some(q.surface_hit(t, a, b)),
            (Shape::Sphere(s), ShapeHit::Sphere(t)) if with_uv => Some(s.hit_at(ray.at(t), t)),
            (Shape::Sphere(s), ShapeHit::Sphere(t)) => Some(s.hit_at_without_uv(ray.at(t), t)),
            (Shape::AxisBox(b), ShapeHit::AxisBox { t, axis }) => Some(b.surface_hit(ray, axis, t)),
            _ => self.intersect(ray, hit.t().next_up(), meshes),
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

    /// A point on the surface as seen from `reference`, with its density
    /// per unit solid angle there: spheres sample the cone they subtend,
    /// every other shape its area.
    pub fn sample_from(&self, reference: DVec3, u: DVec2) -> Option<ShapeSample> {
        match self {
            Shape::Sphere(s) => s.sample_from(reference, u),
            // The usual area light, without two more dispatches and calls.
            Shape::Quad(q) => sampling::by_area(q.sample_area(u), q.area(), reference),
            _ => sampling::by_area(self.sample_area(u), self.area(), reference),
        }
    }

    /// The solid-angle density with which [`Shape::sample_from`] at
    /// `reference` would produce the surface point `point` (normal `normal`).
    pub fn pdf_from(&self, reference: DVec3, point: DVec3, normal: DVec3) -> f64 {
        match self {
            Shape::Sphere(s) => s.pdf_from(reference, point, normal),
            _ => sampling::pdf_by_area(self.area(), reference, point, normal),
        }
    }
}
