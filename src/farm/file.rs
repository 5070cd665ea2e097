//! The film file: a part's exact per-pixel sums with a header saying what
//! image they belong to. Version 1, all integers little-endian:
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `PRISMFLM` |
//! | 4 | format version, u32 (1) |
//! | 4 | header length H, u32 (at most 16 MiB) |
//! | H | header, UTF-8 TOML ([`FilmHeader`]) |
//! | … | one record per pixel, row-major from the top-left |
//! | … | if the header has `light_paths_per_pass`: one light record per pixel, in the same order |
//! | 4 | CRC-32 (IEEE, as in gzip and PNG) of every byte before it |
//!
//! A record is five LEB128 variable-length integers: the sample count
//! (u32), the three colour sums (i128, zigzag-encoded, in units of 2⁻⁶⁴)
//! and the squared-luminance sum (u128, in units of 2⁻³²), exactly as the
//! film keeps them (`crate::film::ExactSums`). A pixel no sample reached
//! takes 5 bytes, one with a few samples about 20 (fixed-width records
//! would take 68). A light record is the three light-path sums
//! (`crate::film::LightSplats`), zigzag-encoded like the colour sums.
//! Uncovered rows are stored like any other, so every film file is a whole
//! image and merging is adding records.
//!
//! Files are written to a temporary name in the destination folder and
//! renamed into place, so a reader (a merge, a watching viewer) never sees a
//! half-written part under its final name. A reader checks the magic, the
//! version, the header, the record count and the checksum, and names the
//! file in every error.

use super::FarmError;
use super::header::FilmHeader;
use crate::film::{ExactSums, Film, LightSplats, PixelAccumulator};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// The file name extension of film files.
pub const FILM_EXTENSION: &str = "film";
/// The first bytes of every film file.
pub const MAGIC: &[u8; 8] = b"PRISMFLM";
/// The version this Prism writes and reads.
pub const FORMAT_VERSION: u32 = 1;
/// Largest header accepted: a merge of thousands of parts lists each one.
const MAX_HEADER_BYTES: u32 = 16 << 20;
/// Magic, version and header length.
const PREAMBLE_BYTES: usize = 16;

/// Whether `path` names a film file (by its extension).
pub fn is_film_path(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case(FILM_EXTENSION))
}

/// A film file about to be written: its folder is checked and its temporary
/// file created before any rendering. Dropping an unsaved one removes the
/// temporary file.
#[derive(Debug)]
pub struct PendingFilm {
    path: PathBuf,
    temporary: PathBuf,
}

impl PendingFilm {
    /// Checks that `path` ends in `.film`, names no directory and lies in an
    /// existing folder, then creates the hidden temporary file beside it
    /// (renamed onto `path` when the film is saved), so a render never
    /// starts that could not write its result.
    pub fn create(path: &Path) -> Result<Self, FarmError> {
        if !is_film_path(path) {
            return Err(FarmError::io(path, format!("a film file must end in .{FILM_EXTENSION}")));
        }
        let directory = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if !directory.is_dir() {
            return Err(FarmError::io(path, format!("folder {} does not exist", directory.display())));
        }
        if path.is_dir() {
            return Err(FarmError::io(path, "is a directory"));
        }
        let file_name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let temporary = directory.join(format!(".{file_name}.{}.tmp", std::process::id()));
        File::create(&temporary)
            .map_err(|e| FarmError::io(path, format!("cannot create a file in {}: {e}", directory.display())))?;
        Ok(Self {
            path: path.to_path_buf(),
            temporary,
        })
    }

    /// The temporary file, for a caller that must remove it on a hard exit.
    pub fn temporary_path(&self) -> &Path {
        &self.temporary
    }

    /// Writes the film and renames it into place.
    pub fn save(self, header: &FilmHeader, film: &Film) -> Result<(), FarmError> {
        write_to(&self.temporary, header, film)
            .and_then(|()| std::fs::rename(&self.temporary, &self.path).map_err(|e| e.to_string()))
            .map_err(|message| FarmError::io(&self.path, format!("cannot write: {message}")))
        // Drop removes the temporary file if the rename did not happen.
    }
}

impl Drop for PendingFilm {
    fn drop(&mut self) {
        if self.temporary.exists() {
            let _ = std::fs::remove_file(&self.temporary);
        }
    }
}

/// Writes `film` with `header` to `path` (atomically).
pub fn write_film(path: &Path, header: &FilmHeader, film: &Film) -> Result<(), FarmError> {
    PendingFilm::create(path)?.save(header, film)
}

