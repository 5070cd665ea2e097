//! Acceleration structures. The BVH knows only bounding boxes; what a leaf
//! primitive is, and how to hit it, is the caller's closure.

pub mod bvh;
mod sah;

pub use bvh::Bvh;
