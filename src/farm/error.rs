//! What can go wrong splitting, writing, reading and merging parts; every
//! error about a file names it.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum FarmError {
    /// A `--part` or `--samples` value that does not parse or is out of range.
    #[error("{flag}: {message}")]
    Argument { flag: &'static str, message: String },
    /// A render that cannot be split into parts as asked.
    #[error("{0}")]
    CannotSplit(String),
    #[error("{}: {message}", path.display())]
    Io { path: PathBuf, message: String },
    #[error("{}: not a Prism film file ({message})", path.display())]
    NotAFilm { path: PathBuf, message: String },
    #[error("{}: film format version {found}, but this Prism reads version {supported}", path.display())]
    Version { path: PathBuf, found: u32, supported: u32 },
    #[error("{}: truncated: {message} (was it still being written, or cut short in transfer?)", path.display())]
    Truncated { path: PathBuf, message: String },
    #[error("{}: corrupt: {message}", path.display())]
    Corrupt { path: PathBuf, message: String },
    /// Two parts of different images.
    #[error(
        "{}: not a part of the same image as {}: {key} is {value} there but {other_value} here",
        path.display(),
        other.display()
    )]
    OtherImage {
        path: PathBuf,
        other: PathBuf,
        key: String,
        value: String,
        other_value: String,
    },
    /// Two parts hold the same samples of a row.
    #[error(
        "{}: samples {}..{} of row {row} are also in {} (samples {}..{}): parts overlap",
        path.display(),
        range.0,
        range.1,
        other.display(),
        other_range.0,
        other_range.1
    )]
    Overlap {
        path: PathBuf,
        other: PathBuf,
        row: u32,
        range: (u32, u32),
        other_range: (u32, u32),
    },
    /// Samples no part holds (without `--allow-missing`).
    #[error("parts are missing: {0}\n(merge what is there with --allow-missing)")]
    Missing(String),
    #[error("no film files to merge")]
    NoParts,
}

impl FarmError {
    /// An I/O error about `path`.
    pub fn io(path: &std::path::Path, error: impl std::fmt::Display) -> Self {
        FarmError::Io {
            path: path.to_path_buf(),
            message: error.to_string(),
        }
    }
}
