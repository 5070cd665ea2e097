//! The binned surface area heuristic builder (Wald 2007, "On fast
//! construction of SAH-based bounding volume hierarchies"): a binary tree,
//! O(n log n), with the split strategy separate from the tree it feeds
//! (`bvh.rs` collapses it into eight-wide nodes).
//!
//! Items are binned along all three axes at once and the plane of least
//! SAH cost C = C_trav + (A_L ⌈N_L/4⌉ + A_R ⌈N_R/4⌉) / A (in units of one
//! leaf test, which tests up to four triangles at once) is taken. With
//! C_trav = 1 a split of a range that fits one block never pays, and any
//! larger range needs more than one leaf anyway, so a range becomes a leaf
//! exactly when it fits one block of its kind; no SAH is evaluated for it.
//! The exception is a kind whose block costs more than a traversal step
//! (four spheres tested at once): a range of it that fits one block is
//! still split when the SAH says rays would skip enough of it, and its
//! small ranges are split by the best of all partitions, not only of
//! centroid planes (spheres' boxes may overlap so that no plane separates
//! them well). Leaves never
//! mix primitive kinds (triangles and other shapes are stored apart), and
//! subtrees deeper than [`MAX_SAH_DEPTH`] fall back to median splits, which
//! bounds the depth for any input.
//!
//! Speed (the builder should be no slower than Embree's): item boxes are
//! four-lane arrays (x, y, z and a fourth lane that carries the item's
//! index and kind), so unions, centroids and bin indices are single vector
//! operations and an item is 32 bytes; a node's bounds and its centroids'
//! bounds come from its parent's partition pass instead of new passes.
//! Near the root the passes stream every item through memory, so their
//! cost is the items' size; further down it is the binning's chains of
//! updates to one bin, which two sets of bins halve.
//!
//! Bounds are single precision, rounded outward from the primitives' own
//! double-precision boxes, so a box can only be larger than what it holds.

use super::bounds::Bounds32;
use arrayvec::ArrayVec;
use wide::{CmpGt, CmpLt, f32x4, i32x4};

/// Bins per axis: 16 is within a few per cent of a full sweep's quality.
const BIN_COUNT: usize = 16;
/// Subtrees larger than this are built on two threads.
const PARALLEL_THRESHOLD: usize = 8192;
/// Cost of one traversal step in units of one leaf test. A wide node
/// tests its boxes at once and a triangle leaf tests its up to four
/// triangles at once, at about the same cost, so a leaf's cost is its
/// number of *blocks* (primitives tested together; see [`blocks`]), and
/// splitting a range that fits one block never pays: leaves come out full.
const TRAVERSAL_COST: f32 = 1.0;
// `choose_split` makes every range that fits one block a leaf without
// evaluating the SAH, which is right only while a traversal step costs at
// least one block.
const _: () = assert!(TRAVERSAL_COST >= 1.0);
/// Depth beyond which splits are made at the object median.
const MAX_SAH_DEPTH: usize = 48;
/// Most primitives any leaf may hold (the BVH encodes counts 1 to 4).
pub const MAX_LEAF_SIZE: usize = 4;

/// How the leaves of one kind of primitive are made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LeafKind {
    /// Most primitives a leaf holds, tested together as one block: 1, 2 or
    /// 4 (other sizes are taken as the power of two below, up to
    /// [`MAX_LEAF_SIZE`]).
    pub max_size: usize,
    /// Cost of testing one block, in units of one leaf test of triangles
    /// (the unit of [`TRAVERSAL_COST`]).
    pub block_cost: f32,
}

impl LeafKind {
    /// Leaves of up to `max_size` primitives whose block costs one traversal step.
    pub const fn sized(max_size: usize) -> Self {
        Self {
            max_size,
            block_cost: TRAVERSAL_COST,
        }
    }
}

/// A box as two four-lane vectors: x, y and z in lanes 0–2. Lane 3 means
/// nothing (items carry their index and kind there); nothing reads it.
#[derive(Clone, Copy, Debug)]
pub struct Box4 {
    /// Lower corner in lanes 0–2 (x, y, z).
    pub lower: f32x4,
    /// Upper corner in lanes 0–2 (x, y, z).
    pub upper: f32x4,
}

impl Box4 {
    /// The box containing nothing; the identity of `union`.
    pub const EMPTY: Box4 = Box4 {
        lower: f32x4::new([f32::INFINITY, f32::INFINITY, f32::INFINITY, 0.0]),
        upper: f32x4::new([f32::NEG_INFINITY, f32::NEG_INFINITY, f32::NEG_INFINITY, 0.0]),
    };

