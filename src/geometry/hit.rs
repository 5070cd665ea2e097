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
