//! Which samples of which rows a set of parts holds: the checks a merge
//! makes before adding anything (no two parts hold the same sample of a
//! row), and what is missing from the samples every row should have.
//!
//! A part's coverage is a list of blocks (rows in an arithmetic
//! progression × a range of sample indices, [`CoverageBlock`]); a merged
//! film's is the concatenation of its parts', so merges can be merged again.

use super::FarmError;
use super::header::{CoverageBlock, FilmHeader};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// What is missing from a set of parts.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Missing {
    /// Missing samples summed over all pixels.
    pub samples: u64,
    /// One line per group of rows missing the same sample ranges, e.g.
    /// "samples 16..32 of every row"; empty when nothing is missing.
    pub groups: Vec<String>,
}

impl Missing {
    /// Whether no sample is missing.
    pub fn is_empty(&self) -> bool {
        self.samples == 0
    }
}

impl std::fmt::Display for Missing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.groups.join("; "))
    }
}

/// Parts' coverage, checked for overlaps.
pub struct Coverage {
    width: u32,
    height: u32,
    /// The samples every row should have: the parts' common target, or
    /// else the furthest sample any part holds.
    expected: u32,
    /// Per row, the sample ranges held, sorted and disjoint.
    rows: Vec<Vec<(u32, u32)>>,
}

impl Coverage {
    /// Checks that no two of `parts` hold the same sample of a row (they
    /// must be parts of one image, see [`FilmHeader::check_same_image`]).
    pub fn of(parts: &[(PathBuf, FilmHeader)]) -> Result<Self, FarmError> {
        let Some((_, first)) = parts.first() else {
            return Err(FarmError::NoParts);
        };
        let (width, height) = (first.width, first.height);
        let blocks: Vec<(usize, CoverageBlock)> = parts
            .iter()
            .enumerate()
            .flat_map(|(source, (_, header))| header.coverage.iter().map(move |&block| (source, block)))
            .filter(|(_, block)| !block.is_empty())
            .collect();
        let mut rows = Vec::with_capacity(height as usize);
        for y in 0..height {
            let mut ranges: Vec<(u32, u32, usize)> = blocks
                .iter()
                .filter(|(_, block)| block.contains_row(y))
                .map(|(source, block)| (block.samples[0], block.samples[1], *source))
                .collect();
            ranges.sort_unstable();
            for pair in ranges.windows(2) {
                let ((a_start, a_end, a), (b_start, b_end, b)) = (pair[0], pair[1]);
                if b_start < a_end {
                    return Err(FarmError::Overlap {
                        path: parts[b].0.clone(),
                        other: parts[a].0.clone(),
                        row: y,
                        range: (b_start, b_end),
                        other_range: (a_start, a_end),
                    });
                }
            }
            // Disjoint and sorted: join the touching ones.
            let mut joined: Vec<(u32, u32)> = Vec::new();
            for (start, end, _) in ranges {
                match joined.last_mut() {
                    Some(last) if last.1 == start => last.1 = end,
                    _ => joined.push((start, end)),
                }
            }
            rows.push(joined);
        }
        let target = parts.iter().filter_map(|(_, h)| h.target_samples).max();
        let furthest = rows.iter().filter_map(|r| r.last().map(|range| range.1)).max().unwrap_or(0);
        Ok(Self {
            width,
            height,
            expected: target.unwrap_or(furthest).max(furthest),
            rows,
        })
    }

    /// The samples every row should have.
    pub fn expected_samples(&self) -> u32 {
        self.expected
    }

    /// Samples held over all pixels.
    pub fn samples_held(&self) -> u64 {
        let per_row: u64 = self.rows.iter().flatten().map(|(a, b)| (b - a) as u64).sum();
        per_row * self.width as u64
    }

    /// Samples every pixel should have, over all pixels.
    pub fn samples_expected(&self) -> u64 {
        self.expected as u64 * self.width as u64 * self.height as u64
    }