    /// The same box as three-component [`Bounds32`].
    pub fn to_bounds(self) -> Bounds32 {
        let (lower, upper) = (self.lower.to_array(), self.upper.to_array());
        Bounds32 {
            min: [lower[0], lower[1], lower[2]],
            max: [upper[0], upper[1], upper[2]],
        }
    }

    /// Lower bounds per lane, for the BVH's nodes.
    pub fn lower(&self) -> [f32; 4] {
        self.lower.to_array()
    }

    /// Upper bounds per lane, for the BVH's nodes.
    pub fn upper(&self) -> [f32; 4] {
        self.upper.to_array()
    }

    #[inline(always)]
    fn union(&self, other: &Box4) -> Box4 {
        Box4 {
            lower: self.lower.fast_min(other.lower),
            upper: self.upper.fast_max(other.upper),
        }
    }

    #[inline(always)]
    fn include(&self, point: f32x4) -> Box4 {
        Box4 {
            lower: self.lower.fast_min(point),
            upper: self.upper.fast_max(point),
        }
    }

    #[inline(always)]
    fn extent(&self) -> [f32; 3] {
        let e = (self.upper - self.lower).to_array();
        [e[0], e[1], e[2]]
    }

    /// Half the surface area (0 for an empty box, whose negative extents
    /// clamp to 0 without a branch): the SAH only compares areas.
    #[inline(always)]
    pub fn half_area(&self) -> f32 {
        let e = (self.upper - self.lower).fast_max(f32x4::ZERO).to_array();
        e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
    }
}

/// One primitive as the builder sees it: its box, with its index in the
/// lower corner's lane 3 and its kind in the upper corner's (as the bits of
/// those lanes), so an item is 32 bytes, two thirds of a separate record's
/// 48, and the passes near the root, which stream every item through
/// memory, move a third less. Every use of a box reads lanes 0–2 only.
#[derive(Clone, Copy, Debug)]
pub struct BuildItem {
    /// The primitive's outward-rounded bounds (lanes 0–2), index and kind (lane 3).
    bounds: Box4,
}

impl BuildItem {
    /// An item for primitive `index` of leaf kind `kind`, with bounds `bounds`.
    pub fn new(bounds: Bounds32, index: u32, kind: u8) -> Self {
        debug_assert!(index < MAX_ITEMS as u32);
        let [x0, y0, z0] = bounds.min;
        let [x1, y1, z1] = bounds.max;
        Self {
            bounds: Box4 {
                lower: f32x4::new([x0, y0, z0, f32::from_bits(LANE3_OFFSET + index)]),
                upper: f32x4::new([x1, y1, z1, f32::from_bits(LANE3_OFFSET + u32::from(kind))]),
            },
        }
    }

    /// Index into the caller's primitives.
    #[inline(always)]
    pub fn index(&self) -> u32 {
        self.bounds.lower.to_array()[3].to_bits() - LANE3_OFFSET
    }

    /// Primitives of different kinds never share a leaf.
    #[inline(always)]
    pub fn kind(&self) -> u32 {
        self.bounds.upper.to_array()[3].to_bits() - LANE3_OFFSET
    }

    /// Twice the box centre (lower + upper): no multiplication needed.
    /// (Lane 3 is meaningless.)
    #[inline(always)]
    fn centroid2(&self) -> f32x4 {
        self.bounds.lower + self.bounds.upper
    }
}

/// Most items a build takes: three kinds of at most 2²⁷ primitives each
/// (what a BVH's leaf references can index) fit.
pub const MAX_ITEMS: usize = 1 << 29;

/// Added to the index and kind before they are stored as lane 3's bits:
/// the lane then holds a normal float (from 2 to 2⁶⁵ for any index below
/// 2²⁹), never a subnormal, which some processors handle slowly in the
/// arithmetic the other lanes need.
const LANE3_OFFSET: u32 = 0x4000_0000;

/// A node of the binary tree, in depth-first order (the left child follows
/// its parent).
#[derive(Clone, Copy, Debug)]
pub struct BinaryNode {
    /// Bounds of everything below the node.
    pub bounds: Box4,
    /// A leaf range or the link to the children.
    pub content: BinaryContent,
}

