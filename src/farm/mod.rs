//! Render farms: one image split across machines, merged exactly.
//!
//! Every sample is a pure function of (pixel, sample index, dimension,
//! seed), and the film keeps its sums in integers (`crate::film`), so a
//! render split into shares (`crate::integrator::Share`) adds back up to the
//! very bits one machine would have produced:
//!
//! - [`part`]: which share a machine renders: `--part K/N`, `--part auto`
//!   from Slurm's or Kubernetes' environment, or `--samples A..B`; and the
//!   renders that cannot be split (time limits, SPPM's per-pixel radius);
//! - [`file`](mod@file): the film file, a versioned binary format holding a part's
//!   exact sums with a [`header`] saying what image it belongs to
//!   ([`content_hash`] of the scene, every setting that changes the image,
//!   the seed, the samples covered and Prism's version);
//! - [`coverage`]: which samples of which rows a set of parts holds:
//!   overlaps, gaps, what is missing;
//! - [`merge`]: `prism merge`: checks, then adds parts;
//! - [`watch`]: a folder of parts merged as they arrive (`prism view --watch`).
//!
//! The user's guide is docs/farm.md.

pub mod content_hash;
pub mod coverage;
pub mod error;
pub mod file;
pub mod header;
pub mod merge;
pub mod part;
pub mod watch;

pub use error::FarmError;
pub use file::{FILM_EXTENSION, is_film_path, read_film, read_header};
pub use header::FilmHeader;
pub use merge::{MergeOptions, Merged, merge_files};
pub use part::{PartRequest, plan_share};
