//! A spatial hash grid over the visible points, rebuilt every iteration (the
//! radii shrink and the points move), so that a photon finds the points whose
//! gather sphere contains it by looking in a single cell (pbrt-v3 §16.2.3).
//!
//! Each visible point is entered in every cell its sphere's bounding box
//! overlaps. Cells are hashed into a table about as large as the number of
//! entries, and the entries are grouped by table slot with a counting sort
//! (no comparisons), so the grid is flat arrays whose size follows the pixel
//! count, never the photon count. The build runs in parallel: chunks of
//! points enter their entries on their own, and the sort is split by the
//! slots' top bits into buckets sorted on their own (see [`BUCKET_BITS`]);
//! the table is still exactly that of one stable sort in point order. The
//! arrays are kept from one iteration to the next, so a rebuild allocates
//! nothing once they have grown. Hash collisions only add candidates: the
//! caller still checks the distance.
//!
//! A candidate is a [`GridPoint`]: the few numbers the rejection tests read
//! (centre, squared radius, normal, side), 64 bytes in one array, so the
//! gather loop touches one cache line per candidate and the full visible
//! point only for the few that pass.

use crate::math::{Aabb, DVec3};
use crate::sampler::mix64;
use arrayvec::ArrayVec;
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
    cells: Cells,
    /// The points entered, in the order the caller gave them.
    points: Vec<GridPoint>,
    /// `slot_start[s]..slot_start[s + 1]` indexes `entries` for slot `s`.
    slot_start: Vec<u32>,
    /// Indices into `points`, grouped by slot.
    entries: Vec<u32>,
    /// Scratch for the build: the entries of each run of
    /// [`POINTS_PER_CHUNK`] points, kept between builds.
    chunks: Vec<ChunkEntries>,
}

/// Cap on cells per axis: keeps coordinates small and the hash well mixed.
const MAX_RESOLUTION: i64 = 1 << 20;

/// Points whose entries one task of the parallel build makes.
const POINTS_PER_CHUNK: usize = 4096;

/// The table's slots fall into up to 2^`BUCKET_BITS` buckets by their top
/// bits. The entries are first grouped by bucket, which is a short sweep per
/// chunk, and then each bucket is counted and placed on its own: in
/// parallel, and within a range of slots small enough to stay in cache,
/// where one counting sort over the whole table would update counters
/// scattered over megabytes (a two-level, most-significant-digit-first
/// radix sort).
const BUCKET_BITS: u32 = 6;
const MAX_BUCKETS: usize = 1 << BUCKET_BITS;

/// The grid's cells: where they start, how large they are, how many per axis.
#[derive(Clone, Copy, Debug, Default)]
struct Cells {
    bounds_min: DVec3,
    inverse_cell_size: f64,
    resolution: [i64; 3],
}

impl Cells {
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

    /// The first and last cell of the box around `point`'s gather sphere.
    #[inline]
    fn range(&self, point: &GridPoint) -> ([i64; 3], [i64; 3]) {
        let r = point.radius_squared.sqrt();
        (
            self.cell_of(point.center - DVec3::splat(r)),
            self.cell_of(point.center + DVec3::splat(r)),
        )
    }

    #[inline]
    fn slot(&self, [x, y, z]: [i64; 3], slots: usize) -> u32 {
        let linear = (z * self.resolution[1] + y) * self.resolution[0] + x;
        (mix64(linear as u64) as usize & (slots - 1)) as u32
    }
}

/// The table's layout for one build: its size and its buckets.
#[derive(Clone, Copy, Debug)]
struct Table {
    /// Slots, a power of two.
    slots: usize,
    /// A slot's bucket is `slot >> bucket_shift`.
    bucket_shift: u32,
    buckets: usize,
}

impl Table {
    fn new(slots: usize) -> Self {
        let bits = slots.trailing_zeros();
        let bucket_bits = bits.min(BUCKET_BITS);
        Self {
            slots,
            bucket_shift: bits - bucket_bits,
            buckets: 1 << bucket_bits,
        }
    }