/// What a [`BinaryNode`] is: a leaf or an interior node.
#[derive(Clone, Copy, Debug)]
pub enum BinaryContent {
    /// Items `first .. first + count` of the reordered item list, all of one kind.
    Leaf {
        /// Index of the leaf's first item in the reordered list.
        first: u32,
        /// Number of items, 1 to the kind's maximum leaf size.
        count: u32,
        /// The items' kind (see [`BuildItem::kind`]).
        kind: u8,
    },
    /// The left child is the next node; the right child is at `right`.
    Interior {
        /// Index of the right child in the node list.
        right: u32,
    },
}

/// Builds the binary tree over `items`, reordering them into leaf order;
/// leaves of kind k are made as `kinds[k]` says (one primitive per leaf
/// for a kind not listed). `items` must not be empty.
pub fn build(items: &mut [BuildItem], kinds: &[LeafKind]) -> Vec<BinaryNode> {
    let mut nodes = Vec::with_capacity(2 * items.len() / MAX_LEAF_SIZE + 1);
    let (bounds, centroids) = items.iter().fold((Box4::EMPTY, Box4::EMPTY), |(b, c), item| {
        (b.union(&item.bounds), c.include(item.centroid2()))
    });
    let range = Range {
        first: 0,
        depth: 0,
        bounds,
        centroids,
    };
    build_into(items, &range, kinds, &mut nodes);
    nodes
}

/// What a subtree's builder is handed: where its items start in the final
/// order, its depth, and the bounds of its items and of their centroids.
#[derive(Clone, Copy)]
struct Range {
    first: usize,
    depth: usize,
    bounds: Box4,
    centroids: Box4,
}

/// Appends the subtree over `items` to `nodes`, with indices relative to
/// the start of `nodes`.
fn build_into(items: &mut [BuildItem], range: &Range, kinds: &[LeafKind], nodes: &mut Vec<BinaryNode>) {
    let Some((mid, left, right)) = choose_split(items, range, kinds) else {
        nodes.push(BinaryNode {
            bounds: range.bounds,
            content: BinaryContent::Leaf {
                first: range.first as u32,
                count: items.len() as u32,
                kind: items[0].kind() as u8,
            },
        });
        return;
    };
    let parent = nodes.len();
    nodes.push(BinaryNode {
        bounds: range.bounds,
        content: BinaryContent::Interior { right: 0 },
    });
    let (left_items, right_items) = items.split_at_mut(mid);
    // (On one thread, building the right subtree apart would only add a copy.)
    if left_items.len() + right_items.len() > PARALLEL_THRESHOLD && rayon::current_num_threads() > 1 {
        // Build the right subtree on another thread into its own list, then
        // append it with its indices shifted.
        let mut right_nodes = Vec::new();
        rayon::join(
            || build_into(left_items, &left, kinds, nodes),
            || build_into(right_items, &right, kinds, &mut right_nodes),
        );
        let offset = nodes.len() as u32;
        nodes.extend(right_nodes.into_iter().map(|mut node| {
            if let BinaryContent::Interior { right } = &mut node.content {
                *right += offset;
            }
            node
        }));
        nodes[parent].content = BinaryContent::Interior { right: offset };
    } else {
        build_into(left_items, &left, kinds, nodes);
        let right_index = nodes.len() as u32;
        nodes[parent].content = BinaryContent::Interior { right: right_index };
        build_into(right_items, &right, kinds, nodes);
    }
}

/// Where to split `items` (reordering them so the left part comes first,
/// and returning both parts' ranges), or `None` to make them a leaf.
fn choose_split(items: &mut [BuildItem], range: &Range, kinds: &[LeafKind]) -> Option<(usize, Range, Range)> {
    let count = items.len();
    if count <= 2 * MAX_LEAF_SIZE {
        // Small enough that kinds matter: separate mixed kinds (each side
        // then may become a leaf); a range of one kind that fits one block
        // is a leaf, since a split costs C_trav + (A_L + A_R) / A ≥ 1 block
        // (areas are never negative), no less than the leaf's one block
        // (unless a block of its kind costs more than a traversal step).
        let first_kind = items[0].kind();
        if !items.iter().all(|item| item.kind() == first_kind) {
            return Some(partition(items, range, |item| item.kind() == first_kind));
        }
        if count <= block_size(first_kind, kinds) as usize {
            return split_costly_block(items, range, leaf_kind(first_kind, kinds));
        }
    }
    // From here on the range must be split: a small one of a costly kind
    // as its cheapest partition, the rest at the cheapest centroid plane.
    let kind = leaf_kind(items[0].kind(), kinds);
    if count <= EXHAUSTIVE_MAX && kind.block_cost > TRAVERSAL_COST && items.iter().all(|i| i.kind() == items[0].kind()) {
        let (_, left_set) = cheapest_partition(items, kind);
        return Some(split_by_set(items, range, left_set));
    }
    let extent = range.centroids.extent();
    if range.depth >= MAX_SAH_DEPTH || extent.iter().all(|&e| e <= 0.0) {
        // No plane separates the centroids, or the tree is already deep:
        // split at the object median.
        return Some(median_split(items, range, extent));
    }
    let binning = Binning::new(range, extent);
    let bins = binning.bin(items);
    let block_shift = block_size(items[0].kind(), kinds).trailing_zeros();
    let Some((axis, plane, _)) = bins.cheapest_plane(count, block_shift) else {
        return Some(median_split(items, range, extent));
    };
    Some(partition(items, range, |item| binning.bins_of(item)[axis] < plane as i32))
}

