//! What an intersection reports, and what area sampling returns.

use glam::{DVec2, DVec3};

/// The nearest intersection of a ray with one shape.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    /// Ray parameter of the hit (the ray direction is unit length).
    pub t: f64,
    /// Hit position in world space.
    pub point: DVec3,
    /// Conservative absolute error bound of `point`, per axis.
    pub point_error: DVec3,
    /// Unit normal of the true surface, pointing outward as the shape defines it.
    pub geometric_normal: DVec3,
    /// Unit normal used for shading (interpolated on meshes), on the same side
    /// as `geometric_normal`.
    pub shading_normal: DVec3,
    /// Surface parameterisation, for textures.
    pub uv: DVec2,
}

/// A shape's nearest hit as its test found it: the distance and what the
/// hit record is made from, so the record can be built once, for the
/// nearest of all candidates, without repeating the test.
#[derive(Clone, Copy, Debug)]
pub enum ShapeHit {
    /// A sphere at distance `t`.
    Sphere(f64),
    /// A quad at distance `t`, at `a` along `edge_u` and `b` along `edge_v`.
    Quad {
        /// Ray parameter of the hit.
        t: f64,
        /// Coordinate along `edge_u`, in [0, 1].
        a: f64,
        /// Coordinate along `edge_v`, in [0, 1].
        b: f64,
    },
    /// An axis-aligned box at distance `t`, on a face normal to `axis`.
    AxisBox {
        /// Ray parameter of the hit.
        t: f64,
        /// Axis of the face hit.
        axis: usize,
    },
    /// Any other shape: the distance alone (its record is found by testing again).
    Distance(f64),
}

impl ShapeHit {
    /// Ray parameter of the hit.
    #[inline(always)]
    pub fn t(&self) -> f64 {
        match *self {
            ShapeHit::Sphere(t) | ShapeHit::Quad { t, .. } | ShapeHit::AxisBox { t, .. } | ShapeHit::Distance(t) => t,
        }
    }
}

/// A point drawn on a shape's surface.
#[derive(Clone, Copy, Debug)]
pub struct AreaSample {
    /// Position on the surface, world space.
    pub point: DVec3,
    /// Conservative absolute error bound of `point`, per axis (for
    /// [`crate::math::Ray::spawn`]).
    pub point_error: DVec3,
    /// Unit outward normal at `point`. (No texture coordinates: emission is
    /// not textured, and a sphere's would cost an atan2 and an acos.)
    pub normal: DVec3,
}
