//! Small numeric building blocks shared by every module: rays with robust
//! origins, bounding boxes, orthonormal shading frames, sampling warps, and
//! polynomials in Bernstein form with their real-root isolation.
//!
//! Prism works in `f64` throughout. The classic smallpt room is built from
//! spheres of radius 1e5 whose surfaces sit a few units from the camera; in
//! `f32` their hit points carry errors larger than the room's details.

pub mod aabb;
pub mod bernstein;
pub mod frame;
pub mod ray;
pub mod roots;
pub mod warp;

pub use aabb::Aabb;
pub use frame::Frame;
pub use ray::{Ray, gamma, offset_ray_origin};

pub use glam::{DVec2, DVec3};

/// Largest component of a vector.
pub fn max_component(v: DVec3) -> f64 {
    v.x.max(v.y).max(v.z)
}
