//! A spatial hash grid over the visible points, rebuilt every iteration (the
//! radii shrink and the points move), so that a photon finds the points whose
//! gather sphere contains it by looking in a single cell (pbrt-v3 §16.2.3).
//!
//! Each visible point is entered in every cell its sphere's bounding box
//! overlaps. Cells are hashed into a table about as large as the number of
//! entries, and the entries are grouped by table slot with a counting sort
//! (two sweeps, no comparisons), so the grid is flat arrays whose size
//! follows the pixel count, never the photon count. The arrays are kept from
//! one iteration to the next, so a rebuild allocates nothing once they have
//! grown. Hash collisions only add candidates: the caller still checks the
//! distance.
//!
//! A candidate is a [`GridPoint`]: the few numbers the rejection tests read
//! (centre, squared radius, normal, side), 64 bytes in one array, so the
//! gather loop touches one cache line per candidate and the full visible
//! point only for the few that pass.

use crate::math::{Aabb, DVec3};
use crate::sampler::mix64;
use rayon::prelude::*;

/// What the gather loop tests a photon against, for one visible point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridPoint {
    /// Centre of the gather sphere (the visible point's position).
    pub center: DVec3,
    /// Squared gather radius, as `radius * radius` (the distance test
    /// compares against exactly this value).
    pub radius_squared: f64,
    /// Geometric normal of the visible point's surface.
    pub normal: DVec3,
    /// Which side of the surface the camera path arrived from, relative to
    /// `normal`: +1 or −1 (exact in f32).
    pub side: f32,
    /// The pixel the visible point belongs to.
    pub pixel: u32,
}

/// Visible points bucketed by the cell their gather sphere overlaps.
#[derive(Debug, Default)]
pub struct VisiblePointGrid {
    bounds_min: DVec3,
    inverse_cell_size: f64,
    /// Cells per axis, so cell coordinates stay in range.
    resolution: [i64; 3],
    /// The points entered, in the order the caller gave them.
    points: Vec<GridPoint>,
    /// `slot_start[s]..slot_start[s + 1]` indexes `entries` for slot `s`.
    slot_start: Vec<u32>,
    /// Indices into `points`, grouped by slot.
    entries: Vec<u32>,
    /// Scratch for the build: (slot, point index) of every entry, unsorted.
    keyed: Vec<(u32, u32)>,
}

/// Cap on cells per axis: keeps coordinates small and the hash well mixed.
const MAX_RESOLUTION: i64 = 1 << 20;

