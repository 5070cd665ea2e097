//! A spatial hash grid over the visible points, rebuilt every iteration (the
//! radii shrink and the points move), so that a photon finds the points whose
//! gather sphere contains it by looking in a single cell (pbrt-v3 §16.2.3).
//!
//! Each visible point is entered in every cell its sphere's bounding box
//! overlaps. Cells are hashed into a table about as large as the number of
//! entries; the entries are sorted by table slot in parallel and each slot
//! keeps a range into them, so the grid is three flat arrays whose size
//! follows the pixel count, never the photon count. Hash collisions only add
//! candidates: the caller still checks the distance.

use crate::math::{Aabb, DVec3};
use crate::sampler::mix64;
use rayon::prelude::*;

/// Visible points bucketed by the cell their gather sphere overlaps.
#[derive(Debug, Default)]
pub struct VisiblePointGrid {
    bounds_min: DVec3,
    inverse_cell_size: f64,
    /// Cells per axis, so cell coordinates stay in range.
    resolution: [i64; 3],
    /// `slot_start[s]..slot_start[s + 1]` indexes `entries` for slot `s`.
    slot_start: Vec<u32>,
    /// Pixel indices, grouped by slot.
    entries: Vec<u32>,
}

/// Cap on cells per axis: keeps coordinates small and the hash well mixed.
const MAX_RESOLUTION: i64 = 1 << 20;

impl VisiblePointGrid {
    /// Builds the grid over `points`: (pixel index, centre, radius) of each
    /// pixel that has a visible point this iteration.
    pub fn build(points: &[(u32, DVec3, f64)]) -> Self {
        if points.is_empty() {
            return Self::default();
        }
        // Bounds of all gather spheres, and a cell twice the mean radius, so a
        // typical sphere overlaps at most 2×2×2 cells; but at least a quarter
        // of the largest radius, so no sphere spans more than 9×9×9 cells.
        let (bounds, radius_sum, radius_max) = points
            .par_iter()
            .map(|&(_, p, r)| (Aabb::new(p - DVec3::splat(r), p + DVec3::splat(r)), r, r))
            .reduce(|| (Aabb::EMPTY, 0.0, 0.0), |a, b| (a.0.union(b.0), a.1 + b.1, a.2.max(b.2)));
        let mean_radius = radius_sum / points.len() as f64;
        let extent = bounds.extent().max_element().max(f64::MIN_POSITIVE);
        let cell_size = (2.0 * mean_radius).max(0.25 * radius_max).max(extent / MAX_RESOLUTION as f64);
        let inverse_cell_size = 1.0 / cell_size;
        let cells = bounds.extent() * inverse_cell_size;
        let resolution = [0, 1, 2].map(|axis| (cells[axis].ceil() as i64).clamp(1, MAX_RESOLUTION));
        let mut grid = Self {
            bounds_min: bounds.min,
            inverse_cell_size,
            resolution,
            slot_start: Vec::new(),
            entries: Vec::new(),
        };

        // Enter every point in each cell its sphere's box overlaps.
        let cell_ranges: Vec<([i64; 3], [i64; 3])> = points
            .par_iter()
            .map(|&(_, p, r)| (grid.cell_of(p - DVec3::splat(r)), grid.cell_of(p + DVec3::splat(r))))
            .collect();
        let entry_count: usize = cell_ranges
            .iter()
            .map(|(lo, hi)| (0..3).map(|a| (hi[a] - lo[a] + 1) as usize).product::<usize>())
            .sum();
        let slots = entry_count.next_power_of_two().max(1);
        let mut keyed: Vec<(u32, u32)> = points
            .par_iter()
            .zip(cell_ranges.par_iter())
            .flat_map_iter(|(&(pixel, _, _), &(lo, hi))| {
                let grid = &grid;
                (lo[2]..=hi[2]).flat_map(move |z| {
                    (lo[1]..=hi[1]).flat_map(move |y| (lo[0]..=hi[0]).map(move |x| (grid.slot([x, y, z], slots), pixel)))
                })
            })
            .collect();
        keyed.par_sort_unstable();
        // Two cells of one sphere may hash to the same slot: list it once there.
        keyed.dedup();

        // Slot ranges by one sweep over the sorted keys.
        let mut slot_start = vec![0u32; slots + 1];
        for &(slot, _) in &keyed {
            slot_start[slot as usize + 1] += 1;
        }
        for s in 0..slots {
            slot_start[s + 1] += slot_start[s];
        }
        grid.slot_start = slot_start;
        grid.entries = keyed.into_iter().map(|(_, pixel)| pixel).collect();
        grid
    }

    /// Pixel indices whose gather sphere may contain `point` (a superset:
    /// the caller tests the distance).
    #[inline]
    pub fn candidates(&self, point: DVec3) -> &[u32] {
        if self.entries.is_empty() {
            return &[];
        }
        let cell = self.cell_of(point);
        let slot = self.slot(cell, self.slot_start.len() - 1) as usize;
        &self.entries[self.slot_start[slot] as usize..self.slot_start[slot + 1] as usize]
    }

    /// Integer cell coordinates of `point`, clamped to the grid.
    #[inline]
    fn cell_of(&self, point: DVec3) -> [i64; 3] {
        let offset = (point - self.bounds_min) * self.inverse_cell_size;
        [0, 1, 2].map(|axis| (offset[axis].floor() as i64).clamp(0, self.resolution[axis] - 1))
    }

    #[inline]
    fn slot(&self, [x, y, z]: [i64; 3], slots: usize) -> u32 {
        let linear = (z * self.resolution[1] + y) * self.resolution[0] + x;
        (mix64(linear as u64) as usize & (slots - 1)) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::{Sampler, SamplerKind};

    /// Every point whose sphere contains the query must be a candidate.
    #[test]
    fn candidates_include_every_containing_sphere() {
        let mut random = Sampler::new(SamplerKind::Random, 1, 0, 3);
        let mut next = || DVec3::new(random.next_1d(), random.next_1d(), random.next_1d());
        let points: Vec<(u32, DVec3, f64)> = (0..500).map(|i| (i, next() * 10.0, 0.05 + next().x * 0.6)).collect();
        let grid = VisiblePointGrid::build(&points);
        let mut found = 0;
        for _ in 0..2000 {
            let query = next() * 12.0 - DVec3::ONE;
            let candidates = grid.candidates(query);
            for &(pixel, centre, radius) in &points {
                if (query - centre).length_squared() <= radius * radius {
                    assert!(candidates.contains(&pixel), "{pixel} missing at {query}");
                    found += 1;
                }
            }
        }
        // The test is only meaningful if some queries landed inside spheres.
        assert!(found > 100, "{found}");
    }

    #[test]
    fn empty_grid_has_no_candidates() {
        let grid = VisiblePointGrid::build(&[]);
        assert!(grid.candidates(DVec3::ZERO).is_empty());
    }
}