    fn slots_per_bucket(&self) -> usize {
        self.slots / self.buckets
    }
}

/// The (slot, point index) entries of one chunk of points, by bucket.
#[derive(Debug, Default)]
struct ChunkEntries {
    /// Per bucket, its entries in point order.
    buckets: Vec<Vec<(u32, u32)>>,
}

impl ChunkEntries {
    /// Enters `points` (whose first is point `first_index`) in every slot
    /// their spheres' cells hash to. Two cells of one sphere may share a
    /// slot, which must list the point once: its earlier entries in that
    /// slot's bucket are the last ones there, so a short look back finds them.
    fn enter(&mut self, cells: &Cells, table: Table, points: &[GridPoint], first_index: usize) {
        self.buckets.resize_with(table.buckets, Vec::new);
        self.buckets.iter_mut().for_each(Vec::clear);
        for (offset, point) in points.iter().enumerate() {
            let index = (first_index + offset) as u32;
            let (lo, hi) = cells.range(point);
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        let slot = cells.slot([x, y, z], table.slots);
                        let bucket = &mut self.buckets[(slot >> table.bucket_shift) as usize];
                        let mine = bucket.iter().rev().take_while(|&&(_, listed)| listed == index);
                        if !mine.clone().any(|&(listed_slot, _)| listed_slot == slot) {
                            bucket.push((slot, index));
                        }
                    }
                }
            }
        }
    }

    /// The entries in bucket `b`.
    fn bucket(&self, b: usize) -> &[(u32, u32)] {
        &self.buckets[b]
    }
}

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
        if self.points.is_empty() {
            return;
        }
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
        let resolution_of = |cells: f64| (cells.ceil() as i64).clamp(1, MAX_RESOLUTION);
        let extent_in_cells = bounds.extent() / cell_size;
        let cells = Cells {
            bounds_min: bounds.min,
            inverse_cell_size: 1.0 / cell_size,
            resolution: [0, 1, 2].map(|axis| resolution_of(extent_in_cells[axis])),
        };
        self.cells = cells;

        // The table has a slot per (point, overlapped cell), rounded up to a
        // power of two.
        let entry_count: usize = points
            .par_iter()
            .map(|p| {
                let (lo, hi) = cells.range(p);
                (0..3).map(|a| (hi[a] - lo[a] + 1) as usize).product::<usize>()
            })
            .sum();
        let table = Table::new(entry_count.next_power_of_two().max(1));

        // Each chunk of points enters its own entries, grouped by bucket.
        let chunk_count = points.len().div_ceil(POINTS_PER_CHUNK);
        if self.chunks.len() < chunk_count {
            self.chunks.resize_with(chunk_count, ChunkEntries::default);
        }
        let chunks = &mut self.chunks[..chunk_count];
        chunks
            .par_iter_mut()
            .zip(points.par_chunks(POINTS_PER_CHUNK))
            .enumerate()
            .for_each(|(c, (chunk, points))| chunk.enter(&cells, table, points, c * POINTS_PER_CHUNK));
        let chunks = &self.chunks[..chunk_count];

        // Bucket b's entries follow those of the buckets before it; split
        // the entries and the slot starts into each bucket's own part.
        let mut bucket_base = [0u32; MAX_BUCKETS + 1];
        for b in 0..table.buckets {
            bucket_base[b + 1] = bucket_base[b] + chunks.iter().map(|chunk| chunk.bucket(b).len() as u32).sum::<u32>();
        }
        let total = bucket_base[table.buckets];
        self.entries.resize(total as usize, 0);
        self.slot_start.resize(table.slots + 1, 0);
        let mut entry_parts: ArrayVec<&mut [u32], MAX_BUCKETS> = ArrayVec::new();
        let mut rest = self.entries.as_mut_slice();
        for b in 0..table.buckets {
            let (part, after) = rest.split_at_mut((bucket_base[b + 1] - bucket_base[b]) as usize);
            entry_parts.push(part);
            rest = after;
        }

        // Within each bucket, a counting sort by slot: count, prefix sums,
        // then place each entry at its slot's cursor, in chunk order, so
        // each slot lists its points in the order they were given.
        let local = table.slots_per_bucket() - 1;
        self.slot_start[..table.slots]
            .par_chunks_mut(table.slots_per_bucket())
            .zip(entry_parts.par_iter_mut())
            .enumerate()
            .for_each(|(b, (starts, out))| {
                starts.fill(0);
                let bucket_entries = || chunks.iter().flat_map(|chunk| chunk.bucket(b));
                for &(slot, _) in bucket_entries() {
                    starts[slot as usize & local] += 1;
                }
                let mut sum = 0;
                for start in starts.iter_mut() {
                    let count = *start;
                    *start = sum;
                    sum += count;
                }
                for &(slot, index) in bucket_entries() {
                    let cursor = &mut starts[slot as usize & local];
                    out[*cursor as usize] = index;
                    *cursor += 1;
                }
                // Each slot's cursor now sits at its end, which is the next
                // slot's start: shift back by one to restore the starts, and
                // make them count from the bucket's first entry.
                starts.copy_within(..starts.len() - 1, 1);
                starts[0] = 0;
                for start in starts.iter_mut() {
                    *start += bucket_base[b];
                }
            });
        self.slot_start[table.slots] = total;
    }

    /// The visible points whose gather sphere may contain `point` (a
    /// superset: the caller tests the distance).
    #[inline]
    pub fn candidates(&self, point: DVec3) -> impl Iterator<Item = &GridPoint> {
        let entries: &[u32] = if self.entries.is_empty() {
            &[]
        } else {
            let slot = self.cells.slot(self.cells.cell_of(point), self.slot_start.len() - 1) as usize;
            &self.entries[self.slot_start[slot] as usize..self.slot_start[slot + 1] as usize]
        };
        entries.iter().map(|&index| &self.points[index as usize])
    }
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

    /// The parallel two-level build gives exactly the table of one stable
    /// counting sort over all entries in point order: each slot lists its
    /// points in the order they were given, across chunks and buckets.
    #[test]
    fn parallel_build_equals_one_stable_counting_sort() {
        let mut random = Sampler::new(SamplerKind::Random, 2, 0, 5);
        let mut next = || DVec3::new(random.next_1d(), random.next_1d(), random.next_1d());
        let mut grid = VisiblePointGrid::default();
        for count in [3 * POINTS_PER_CHUNK + 17, 40, 2 * POINTS_PER_CHUNK] {
            let points: Vec<GridPoint> = (0..count as u32)
                .map(|i| grid_point(i, next() * 30.0, 0.1 + 0.4 * next().x))
                .collect();
            grid.rebuild(|v| v.extend_from_slice(&points));
            let slots = grid.slot_start.len() - 1;
            let mut keyed = Vec::new();
            for (index, point) in points.iter().enumerate() {
                let (lo, hi) = grid.cells.range(point);
                let mut mine = Vec::new();
                for z in lo[2]..=hi[2] {
                    for y in lo[1]..=hi[1] {
                        for x in lo[0]..=hi[0] {
                            let slot = grid.cells.slot([x, y, z], slots);
                            if !mine.contains(&slot) {
                                mine.push(slot);
                            }
                        }
                    }
                }
                keyed.extend(mine.into_iter().map(|slot| (slot, index as u32)));
            }
            keyed.sort_by_key(|&(slot, _)| slot);
            let entries: Vec<u32> = keyed.iter().map(|&(_, index)| index).collect();
            let slot_start: Vec<u32> = (0..=slots as u32)
                .map(|s| keyed.partition_point(|&(slot, _)| slot < s) as u32)
                .collect();
            assert_eq!(grid.entries, entries, "{count} points");
            assert_eq!(grid.slot_start, slot_start, "{count} points");
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
