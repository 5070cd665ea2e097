//! Acceleration structures. The BVH knows only bounding boxes and leaf
//! ranges; what a leaf's primitives are, and how to hit them, is the
//! caller's [`LeafVisitor`].
//!
//! - [`build`]: the binned-SAH binary tree builder;
//! - [`collapse`]: which binary nodes become eight-wide nodes;
//! - [`bvh`]: the eight-wide tree collapsed from it;
//! - [`traversal`]: the tree's front-to-back traversal, with the caller's leaf tests compiled in;
//! - [`bounds`]: the outward-rounded single-precision boxes both use;
//! - [`kernel`]: which instructions the queries run with, chosen at run time;
//! - [`quad_packets`]: four rays at a time against a scene of a few quads, without a tree;
//! - `huge_pages`: large arrays asked onto 2 MiB pages;
//! - `slab_test`: the conservative box test of a node's children.

pub mod bounds;
pub mod build;
pub mod bvh;
pub mod collapse;
pub(crate) mod huge_pages;
pub mod kernel;
pub mod quad_packets;
mod slab_test;
pub mod traversal;

pub use build::LeafKind;
pub use bvh::{BuildPrimitive, Bvh, Leaf};
pub use kernel::{Avx2, Kernel};
pub use quad_packets::{QuadPackets, RayLanes};
pub use slab_test::TraversalRay;
pub use traversal::{Dispatched, LeafVisitor, Portable, Traversal};
