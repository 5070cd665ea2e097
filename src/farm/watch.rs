//! A folder of film files merged as they arrive: what `prism view --watch`
//! shows while a farm renders. Each [`FolderWatch::scan`] reads only the
//! files that are new since the last one and adds them to the merge, so a
//! scan costs the new parts, not all of them.
//!
//! Parts are written under a temporary (hidden) name and renamed into
//! place (`super::file`), so a file with its final name is complete. A part
//! that is not of the same image as the first one, overlaps one already
//! merged, or does not read (corrupt, or copied in by a tool that writes in
//! place and not finished yet) is left out and listed as a problem; it is
//! tried again when its size or time stamp changes. If a merged file changes
//! or disappears (a task re-run), the merge starts over from the folder.

use super::FarmError;
use super::coverage::{Coverage, Missing};
use super::file::{add_film_file, is_film_path, read_header};
use super::header::FilmHeader;
use crate::color::luminance;
use crate::film::{Film, Frame};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// What identifies a version of a file: its size and modification time.
type Stamp = (u64, Option<SystemTime>);

/// The merge of a watched folder so far.
pub struct FolderWatch {
    folder: PathBuf,
    /// Merged parts, in the order they were added, with their stamps.
    parts: Vec<(PathBuf, FilmHeader, Stamp)>,
    film: Option<Film>,
    /// Files left out, with the stamp they had and why.
    problems: BTreeMap<PathBuf, (Stamp, String)>,
    /// Counts the changes to the merge, so a viewer knows when to redraw.
    generation: u64,
}

/// Where a watched merge stands.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WatchStatus {
    /// Parts merged.
    pub parts: usize,
    /// Samples merged so far, over all pixels.
    pub samples_held: u64,
    /// Samples the image holds once every part is in, over all pixels (0
    /// before the first part is read).
    pub samples_expected: u64,
    /// What is still missing.
    pub missing: Missing,
    /// Root-mean-square per-pixel standard error over the image's mean
    /// luminance (as the viewer's status line), once most pixels have two
    /// samples or more.
    pub noise: Option<f64>,
    /// Files left out, one line each, naming the file.
    pub problems: Vec<String>,
    /// Changes so far (see [`FolderWatch::generation`]).
    pub generation: u64,
}

impl FolderWatch {
    /// Watches `folder` (nothing is read until the first scan).
    pub fn new(folder: &Path) -> Self {
        Self {
            folder: folder.to_path_buf(),
            parts: Vec::new(),
            film: None,
            problems: BTreeMap::new(),
            generation: 0,
        }
    }

    /// The folder watched.
    pub fn folder(&self) -> &Path {
        &self.folder
    }

    /// Reads the parts that appeared or changed since the last scan and adds
    /// them; returns whether the merge changed. Fails only if the folder
    /// cannot be listed.
    pub fn scan(&mut self) -> Result<bool, FarmError> {
        let files = film_files(&self.folder)?;
        // A merged part that changed or vanished cannot be taken back out
        // (its old contents are gone): start over.
        let stale = self.parts.iter().any(|(path, _, stamp)| files.get(path) != Some(stamp));
        let mut changed = false;
        if stale {
            self.parts.clear();
            self.film = None;
            changed = true;
        }
        self.problems.retain(|path, (stamp, _)| files.get(path) == Some(stamp));
        for (path, stamp) in files {
            if self.parts.iter().any(|(p, _, _)| *p == path) || self.problems.contains_key(&path) {
                continue;
            }
            match self.add(&path, stamp) {
                Ok(()) => changed = true,
                Err(error) => {
                    self.problems.insert(path, (stamp, error.to_string()));
                }
            }
        }
        if changed {
            self.generation += 1;
        }
        Ok(changed)
    }

    /// Checks one new part against the merge and adds it.
    fn add(&mut self, path: &Path, stamp: Stamp) -> Result<(), FarmError> {
        let header = read_header(path)?;
        if let Some((first_path, first, _)) = self.parts.first() {
            first.check_same_image(first_path, &header, path)?;
            let mut all: Vec<(PathBuf, FilmHeader)> = self.parts.iter().map(|(p, h, _)| (p.clone(), h.clone())).collect();
            all.push((path.to_path_buf(), header.clone()));
            Coverage::of(&all)?;
        }
        let film = self.film.get_or_insert_with(|| Film::new(header.width, header.height));
        let read = add_film_file(path, film)?;
        if read != header {
            // Replaced between the two reads: unusual; the next scan sees its new stamp.
            self.parts.clear();
            self.film = None;
            return Err(FarmError::io(path, "the file changed while it was being read"));
        }
        self.parts.push((path.to_path_buf(), header, stamp));
        Ok(())
    }

    /// Changes to the merge so far: a new value means a new frame.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The merged estimate, once some part is in.
    pub fn frame(&self) -> Option<Frame> {
        self.film.as_ref().map(Film::frame)
    }

    /// The merged film, once some part is in.
    pub fn film(&self) -> Option<&Film> {
        self.film.as_ref()
    }

    /// Parts, samples, what is missing, noise and problems.
    pub fn status(&self) -> WatchStatus {
        let headers: Vec<(PathBuf, FilmHeader)> = self.parts.iter().map(|(p, h, _)| (p.clone(), h.clone())).collect();
        let coverage = Coverage::of(&headers).ok();
        WatchStatus {
            parts: self.parts.len(),
            samples_held: coverage.as_ref().map_or(0, Coverage::samples_held),
            samples_expected: coverage.as_ref().map_or(0, Coverage::samples_expected),
            missing: coverage.as_ref().map(Coverage::missing).unwrap_or_default(),
            noise: self.film.as_ref().and_then(noise),
            problems: self.problems.values().map(|(_, message)| message.clone()).collect(),
            generation: self.generation,
        }
    }
}

/// The folder's film files (not hidden ones: temporary files being written
/// are hidden) with their stamps, by name.
fn film_files(folder: &Path) -> Result<BTreeMap<PathBuf, Stamp>, FarmError> {
    let entries = std::fs::read_dir(folder).map_err(|e| FarmError::io(folder, format!("cannot list the folder: {e}")))?;
    let mut files = BTreeMap::new();
    for entry in entries.flatten() {
        let path = entry.path();
        let hidden = path.file_name().is_some_and(|n| n.to_string_lossy().starts_with('.'));
        if hidden || !is_film_path(&path) {
            continue;
        }
        if let Some(metadata) = entry.metadata().ok().filter(|m| m.is_file()) {
            files.insert(path, (metadata.len(), metadata.modified().ok()));
        }
    }
    Ok(files)
}

/// Root-mean-square standard error of the pixels with two samples or more,
/// over the image's mean luminance; `None` while most pixels have fewer.
fn noise(film: &Film) -> Option<f64> {
    let (mut squared, mut counted, mut luminance_sum) = (0.0, 0usize, 0.0);
    for pixel in &film.pixels {
        luminance_sum += luminance(pixel.mean());
        if pixel.count >= 2 {
            let error = pixel.standard_error();
            squared += error * error;
            counted += 1;
        }
    }
    let mean = luminance_sum / film.pixels.len().max(1) as f64;
    (counted * 2 >= film.pixels.len() && mean > 0.0).then(|| (squared / counted as f64).sqrt() / mean)
}