/// A range of one kind that fits one block: `None` (a leaf) unless the
/// kind's block costs more than a traversal step and the SAH finds a split
/// whose two one-block leaves, entered only by the rays that enter their
/// boxes, cost less than the block every ray entering the range would
/// test: C_trav · A + C_block · (A_L + A_R) < C_block · A.
fn split_costly_block(items: &mut [BuildItem], range: &Range, kind: LeafKind) -> Option<(usize, Range, Range)> {
    if kind.block_cost <= TRAVERSAL_COST || items.len() < 2 {
        return None;
    }
    let (split_areas, left_set) = cheapest_partition(items, kind);
    let area = range.bounds.half_area();
    (TRAVERSAL_COST * area + kind.block_cost * split_areas < kind.block_cost * area).then(|| split_by_set(items, range, left_set))
}

/// Most items of a costly kind whose split is chosen among all partitions
/// into two sets ([`cheapest_partition`]): 2⁸ of them at most, a few
/// microseconds.
const EXHAUSTIVE_MAX: usize = 2 * MAX_LEAF_SIZE + 1;

/// The partition of `items` (at most [`EXHAUSTIVE_MAX`], all of `kind`)
/// into two sets of least SAH cost A_L ⌈N_L/b⌉ + A_R ⌈N_R/b⌉, among all
/// partitions rather than the planes through centroids, with that cost;
/// bit i of the set says item i goes left. Boxes that overlap defeat
/// centroid planes: smallpt's walls are spheres whose boxes hold the whole
/// room, with centres 10⁵ away on six sides, so every such plane peels one
/// wall off the rest and each wall became a leaf of its own, which every
/// ray enters; the cheapest partition puts opposite walls (whose boxes
/// overlap most) together, in two full blocks.
fn cheapest_partition(items: &[BuildItem], kind: LeafKind) -> (f32, u32) {
    debug_assert!(items.len() <= EXHAUSTIVE_MAX);
    let count = items.len();
    let block_size = 1 << kind.max_size.clamp(1, MAX_LEAF_SIZE).ilog2();
    let blocks = |n: u32| n.div_ceil(block_size) as f32;
    // The last item always goes right, so each partition is counted once.
    let mut best = (f32::INFINITY, 1u32);
    for left_set in 1..1u32 << (count - 1) {
        let (mut left, mut right) = (Box4::EMPTY, Box4::EMPTY);
        for (i, item) in items.iter().enumerate() {
            if left_set >> i & 1 == 1 {
                left = left.union(&item.bounds);
            } else {
                right = right.union(&item.bounds);
            }
        }
        let left_count = left_set.count_ones();
        let cost = left.half_area() * blocks(left_count) + right.half_area() * blocks(count as u32 - left_count);
        if cost < best.0 {
            best = (cost, left_set);
        }
    }
    best
}

/// Splits `items` into those whose bit is set in `left_set` and the rest.
fn split_by_set(items: &mut [BuildItem], range: &Range, left_set: u32) -> (usize, Range, Range) {
    let goes_left: ArrayVec<u32, EXHAUSTIVE_MAX> = (0..items.len())
        .filter(|&i| left_set >> i & 1 == 1)
        .map(|i| items[i].index())
        .collect();
    partition(items, range, |item| goes_left.contains(&item.index()))
}

/// How centroids map to bins: bin ⌊(c − origin) · scale⌋ per axis, clamped
/// to the bins (axes of zero extent put everything in bin 0).
struct Binning {
    origin: f32x4,
    scale: f32x4,
}