/// A writer that keeps the CRC-32 of what passes through it.
struct Checksummed<W: Write> {
    inner: W,
    crc: crc32fast::Hasher,
}

impl<W: Write> Write for Checksummed<W> {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        let written = self.inner.write(bytes)?;
        self.crc.update(&bytes[..written]);
        Ok(written)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

fn write_to(path: &Path, header: &FilmHeader, film: &Film) -> Result<(), String> {
    if (film.width, film.height) != (header.width, header.height) {
        return Err(format!(
            "the film is {}×{} but its header says {}×{}",
            film.width, film.height, header.width, header.height
        ));
    }
    let header = FilmHeader {
        rejected_samples: film.rejected_samples,
        light_paths_per_pass: film.light.as_ref().map(|light| light.paths_per_pass),
        ..header.clone()
    }
    .to_toml()?;
    let file = File::create(path).map_err(|e| e.to_string())?;
    let mut out = Checksummed {
        inner: BufWriter::with_capacity(1 << 20, file),
        crc: crc32fast::Hasher::new(),
    };
    let io = |e: std::io::Error| e.to_string();
    out.write_all(MAGIC).map_err(io)?;
    out.write_all(&FORMAT_VERSION.to_le_bytes()).map_err(io)?;
    out.write_all(&(header.len() as u32).to_le_bytes()).map_err(io)?;
    out.write_all(header.as_bytes()).map_err(io)?;
    let mut record = Vec::with_capacity(96);
    for pixel in &film.pixels {
        record.clear();
        encode_record(&pixel.exact_sums(), &mut record);
        out.write_all(&record).map_err(io)?;
    }
    for sums in film.light.iter().flat_map(|light| &light.sums) {
        record.clear();
        encode_light_record(sums, &mut record);
        out.write_all(&record).map_err(io)?;
    }
    let crc = out.crc.clone().finalize();
    let mut inner = out.inner;
    inner.write_all(&crc.to_le_bytes()).map_err(io)?;
    let file = inner.into_inner().map_err(|e| e.error().to_string())?;
    // On disk before the rename makes it visible.
    file.sync_all().map_err(io)
}

fn encode_record(sums: &ExactSums, out: &mut Vec<u8>) {
    write_varint(sums.count as u128, out);
    encode_light_record(&sums.sum, out);
    write_varint(sums.luminance_squared_sum, out);
}

/// Three colour sums, zigzag-encoded: small magnitudes of either sign take
/// few bytes. Also a pixel's light record.
fn encode_light_record(sums: &[i128; 3], out: &mut Vec<u8>) {
    for sum in sums {
        write_varint(((sum << 1) ^ (sum >> 127)) as u128, out);
    }
}

fn write_varint(mut value: u128, out: &mut Vec<u8>) {
    while value >= 0x80 {
        out.push((value as u8 & 0x7f) | 0x80);
        value >>= 7;
    }
    out.push(value as u8);
}

/// Checks that `path` is a regular file before it is opened: a folder
/// would fail obscurely, and reading a named pipe would block the merge.
fn regular_film_file(path: &Path) -> Result<(), FarmError> {
    match crate::input_file::not_a_regular_file(path) {
        Some(reason) => Err(FarmError::io(path, reason)),
        None => Ok(()),
    }
}

/// Reads only the header of the film file at `path` (cheap: for checking
/// parts against each other before reading any of them whole).
pub fn read_header(path: &Path) -> Result<FilmHeader, FarmError> {
    regular_film_file(path)?;
    let mut file = File::open(path).map_err(|e| FarmError::io(path, format!("cannot open: {e}")))?;
    let mut preamble = [0u8; PREAMBLE_BYTES];
    let read = read_up_to(&mut file, &mut preamble).map_err(|e| FarmError::io(path, e))?;
    let length = parse_preamble(path, &preamble[..read])?;
    let mut header = vec![0u8; length];
    let read = read_up_to(&mut file, &mut header).map_err(|e| FarmError::io(path, e))?;
    if read < length {
        return Err(truncated(path, "the header is cut short"));
    }
    parse_header(path, &header)
}

fn read_up_to(file: &mut File, buffer: &mut [u8]) -> std::io::Result<usize> {
    use std::io::Read;
    let mut filled = 0;
    while filled < buffer.len() {
        match file.read(&mut buffer[filled..])? {
            0 => break,
            n => filled += n,
        }
    }
    Ok(filled)
}

/// Reads the film file at `path`: its header and its film.
pub fn read_film(path: &Path) -> Result<(FilmHeader, Film), FarmError> {
    let header = read_header(path)?;
    let mut film = Film::new(header.width, header.height);
    let header = add_film_file(path, &mut film)?;
    Ok((header, film))
}

/// Reads the film file at `path` and adds its samples to `film` (which must
/// be of its size). Every check, the checksum included, passes before
/// anything is added; on error `film` is unchanged.
pub fn add_film_file(path: &Path, film: &mut Film) -> Result<FilmHeader, FarmError> {
    regular_film_file(path)?;
    let bytes = std::fs::read(path).map_err(|e| FarmError::io(path, format!("cannot read: {e}")))?;
    let length = parse_preamble(path, &bytes[..bytes.len().min(PREAMBLE_BYTES)])?;
    let records_start = PREAMBLE_BYTES + length;
    let header_bytes = bytes
        .get(PREAMBLE_BYTES..records_start)
        .ok_or_else(|| truncated(path, "the header is cut short"))?;
    let header = parse_header(path, header_bytes)?;
    if (film.width, film.height) != (header.width, header.height) {
        return Err(FarmError::OtherImage {
            path: path.to_path_buf(),
            other: PathBuf::from("the parts before it"),
            key: "the image size".into(),
            value: format!("{}×{}", film.width, film.height),
            other_value: format!("{}×{}", header.width, header.height),
        });
    }
    let pixels = film.pixels.len();
    // The checksum first; if it fails, say whether the file is short.
    let checked = bytes.len().checked_sub(4).filter(|&end| end >= records_start);
    let checksum_holds = checked.is_some_and(|end| {
        let stored = u32::from_le_bytes([bytes[end], bytes[end + 1], bytes[end + 2], bytes[end + 3]]);
        crc32fast::hash(&bytes[..end]) == stored
    });
    let Some(end) = checked.filter(|_| checksum_holds) else {
        return Err(match decode_records(&bytes[records_start..], pixels, |_, _| {}) {
            Err(Decode::Short(read)) => truncated(path, &format!("it ends after {read} of {pixels} pixels")),
            Ok(_) if bytes.len() < records_start + 4 => truncated(path, "the checksum is missing"),
            _ => corrupt(path, "the checksum does not match the contents"),
        });
    };
    // Two passes over the records: the first checks that every record
    // decodes and fits its pixel, so that the second, which adds them,
    // cannot fail half-way.
    let records = &bytes[records_start..end];
    let mut overflow = None;
    let checked = decode_records(records, pixels, |index, sums| {
        if overflow.is_none() && film.pixels[index].count.checked_add(sums.count).is_none() {
            overflow = Some(index);
        }
    });
    let light_start = match checked {
        Ok(used) => used,
        Err(Decode::Short(read)) => return Err(truncated(path, &format!("it ends after {read} of {pixels} pixels"))),
        Err(Decode::Invalid(index)) => return Err(corrupt(path, &format!("pixel {index} is not a valid record"))),
    };
    let light = match header.light_paths_per_pass {
        None if light_start == records.len() => None,
        None => return Err(corrupt(path, "bytes after the last pixel")),
        Some(paths_per_pass) => {
            let mut light = LightSplats::new(paths_per_pass, pixels);
            match decode_light_records(&records[light_start..], &mut light.sums) {
                Ok(used) if light_start + used == records.len() => Some(light),
                Ok(_) => return Err(corrupt(path, "bytes after the last light record")),
                Err(Decode::Short(read)) => {
                    return Err(truncated(path, &format!("it ends after {read} of {pixels} light records")));
                }
                Err(Decode::Invalid(index)) => {
                    return Err(corrupt(path, &format!("light record {index} is not a valid record")));
                }
            }
        }
    };
    // Light paths must be alike in every part (an empty film takes the file's).
    match (&film.light, &light) {
        (None, None) => {}
        (Some(a), Some(b)) if a.paths_per_pass == b.paths_per_pass => {}
        (None, Some(_)) if film.pixels.iter().all(|p| p.count == 0) => {}
        _ => {
            let describe = |light: Option<u64>| light.map_or("none".to_string(), |n| format!("{n} per pass"));
            return Err(FarmError::OtherImage {
                path: path.to_path_buf(),
                other: PathBuf::from("the parts before it"),
                key: "light paths".into(),
                value: describe(film.light.as_ref().map(|l| l.paths_per_pass)),
                other_value: describe(header.light_paths_per_pass),
            });
        }
    }
    if let Some(index) = overflow {
        return Err(FarmError::io(
            path,
            format!("pixel {index} would hold more than {} samples", u32::MAX),
        ));
    }
    let _ = decode_records(records, pixels, |index, sums| {
        // Checked above: the counts fit.
        let _ = film.pixels[index].merge(&PixelAccumulator::from_exact_sums(sums));
    });
    match (&mut film.light, light) {
        (Some(sums), Some(light)) => sums.merge(&light),
        (film_light, light) => *film_light = light.or(film_light.take()),
    }
    film.rejected_samples = film.rejected_samples.saturating_add(header.rejected_samples);
    Ok(header)
}

fn parse_preamble(path: &Path, bytes: &[u8]) -> Result<usize, FarmError> {
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        let message = if bytes.is_empty() {
            "the file is empty"
        } else {
            "it does not start with PRISMFLM"
        };
        return Err(FarmError::NotAFilm {
            path: path.to_path_buf(),
            message: message.into(),
        });
    }
    if bytes.len() < PREAMBLE_BYTES {
        return Err(truncated(path, "the preamble is cut short"));
    }
    let word = |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let version = word(8);
    if version != FORMAT_VERSION {
        return Err(FarmError::Version {
            path: path.to_path_buf(),
            found: version,
            supported: FORMAT_VERSION,
        });
    }
    let length = word(12);
    if length > MAX_HEADER_BYTES {
        return Err(corrupt(path, &format!("a header of {length} bytes")));
    }
    Ok(length as usize)
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<FilmHeader, FarmError> {
    let text = std::str::from_utf8(bytes).map_err(|_| corrupt(path, "the header is not UTF-8"))?;
    FilmHeader::from_toml(text, path)
}

fn truncated(path: &Path, message: &str) -> FarmError {
    FarmError::Truncated {
        path: path.to_path_buf(),
        message: message.to_string(),
    }
}

fn corrupt(path: &Path, message: &str) -> FarmError {
    FarmError::Corrupt {
        path: path.to_path_buf(),
        message: message.to_string(),
    }
}

/// Why records did not decode.
enum Decode {
    /// The bytes ran out after this many whole records.
    Short(usize),
    /// This record is malformed (a number too long for its type).
    Invalid(usize),
}

/// Decodes `pixels` records from `bytes`, handing each to `each`; returns
/// the bytes used.
fn decode_records(bytes: &[u8], pixels: usize, mut each: impl FnMut(usize, ExactSums)) -> Result<usize, Decode> {
    let mut at = 0;
    for index in 0..pixels {
        let mut next = |bits: u32| read_varint(bytes, &mut at, bits);
        let fields = (|| {
            let count = next(32)?;
            let mut sum = [0i128; 3];
            for s in &mut sum {
                *s = unzigzag(next(128)?);
            }
            Ok((count, sum, next(128)?))
        })();
        match fields {
            Ok((count, sum, luminance_squared_sum)) => each(
                index,
                ExactSums {
                    sum,
                    luminance_squared_sum,
                    count: count as u32,
                },
            ),
            Err(VarintError::End) => return Err(Decode::Short(index)),
            Err(VarintError::TooLong) => return Err(Decode::Invalid(index)),
        }
    }
    Ok(at)
}

/// Decodes one light record per entry of `sums` from `bytes` into it;
/// returns the bytes used.
fn decode_light_records(bytes: &[u8], sums: &mut [[i128; 3]]) -> Result<usize, Decode> {
    let mut at = 0;
    for (index, pixel) in sums.iter_mut().enumerate() {
        for sum in pixel.iter_mut() {
            *sum = unzigzag(read_varint(bytes, &mut at, 128).map_err(|e| match e {
                VarintError::End => Decode::Short(index),
                VarintError::TooLong => Decode::Invalid(index),
            })?);
        }
    }
    Ok(at)
}

/// The inverse of the zigzag encoding in [`encode_light_record`].
fn unzigzag(zigzag: u128) -> i128 {
    ((zigzag >> 1) as i128) ^ -((zigzag & 1) as i128)
}

enum VarintError {
    End,
    TooLong,
}

/// One LEB128 number of at most `bits` bits at `bytes[*at..]`.
#[inline]
fn read_varint(bytes: &[u8], at: &mut usize, bits: u32) -> Result<u128, VarintError> {
    let mut value = 0u128;
    let mut shift = 0;
    loop {
        let byte = *bytes.get(*at).ok_or(VarintError::End)?;
        *at += 1;
        let payload = (byte & 0x7f) as u128;
        // No bits beyond the type's: the last byte of a 128-bit number
        // carries 2 of them, of a 32-bit one 4.
        if shift >= bits || (shift + 7 > bits && payload >> (bits - shift) != 0) {
            return Err(VarintError::TooLong);
        }
        value |= payload << shift;
        if byte & 0x80 == 0 {
            return Ok(value);
        }
        shift += 7;
    }
}