impl VisiblePointGrid {
    /// Rebuilds the grid over the points `fill` pushes (those of the pixels
    /// with a visible point this iteration; `fill` gets an empty vector),
    /// reusing the previous build's arrays.
    pub fn rebuild(&mut self, fill: impl FnOnce(&mut Vec<GridPoint>)) {
        let mut points = std::mem::take(&mut self.points);
        points.clear();
        fill(&mut points);
        self.points = points;
        self.slot_start.clear();
        self.entries.clear();
        self.keyed.clear();
        if self.points.is_empty() {
            return;
        }
        let mut keyed = std::mem::take(&mut self.keyed);
        let points = &self.points;
        // Bounds of all gather spheres, and a cell twice the mean radius, so a
        // typical sphere overlaps at most 2×2×2 cells; but at least a quarter
        // of the largest radius, so no sphere spans more than 9×9×9 cells.
        let (bounds, radius_sum, radius_max) = points
            .par_iter()
            .map(|p| {
                let r = p.radius_squared.sqrt();
                (Aabb::new(p.center - DVec3::splat(r), p.center + DVec3::splat(r)), r, r)
            })
            .reduce(|| (Aabb::EMPTY, 0.0, 0.0), |a, b| (a.0.union(b.0), a.1 + b.1, a.2.max(b.2)));
        let mean_radius = radius_sum / points.len() as f64;
        let extent = bounds.extent().max_element().max(f64::MIN_POSITIVE);
        let cell_size = (2.0 * mean_radius).max(0.25 * radius_max).max(extent / MAX_RESOLUTION as f64);
        self.bounds_min = bounds.min;
        self.inverse_cell_size = 1.0 / cell_size;
        let cells = bounds.extent() * self.inverse_cell_size;
        self.resolution = [0, 1, 2].map(|axis| (cells[axis].ceil() as i64).clamp(1, MAX_RESOLUTION));

        // The table has a slot per (point, overlapped cell), rounded up to a
        // power of two.
        let cell_range = |p: &GridPoint| {
            let r = p.radius_squared.sqrt();
            (
                self.cell_of(p.center - DVec3::splat(r)),
                self.cell_of(p.center + DVec3::splat(r)),
            )
        };
        let entry_count: usize = points
            .par_iter()
            .map(|p| {
                let (lo, hi) = cell_range(p);
                (0..3).map(|a| (hi[a] - lo[a] + 1) as usize).product::<usize>()
            })
            .sum();
        let slots = entry_count.next_power_of_two().max(1);

        // Enter every point in each slot its sphere's cells hash to; two
        // cells of one sphere may share a slot, which lists the point once.
        for (index, p) in points.iter().enumerate() {
            let (lo, hi) = cell_range(p);
            let first = keyed.len();
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        keyed.push((self.slot([x, y, z], slots), index as u32));
                    }
                }
            }
            let kept = distinct_prefix(&mut keyed[first..]);
            keyed.truncate(first + kept);
        }

        // Counting sort by slot: count, prefix sums, then place each entry at
        // its slot's cursor.
        self.slot_start.resize(slots + 1, 0);
        for &(slot, _) in &keyed {
            self.slot_start[slot as usize + 1] += 1;
        }
        for s in 0..slots {
            self.slot_start[s + 1] += self.slot_start[s];
        }
        self.entries.resize(keyed.len(), 0);
        for &(slot, index) in &keyed {
            // The slot's next free place: its start, advanced as it fills.
            let cursor = &mut self.slot_start[slot as usize];
            self.entries[*cursor as usize] = index;
            *cursor += 1;
        }
        // Each slot's cursor now sits at its end, which is the next slot's
        // start: shift back by one to restore the starts.
        for s in (1..=slots).rev() {
            self.slot_start[s] = self.slot_start[s - 1];
        }
        self.slot_start[0] = 0;
        self.keyed = keyed;
    }

    /// The visible points whose gather sphere may contain `point` (a
    /// superset: the caller tests the distance).
    #[inline]
    pub fn candidates(&self, point: DVec3) -> impl Iterator<Item = &GridPoint> {
        let entries: &[u32] = if self.entries.is_empty() {
            &[]
        } else {
            let slot = self.slot(self.cell_of(point), self.slot_start.len() - 1) as usize;
            &self.entries[self.slot_start[slot] as usize..self.slot_start[slot + 1] as usize]
        };
        entries.iter().map(|&index| &self.points[index as usize])
    }

    /// Integer cell coordinates of `point`, clamped to the grid.
    ///
    /// The cast truncates towards zero where `floor` would round down, but
    /// the two differ only for negative offsets, which the clamp sends to
    /// cell 0 either way (and NaN casts to 0 in both): the same cells as
    /// `floor`, without its library call (x86-64's baseline has no SSE4.1
    /// rounding instruction), on every photon deposit.
    #[inline]
    fn cell_of(&self, point: DVec3) -> [i64; 3] {
        let offset = (point - self.bounds_min) * self.inverse_cell_size;
        let cell = |value: f64, resolution: i64| (value as i64).clamp(0, resolution - 1);
        [
            cell(offset.x, self.resolution[0]),
            cell(offset.y, self.resolution[1]),
            cell(offset.z, self.resolution[2]),
        ]
    }

    #[inline]
    fn slot(&self, [x, y, z]: [i64; 3], slots: usize) -> u32 {
        let linear = (z * self.resolution[1] + y) * self.resolution[0] + x;
        (mix64(linear as u64) as usize & (slots - 1)) as u32
    }
}