impl Binning {
    fn new(range: &Range, extent: [f32; 3]) -> Self {
        Self {
            origin: range.centroids.lower,
            scale: f32x4::new(std::array::from_fn(|axis| {
                if axis < 3 && extent[axis] > 0.0 {
                    BIN_COUNT as f32 * (1.0 - 1e-6) / extent[axis]
                } else {
                    0.0
                }
            })),
        }
    }

    /// The item's bin on each axis (lane 3: 0). Clamped as floats (a NaN
    /// becomes 0: maxps returns its second operand), then truncated in one
    /// instruction (cvttps2dq), which needs no care for values out of
    /// range once clamped.
    #[inline(always)]
    fn bins_of(&self, item: &BuildItem) -> [i32; 4] {
        ((item.centroid2() - self.origin) * self.scale)
            .fast_max(f32x4::ZERO)
            .fast_min(f32x4::splat((BIN_COUNT - 1) as f32))
            .fast_trunc_int()
            .to_array()
    }

    /// Bins every item along the three axes at once. Neighbouring items
    /// (neighbouring in a mesh, so in space) often fall in the same bin,
    /// and each update of a bin waits for the previous one to be stored;
    /// alternate items go to two sets of bins, merged at the end, so two
    /// such chains run side by side.
    // Out of line (as are the sweep and the partition), so that profiles
    // show the builder's three phases apart.
    #[inline(never)]
    fn bin(&self, items: &[BuildItem]) -> Bins {
        let mut even = Bins::EMPTY;
        if items.len() < PAIRED_BINNING_MIN {
            for item in items {
                self.add(item, &mut even);
            }
            return even;
        }
        let mut odd = Bins::EMPTY;
        let mut pairs = items.chunks_exact(2);
        for pair in &mut pairs {
            self.add(&pair[0], &mut even);
            self.add(&pair[1], &mut odd);
        }
        for item in pairs.remainder() {
            self.add(item, &mut even);
        }
        even.merge(&odd);
        even
    }

    #[inline(always)]
    fn add(&self, item: &BuildItem, bins: &mut Bins) {
        let bin = self.bins_of(item);
        for axis in 0..3 {
            // The mask only tells the compiler the index is in range (it is).
            let bin = bin[axis] as usize & (BIN_COUNT - 1);
            bins.bounds[bin][axis] = bins.bounds[bin][axis].union(&item.bounds);
            bins.counts[bin][axis] += 1;
        }
    }
}

/// Ranges at least this long are binned into two sets of bins (merging
/// them costs about as much as binning this many items).
const PAIRED_BINNING_MIN: usize = 64;

const _: () = assert!(BIN_COUNT.is_power_of_two());

/// The bins of one range: per bin, per axis, the bounds and number of the
/// items whose centroid falls in it.
struct Bins {
    bounds: [[Box4; 3]; BIN_COUNT],
    /// Lane `axis` of `counts[bin]`; lane 3 stays 0.
    counts: [[i32; 4]; BIN_COUNT],
}

impl Bins {
    const EMPTY: Bins = Bins {
        bounds: [[Box4::EMPTY; 3]; BIN_COUNT],
        counts: [[0; 4]; BIN_COUNT],
    };

    /// Adds `other`'s items to these bins.
    fn merge(&mut self, other: &Bins) {
        for bin in 0..BIN_COUNT {
            for axis in 0..3 {
                self.bounds[bin][axis] = self.bounds[bin][axis].union(&other.bounds[bin][axis]);
                self.counts[bin][axis] += other.counts[bin][axis];
            }
        }
    }

