//! Acceleration structures. The BVH knows only bounding boxes and leaf
//! ranges; what a leaf's primitives are, and how to hit them, is the
//! caller's closure.
//!
//! - [`build`]: the binned-SAH binary tree builder;
//! - [`collapse`]: which binary nodes become eight-wide nodes;
//! - [`bvh`]: the eight-wide tree collapsed from it, and its traversal;
//! - [`bounds`]: the outward-rounded single-precision boxes both use.

pub mod bounds;
pub mod build;
pub mod bvh;
pub mod collapse;

pub use build::LeafKind;
pub use bvh::{BuildPrimitive, Bvh, Leaf, TraversalRay};
