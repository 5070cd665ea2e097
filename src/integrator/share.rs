//! A render's share of an image: which sample indices (or SPPM iterations)
//! its passes use, and which rows they sample. A whole render is the share
//! of every row and of samples `0..n`; a render farm gives each machine a
//! share, and since every sample is a pure function of (pixel, sample index,
//! seed), the shares' films add up to exactly the whole render's
//! (see `crate::farm`).

use std::ops::Range;

/// Rows `first, first + step, first + 2·step, …`: every row when `first` is
/// 0 and `step` 1. Interleaved rather than contiguous, so that each share
/// gets a like mix of cheap and costly parts of the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RowSet {
    /// The first row sampled (0 at the top).
    pub first: u32,
    /// At least 1.
    pub step: u32,
}

impl RowSet {
    /// Every row.
    pub const ALL: RowSet = RowSet { first: 0, step: 1 };

    /// Whether row `y` is in the set.
    #[inline]
    pub fn contains(&self, y: u32) -> bool {
        y >= self.first && (y - self.first).is_multiple_of(self.step.max(1))
    }

    /// The set's rows of an image `height` rows tall.
    pub fn rows(&self, height: u32) -> impl Iterator<Item = u32> + use<> {
        (self.first..height).step_by(self.step.max(1) as usize)
    }

    /// Whether this is every row.
    pub fn is_all(&self) -> bool {
        *self == Self::ALL
    }
}

/// What one render computes of an image.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Share {
    /// Sample indices (path tracing) or iterations (SPPM) the passes use, in order.
    pub samples: Range<u32>,
    /// Rows sampled; the others are left empty.
    pub rows: RowSet,
}

impl Share {
    /// Samples `0..passes` of every row: an ordinary render.
    pub fn whole(passes: u32) -> Self {
        Self {
            samples: 0..passes,
            rows: RowSet::ALL,
        }
    }

    /// Passes the share takes.
    pub fn passes(&self) -> u32 {
        self.samples.end.saturating_sub(self.samples.start)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn row_sets_interleave_and_cover_every_row_once() {
        let height = 10;
        let parts = 3;
        let mut seen = vec![0; height as usize];
        for first in 0..parts {
            let set = RowSet { first, step: parts };
            for y in set.rows(height) {
                assert!(set.contains(y));
                seen[y as usize] += 1;
            }
            assert_eq!(set.rows(height).count(), (0..height).filter(|&y| set.contains(y)).count());
        }
        assert_eq!(seen, vec![1; height as usize]);
        assert_eq!(RowSet::ALL.rows(4).collect::<Vec<_>>(), vec![0, 1, 2, 3]);
        assert!(RowSet { first: 9, step: 12 }.rows(5).next().is_none());
    }
}