    /// The axis and plane (items in bins below `plane` go left) of least
    /// SAH cost A_L ⌈N_L/b⌉ + A_R ⌈N_R/b⌉ (b = 2^`block_shift`) among
    /// planes with items on both sides, or `None` if there is none. The
    /// three axes are swept together, one per lane; ties go to the lowest
    /// axis, then the lowest plane.
    #[inline(never)]
    fn cheapest_plane(&self, count: usize, block_shift: u32) -> Option<(usize, usize, f32)> {
        // From the right: the cost of what lies right of each plane.
        let mut right_cost = [f32x4::ZERO; BIN_COUNT];
        let (mut right, mut right_count) = ([Box4::EMPTY; 3], i32x4::ZERO);
        for plane in (1..BIN_COUNT).rev() {
            right = std::array::from_fn(|axis| right[axis].union(&self.bounds[plane][axis]));
            right_count += i32x4::new(self.counts[plane]);
            right_cost[plane] = half_areas(&right) * blocks(right_count, block_shift);
        }
        // From the left: each plane's total cost, keeping each axis's cheapest.
        let total = i32x4::splat(count as i32);
        let (mut left, mut left_count) = ([Box4::EMPTY; 3], i32x4::ZERO);
        let (mut best_cost, mut best_plane) = (f32x4::splat(f32::INFINITY), i32x4::ZERO);
        for (plane, &right_of_plane) in right_cost.iter().enumerate().skip(1) {
            left = std::array::from_fn(|axis| left[axis].union(&self.bounds[plane - 1][axis]));
            left_count += i32x4::new(self.counts[plane - 1]);
            let cost = half_areas(&left) * blocks(left_count, block_shift) + right_of_plane;
            let splits = left_count.cmp_gt(i32x4::ZERO) & left_count.cmp_lt(total);
            let better: i32x4 = splits & bytemuck::cast::<f32x4, i32x4>(cost.cmp_lt(best_cost));
            best_cost = bytemuck::cast::<i32x4, f32x4>(better).blend(cost, best_cost);
            best_plane = better.blend(i32x4::splat(plane as i32), best_plane);
        }
        let (costs, planes) = (best_cost.to_array(), best_plane.to_array());
        let mut best: Option<(usize, usize, f32)> = None;
        for (axis, (&cost, &plane)) in costs.iter().zip(&planes).take(3).enumerate() {
            if cost < best.map_or(f32::INFINITY, |(_, _, best_cost)| best_cost) {
                best = Some((axis, plane as usize, cost));
            }
        }
        best
    }
}

/// Half the surface area of each of three boxes, box i in lane i (lane 3:
/// 0), with the same operations in the same order as [`Box4::half_area`],
/// so the results are equal to the last bit.
#[inline(always)]
fn half_areas(boxes: &[Box4; 3]) -> f32x4 {
    let extent = |b: &Box4| (b.upper - b.lower).fast_max(f32x4::ZERO);
    let [x, y, z, _] = f32x4::transpose([extent(&boxes[0]), extent(&boxes[1]), extent(&boxes[2]), f32x4::ZERO]);
    x * y + y * z + z * x
}

/// Leaf tests `count` primitives need per lane, 2^`block_shift` at a time
/// (Embree's builders count the same way).
#[inline(always)]
fn blocks(count: i32x4, block_shift: u32) -> f32x4 {
    ((count + i32x4::splat((1 << block_shift) - 1)) >> block_shift).round_float()
}

/// How leaves of `kind` are made: as `kinds` says, else one primitive each.
fn leaf_kind(kind: u32, kinds: &[LeafKind]) -> LeafKind {
    kinds.get(kind as usize).copied().unwrap_or(LeafKind::sized(1))
}

/// Primitives of `kind` tested together, which the SAH counts as one
/// block: the kind's leaf size (a power of two, see [`LeafKind`]).
fn block_size(kind: u32, kinds: &[LeafKind]) -> u32 {
    1 << leaf_kind(kind, kinds).max_size.clamp(1, MAX_LEAF_SIZE).ilog2()
}

/// Splits at the median centroid along the widest axis.
fn median_split(items: &mut [BuildItem], range: &Range, extent: [f32; 3]) -> (usize, Range, Range) {
    let axis = largest_axis(extent);
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| {
        a.centroid2().to_array()[axis].total_cmp(&b.centroid2().to_array()[axis])
    });
    let left = child_range(&items[..mid], range.first, range.depth + 1);
    let right = child_range(&items[mid..], range.first + mid, range.depth + 1);
    (mid, left, right)
}

fn child_range(items: &[BuildItem], first: usize, depth: usize) -> Range {
    let (bounds, centroids) = items.iter().fold((Box4::EMPTY, Box4::EMPTY), |(b, c), item| {
        (b.union(&item.bounds), c.include(item.centroid2()))
    });
    Range {
        first,
        depth,
        bounds,
        centroids,
    }
}

/// Index of the largest of three extents.
fn largest_axis(extent: [f32; 3]) -> usize {
    if extent[0] >= extent[1] && extent[0] >= extent[2] {
        0
    } else if extent[1] >= extent[2] {
        1
    } else {
        2
    }
}

