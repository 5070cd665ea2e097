//! Prism: a physically based renderer you watch converge.
//!
//! Data flows one way:
//! scene file → [`scene::description`] (plain data with spans) →
//! [`scene::Scene`] (shapes, materials, lights, BVH; frozen) →
//! an [`integrator::Integrator`] (path tracing or SPPM) rendering passes →
//! [`film::Frame`] → image file ([`output`]), viewer texture or benchmark error
//! (the viewer may show a [`denoise`]d copy; the film is never filtered).
//! [`render::ProgressiveRender`] is the one progressive driver the CLI, the
//! viewer and the benchmarks share. [`farm`] splits a render across machines
//! and merges the parts' films exactly.

// Only the run-time choice of AVX2 kernels may use `unsafe` (commented
// calls into code compiled for AVX2, in src/accel/kernel.rs,
// src/accel/slab_test.rs, src/geometry/triangles/lanes/avx2.rs and
// src/geometry/spheres/mod.rs).
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod accel;
pub mod bench;
pub mod camera;
pub mod color;
pub mod denoise;
pub mod farm;
pub mod film;
pub mod geometry;
pub mod input_file;
pub mod integrator;
pub mod light;
pub mod material;
pub mod math;
pub mod metrics;
pub mod output;
pub mod render;
pub mod sampler;
pub mod scene;
pub mod settings;
pub mod spectrum;
#[cfg(feature = "viewer")]
pub mod viewer;