    /// What no part holds of samples `0..expected` of every row.
    pub fn missing(&self) -> Missing {
        // Rows grouped by the ranges they lack.
        let mut groups: BTreeMap<Vec<(u32, u32)>, Vec<u32>> = BTreeMap::new();
        for (y, held) in self.rows.iter().enumerate() {
            let mut gaps = Vec::new();
            let mut next = 0;
            for &(start, end) in held {
                if start > next {
                    gaps.push((next, start));
                }
                next = next.max(end);
            }
            if next < self.expected {
                gaps.push((next, self.expected));
            }
            if !gaps.is_empty() {
                groups.entry(gaps).or_default().push(y as u32);
            }
        }
        let mut missing = Missing::default();
        for (gaps, rows) in groups {
            let per_row: u64 = gaps.iter().map(|(a, b)| (b - a) as u64).sum();
            missing.samples += per_row * rows.len() as u64 * self.width as u64;
            let ranges: Vec<String> = gaps.iter().map(|(a, b)| format!("{a}..{b}")).collect();
            missing.groups.push(format!(
                "samples {} of {}",
                ranges.join(", "),
                describe_rows(&rows, self.height)
            ));
        }
        missing
    }
}

/// "every row", "row 3", or "rows 1, 4, 7 … (12 of 36 rows)".
fn describe_rows(rows: &[u32], height: u32) -> String {
    const SHOWN: usize = 4;
    match rows {
        _ if rows.len() == height as usize => "every row".into(),
        [row] => format!("row {row}"),
        _ => {
            let shown: Vec<String> = rows.iter().take(SHOWN).map(u32::to_string).collect();
            let more = if rows.len() > SHOWN { " …" } else { "" };
            format!("rows {}{more} ({} of {height} rows)", shown.join(", "), rows.len())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::{RowSet, Share};
    use crate::settings::RenderSettings;

    fn part(share: Share, target: Option<u32>) -> FilmHeader {
        let settings = RenderSettings {
            width: 2,
            height: 6,
            ..Default::default()
        };
        FilmHeader::new("s", &settings, "h", &share, target)
    }

    fn share(samples: std::ops::Range<u32>, first: u32, step: u32) -> Share {
        Share {
            samples,
            rows: RowSet { first, step },
        }
    }

    #[test]
    fn complete_parts_miss_nothing_and_gaps_are_named() {
        let parts = vec![
            ("a".into(), part(share(0..8, 0, 1), Some(16))),
            ("b".into(), part(share(8..16, 0, 1), Some(16))),
        ];
        let coverage = Coverage::of(&parts).expect("no overlap");
        assert!(coverage.missing().is_empty());
        assert_eq!(coverage.samples_held(), 2 * 6 * 16);

        let coverage = Coverage::of(&parts[..1]).expect("no overlap");
        let missing = coverage.missing();
        assert_eq!(missing.to_string(), "samples 8..16 of every row");
        assert_eq!(missing.samples, 2 * 6 * 8);

        // Rows split in three, one part absent.
        let rows: Vec<(PathBuf, FilmHeader)> = [0, 2]
            .iter()
            .map(|&k| (format!("{k}").into(), part(share(0..4, k, 3), Some(4))))
            .collect();
        let missing = Coverage::of(&rows).expect("no overlap").missing();
        assert_eq!(missing.to_string(), "samples 0..4 of rows 1, 4 (2 of 6 rows)");
        assert_eq!(missing.samples, 2 * 2 * 4);
    }

    #[test]
    fn overlaps_name_both_parts() {
        let parts = vec![
            ("a.film".into(), part(share(0..10, 0, 1), None)),
            ("b.film".into(), part(share(8..16, 0, 2), None)),
        ];
        let error = Coverage::of(&parts).err().map(|e| e.to_string()).unwrap_or_default();
        assert_eq!(
            error,
            "b.film: samples 8..16 of row 0 are also in a.film (samples 0..10): parts overlap"
        );
        // Without a target, the furthest sample held is expected everywhere.
        let parts = vec![
            ("a".into(), part(share(0..4, 0, 1), None)),
            ("b".into(), part(share(6..9, 0, 1), None)),
        ];
        assert_eq!(
            Coverage::of(&parts).expect("disjoint").missing().to_string(),
            "samples 4..6 of every row"
        );
    }
}
