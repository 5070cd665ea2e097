//! Small numeric building blocks shared by every module: rays with robust
//! origins, bounding boxes, orthonormal shading frames, sampling warps,
//! polynomials in Bernstein form with their real-root isolation; and the
//! statistics that check sampling code against its densities (incomplete
//! gamma, adaptive quadrature, χ² goodness-of-fit tests). Those live in the
//! library, not only in tests/, because the checks sit beside the code they
//! test (warps here, BSDFs in `material`, shapes in `geometry`).
//!
//! Prism works in `f64` throughout. The classic smallpt room is built from
//! spheres of radius 1e5 whose surfaces sit a few units from the camera; in
//! `f32` their hit points carry errors larger than the room's details.

pub mod aabb;
#[cfg(target_arch = "x86_64")]
pub mod avx_lanes;
pub mod bernstein;
pub mod chi_square;
pub mod frame;
pub mod gamma;
pub mod lane_mask;
pub mod quadrature;
pub mod ray;
pub mod roots;
pub mod trig;
pub mod warp;

pub use aabb::Aabb;
pub use frame::Frame;
pub use ray::{Ray, gamma, offset_ray_origin};

pub use glam::{DVec2, DVec3};

/// One step of Marsaglia's xorshift64 (shifts 13, 7, 17): the fixed
/// pseudo-random sequences of unit tests. `state` must not be zero.
#[cfg(test)]
pub(crate) fn xorshift64(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}

/// Largest component of a vector.
pub fn max_component(v: DVec3) -> f64 {
    v.x.max(v.y).max(v.z)
}
