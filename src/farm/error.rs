//! What can go wrong splitting, writing, reading and merging parts; every
//! error about a file names it.

use std::path::PathBuf;

/// Why a farm operation (splitting a render into parts, writing, reading or
/// merging film files) failed.
#[derive(Debug, thiserror::Error)]
pub enum FarmError {
    /// A `--part` or `--samples` value that does not parse or is out of range.
    #[error("{flag}: {message}")]
    Argument {
        /// The command-line flag, e.g. `--part`.
        flag: &'static str,
        /// What is wrong with its value.
        message: String,
    },
    /// A render that cannot be split into parts as asked.
    #[error("{0}")]
    CannotSplit(String),
    /// A file could not be read or written, or cannot be used as asked
    /// (a missing folder, a wrong extension; the message says which).
    #[error("{}: {message}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What failed, with the operating system's reason.
        message: String,
    },
    /// The file does not start with the film file's magic bytes
    /// (`PRISMFLM`); an empty file, for instance.
    #[error("{}: not a Prism film file ({message})", path.display())]
    NotAFilm {
        /// The file.
        path: PathBuf,
        /// What was found instead.
        message: String,
    },
    /// The film file was written by a Prism with another format version.
    #[error("{}: film format version {found}, but this Prism reads version {supported}", path.display())]
    Version {
        /// The file.
        path: PathBuf,
        /// The file's format version.
        found: u32,
        /// The one version this build reads and writes.
        supported: u32,
    },
    /// The file ends before its header or records do.
    #[error("{}: truncated: {message} (was it still being written, or cut short in transfer?)", path.display())]
    Truncated {
        /// The file.
        path: PathBuf,
        /// Which part is cut short.
        message: String,
    },
    /// The file is complete but its checksum, header or records are wrong.
    #[error("{}: corrupt: {message}", path.display())]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Two parts of different images.
    #[error(
        "{}: not a part of the same image as {}: {key} is {value} there but {other_value} here",
        path.display(),
        other.display()
    )]
    OtherImage {
        /// The part that does not match.
        path: PathBuf,
        /// The part (or parts) it was compared with.
        other: PathBuf,
        /// What differs: the image size, the planned samples per pixel, or
        /// a key of the header's image settings.
        key: String,
        /// Its value in `other`.
        value: String,
        /// Its value in `path`.
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
        /// One of the two parts.
        path: PathBuf,
        /// The other part.
        other: PathBuf,
        /// The image row (0 at the top) where they overlap.
        row: u32,
        /// The half-open sample range `path` holds in that row.
        range: (u32, u32),
        /// The half-open sample range `other` holds in that row.
        other_range: (u32, u32),
    },
    /// Samples no part holds (without `--allow-missing`).
    #[error("parts are missing: {0}\n(merge what is there with --allow-missing)")]
    Missing(String),
    /// A merge was asked for with no film files.
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