/// Moves the distinct values of `entries` to its front and returns how
/// many there are. A sphere usually overlaps 8 cells, whose slots a linear
/// scan compares faster than a sort; a large sphere's list is sorted.
fn distinct_prefix(entries: &mut [(u32, u32)]) -> usize {
    const LINEAR_SCAN_MAX: usize = 16;
    if entries.len() > LINEAR_SCAN_MAX {
        entries.sort_unstable();
    }
    let mut kept = 0;
    for i in 0..entries.len() {
        let entry = entries[i];
        let seen = if entries.len() > LINEAR_SCAN_MAX {
            kept > 0 && entries[kept - 1] == entry
        } else {
            entries[..kept].contains(&entry)
        };
        if !seen {
            entries[kept] = entry;
            kept += 1;
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::{Sampler, SamplerKind};

    fn grid_point(pixel: u32, center: DVec3, radius: f64) -> GridPoint {
        GridPoint {
            center,
            radius_squared: radius * radius,
            normal: DVec3::Z,
            side: 1.0,
            pixel,
        }
    }

    /// Every point whose sphere contains the query must be a candidate, once,
    /// through any number of rebuilds of one grid (the reused arrays must not
    /// keep anything from an earlier build).
    #[test]
    fn candidates_include_every_containing_sphere_once() {
        let mut random = Sampler::new(SamplerKind::Random, 1, 0, 3);
        let mut next = || DVec3::new(random.next_1d(), random.next_1d(), random.next_1d());
        let mut grid = VisiblePointGrid::default();
        for build in 0..3 {
            // Later builds have fewer, smaller spheres in a smaller box.
            let (count, scale) = (500 - 150 * build, 10.0 / (1 + build) as f64);
            let points: Vec<GridPoint> = (0..count)
                .map(|i| grid_point(i, next() * scale, (0.05 + next().x * 0.6) / (1 + build) as f64))
                .collect();
            grid.rebuild(|v| v.extend_from_slice(&points));
            let mut found = 0;
            // Enough queries that even the sparsest build has hundreds inside spheres.
            for _ in 0..8000 {
                let query = next() * (scale * 1.2) - DVec3::splat(0.1 * scale);
                let candidates: Vec<u32> = grid.candidates(query).map(|p| p.pixel).collect();
                for p in &points {
                    if (query - p.center).length_squared() <= p.radius_squared {
                        let times = candidates.iter().filter(|&&c| c == p.pixel).count();
                        assert_eq!(times, 1, "build {build}: {} listed {times} times at {query}", p.pixel);
                        found += 1;
                    }
                }
                // Only points of this build are candidates.
                assert!(candidates.iter().all(|&c| c < count), "build {build}: stale candidate");
            }
            // The test is only meaningful if some queries landed inside spheres.
            assert!(found > 100, "build {build}: {found}");
        }
    }

    /// Duplicates go, each distinct entry stays once, short lists and long.
    #[test]
    fn distinct_prefix_keeps_each_entry_once() {
        for length in [0usize, 1, 8, 16, 17, 100] {
            let mut entries: Vec<(u32, u32)> = (0..length as u32).map(|i| ((i * 7) % 5, 3)).collect();
            let kept = distinct_prefix(&mut entries);
            let mut distinct = entries[..kept].to_vec();
            distinct.sort_unstable();
            let expected: Vec<(u32, u32)> = (0..length as u32)
                .map(|i| ((i * 7) % 5, 3))
                .collect::<std::collections::BTreeSet<_>>()
                .into_iter()
                .collect();
            assert_eq!(distinct, expected, "length {length}");
        }
    }

    #[test]
    fn empty_grid_has_no_candidates() {
        let mut grid = VisiblePointGrid::default();
        grid.rebuild(|_| {});
        assert_eq!(grid.candidates(DVec3::ZERO).count(), 0);
        // Emptied after holding points.
        grid.rebuild(|v| v.push(grid_point(0, DVec3::ZERO, 1.0)));
        assert_eq!(grid.candidates(DVec3::ZERO).count(), 1);
        grid.rebuild(|_| {});
        assert_eq!(grid.candidates(DVec3::ZERO).count(), 0);
    }
}
