//! `prism merge`: parts in, one film out, exactly as one machine would have
//! rendered it. Everything that can be checked without reading the parts
//! whole (same image, no overlaps, nothing missing) is checked first; then
//! each part is read, checksummed and added; the caller writes the result
//! only if all of that succeeded.

use super::FarmError;
use super::coverage::{Coverage, Missing};
use super::file::{add_film_file, read_header};
use super::header::FilmHeader;
use crate::film::Film;
use std::path::PathBuf;

/// How strict a merge is.
#[derive(Clone, Copy, Debug, Default)]
pub struct MergeOptions {
    /// Merge what is there even if samples are missing (else an error lists them).
    pub allow_missing: bool,
}

/// The result of a merge.
#[derive(Clone, Debug)]
pub struct Merged {
    /// The merged film's header: the parts' image, their coverage joined.
    pub header: FilmHeader,
    /// The parts' samples summed, pixel by pixel.
    pub film: Film,
    /// Samples held, over all pixels.
    pub samples_held: u64,
    /// Samples the complete image holds: the planned samples per pixel
    /// times the pixel count.
    pub samples_expected: u64,
    /// What no part holds (empty unless allowed).
    pub missing: Missing,
}

/// Checks and merges the film files `paths`.
pub fn merge_files(paths: &[PathBuf], options: MergeOptions) -> Result<Merged, FarmError> {
    // Headers first: refuse another image, overlaps and gaps before reading
    // any part whole.
    let mut parts: Vec<(PathBuf, FilmHeader)> = Vec::with_capacity(paths.len());
    for path in paths {
        let header = read_header(path)?;
        if let Some((first_path, first)) = parts.first() {
            first.check_same_image(first_path, &header, path)?;
        }
        parts.push((path.clone(), header));
    }
    let coverage = Coverage::of(&parts)?;
    let missing = coverage.missing();
    if !missing.is_empty() && !options.allow_missing {
        return Err(FarmError::Missing(missing.to_string()));
    }
    let first = &parts[0].1;
    let mut film = Film::new(first.width, first.height);
    for (path, header) in &parts {
        let read = add_film_file(path, &mut film)?;
        if read != *header {
            return Err(FarmError::io(path, "the file changed while it was being merged"));
        }
    }
    let target = parts.iter().any(|(_, h)| h.target_samples.is_some());
    let header = FilmHeader {
        target_samples: target.then_some(coverage.expected_samples()),
        rejected_samples: film.rejected_samples,
        coverage: parts.iter().flat_map(|(_, h)| h.coverage.iter().copied()).collect(),
        ..first.clone()
    };
    Ok(Merged {
        header,
        film,
        samples_held: coverage.samples_held(),
        samples_expected: coverage.samples_expected(),
        missing,
    })
}