/// Moves items satisfying `goes_left` to the front, gathering both sides'
/// bounds and centroid bounds on the way; returns the split and the ranges.
#[inline(never)]
fn partition(items: &mut [BuildItem], range: &Range, goes_left: impl Fn(&BuildItem) -> bool) -> (usize, Range, Range) {
    let (mut left_bounds, mut left_centroids) = (Box4::EMPTY, Box4::EMPTY);
    let (mut right_bounds, mut right_centroids) = (Box4::EMPTY, Box4::EMPTY);
    // Hoare's scheme: items before `split` go left, items from `end` on go
    // right; only an item found on the wrong side is moved, swapped with
    // one found on the wrong side from the other end.
    let (mut split, mut end) = (0, items.len());
    'scan: while split < end {
        let item = items[split];
        if goes_left(&item) {
            left_bounds = left_bounds.union(&item.bounds);
            left_centroids = left_centroids.include(item.centroid2());
            split += 1;
            continue;
        }
        right_bounds = right_bounds.union(&item.bounds);
        right_centroids = right_centroids.include(item.centroid2());
        loop {
            end -= 1;
            if end == split {
                break 'scan;
            }
            let other = items[end];
            if goes_left(&other) {
                left_bounds = left_bounds.union(&other.bounds);
                left_centroids = left_centroids.include(other.centroid2());
                items[split] = other;
                items[end] = item;
                split += 1;
                break;
            }
            right_bounds = right_bounds.union(&other.bounds);
            right_centroids = right_centroids.include(other.centroid2());
        }
    }
    let depth = range.depth + 1;
    (
        split,
        Range {
            first: range.first,
            depth,
            bounds: left_bounds,
            centroids: left_centroids,
        },
        Range {
            first: range.first + split,
            depth,
            bounds: right_bounds,
            centroids: right_centroids,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn item(min: [f32; 3], max: [f32; 3], index: u32, kind: u8) -> BuildItem {
        BuildItem::new(Bounds32 { min, max }, index, kind)
    }

    fn contains(outer: &Box4, inner: &Box4) -> bool {
        let (outer, inner) = (outer.to_bounds(), inner.to_bounds());
        (0..3).all(|axis| outer.min[axis] <= inner.min[axis] && inner.max[axis] <= outer.max[axis])
    }

    /// A kind whose block costs four traversal steps: four far-apart boxes
    /// are split into leaves of their own (a ray entering one box need not
    /// test the others), four boxes that share most of their space stay one
    /// leaf; a kind of unit cost makes one leaf of either.
    #[test]
    fn costly_blocks_are_split_only_where_boxes_overlap_little() {
        let leaves = |boxes: &[([f32; 3], [f32; 3])], block_cost: f32| {
            let mut items: Vec<BuildItem> = boxes
                .iter()
                .enumerate()
                .map(|(i, &(min, max))| item(min, max, i as u32, 0))
                .collect();
            let kind = LeafKind { max_size: 4, block_cost };
            let nodes = build(&mut items, &[kind]);
            nodes
                .iter()
                .filter(|node| matches!(node.content, BinaryContent::Leaf { .. }))
                .count()
        };
        let apart: Vec<_> = (0..4)
            .map(|i| ([10.0 * i as f32, 0.0, 0.0], [10.0 * i as f32 + 1.0, 1.0, 1.0]))
            .collect();
        let shared: Vec<_> = (0..4)
            .map(|i| ([0.1 * i as f32, 0.0, 0.0], [0.1 * i as f32 + 10.0, 10.0, 10.0]))
            .collect();
        assert_eq!(leaves(&apart, 4.0), 4);
        assert_eq!(leaves(&shared, 4.0), 1);
        assert_eq!(leaves(&apart, 1.0), 1);
    }

    /// smallpt's nine spheres as a costly kind: six walls of radius 10⁵
    /// whose boxes each hold the room (centres 10⁵ away on six sides), the
    /// light of radius 600 and two balls. No plane through centroids
    /// separates the walls into two groups, and such planes peeled them off
    /// one by one into three leaves (four with the light's, every one of
    /// which a ray in the room enters); the cheapest partitions put the six
    /// in two leaves.
    #[test]
    fn walls_whose_boxes_overlap_share_two_leaves() {
        let spheres: [([f32; 3], f32); 9] = [
            ([100_001.0, 40.8, 81.6], 1e5),
            ([-99_901.0, 40.8, 81.6], 1e5),
            ([50.0, 40.8, 1e5], 1e5),
            ([50.0, 40.8, -99_830.0], 1e5),
            ([50.0, 1e5, 81.6], 1e5),
            ([50.0, -99_918.4, 81.6], 1e5),
            ([50.0, 681.33, 81.6], 600.0),
            ([27.0, 16.5, 47.0], 16.5),
            ([73.0, 16.5, 78.0], 16.5),
        ];
        let mut items: Vec<BuildItem> = spheres
            .iter()
            .enumerate()
            .map(|(i, &(c, r))| item(c.map(|x| x - r), c.map(|x| x + r), i as u32, 0))
            .collect();
        let kind = LeafKind {
            max_size: 4,
            block_cost: 4.0,
        };
        let nodes = build(&mut items, &[kind]);
        let leaves_with_walls = nodes
            .iter()
            .filter(|node| match node.content {
                BinaryContent::Leaf { first, count, .. } => items[first as usize..(first + count) as usize]
                    .iter()
                    .any(|item| item.index() < 6),
                BinaryContent::Interior { .. } => false,
            })
            .count();
        assert_eq!(leaves_with_walls, 2);
    }

    /// Every item lands in exactly one leaf, leaves hold at most their
    /// kind's leaf size of one kind, and every node's box contains its children's.
    #[test]
    fn leaves_cover_every_item_once_and_boxes_nest() {
        let mut items: Vec<BuildItem> = (0..1000u32)
            .map(|i| {
                let x = (i as f32 * 0.618_034).fract() * 100.0;
                let y = (i as f32 * 0.414_213).fract() * 100.0;
                item([x, y, 0.0], [x + 1.0, y + 1.0, 1.0], i, (i % 3 == 0) as u8)
            })
            .collect();
        let leaf_sizes = [4, 1];
        let nodes = build(&mut items, &leaf_sizes.map(LeafKind::sized));
        let mut seen = vec![0; items.len()];
        for node in &nodes {
            if let BinaryContent::Leaf { first, count, kind } = node.content {
                assert!(count as usize <= leaf_sizes[kind as usize] && count > 0);
                for item in &items[first as usize..(first + count) as usize] {
                    assert_eq!(item.kind(), u32::from(kind));
                    assert!(contains(&node.bounds, &item.bounds));
                    seen[item.index() as usize] += 1;
                }
            }
        }
        assert!(seen.iter().all(|&s| s == 1));
        check_nesting(&nodes, 0);
    }

    fn check_nesting(nodes: &[BinaryNode], index: usize) -> usize {
        match nodes[index].content {
            BinaryContent::Leaf { .. } => index + 1,
            BinaryContent::Interior { right } => {
                assert!(contains(&nodes[index].bounds, &nodes[index + 1].bounds));
                assert!(contains(&nodes[index].bounds, &nodes[right as usize].bounds));
                let after_left = check_nesting(nodes, index + 1);
                assert_eq!(after_left, right as usize);
                check_nesting(nodes, right as usize)
            }
        }
    }

    /// An item gives back its index and kind, for the smallest and largest
    /// of each, and its fourth lanes hold normal floats (see `LANE3_OFFSET`).
    #[test]
    fn items_carry_index_and_kind_in_normal_floats() {
        for (index, kind) in [(0, 0), (1, 2), (MAX_ITEMS as u32 - 1, 2), (12345, 1)] {
            let item = item([-1.0, 0.0, 1.0], [2.0, 3.0, 4.0], index, kind);
            assert_eq!((item.index(), item.kind()), (index, u32::from(kind)));
            for lane in [item.bounds.lower.to_array()[3], item.bounds.upper.to_array()[3]] {
                assert!(lane.is_normal(), "{lane:e}");
            }
            let bounds = item.bounds.to_bounds();
            assert_eq!((bounds.min, bounds.max), ([-1.0, 0.0, 1.0], [2.0, 3.0, 4.0]));
        }
    }

    /// A thousand copies of one box cannot be separated by any plane: the
    /// median fallback still ends in small leaves.
    #[test]
    fn identical_boxes_end_in_small_leaves() {
        let mut items: Vec<BuildItem> = (0..1000).map(|i| item([0.0; 3], [1.0; 3], i, 0)).collect();
        let nodes = build(&mut items, &[LeafKind::sized(MAX_LEAF_SIZE)]);
        for node in &nodes {
            if let BinaryContent::Leaf { count, .. } = node.content {
                assert!(count as usize <= MAX_LEAF_SIZE);
            }
        }
    }
}
