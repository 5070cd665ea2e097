//! The binned surface area heuristic builder (Wald 2007, "On fast
//! construction of SAH-based bounding volume hierarchies"): a binary tree,
//! O(n log n), with the split strategy separate from the tree it feeds
//! (`bvh.rs` collapses it into four-wide nodes).
//!
//! Items are binned along all three axes and the plane of least SAH cost
//! C = C_trav + (A_L N_L + A_R N_R) / A (in units of one primitive test) is
//! taken; a range becomes a leaf when that is no cheaper than testing its
//! primitives, which the four-wide nodes make worth at most
//! [`MAX_LEAF_SIZE`] primitives. Leaves never mix primitive kinds (triangles
//! and other shapes are stored apart), and subtrees deeper than
//! [`MAX_SAH_DEPTH`] fall back to median splits, which bounds the depth
//! (and so the traversal stack) for any input.
//!
//! Bounds are single precision, rounded outward from the primitives' own
//! double-precision boxes, so a box can only be larger than what it holds.

use super::bounds::Bounds32;

/// Bins per axis: 16 is within a few per cent of a full sweep's quality.
const BIN_COUNT: usize = 16;
/// Subtrees larger than this are built on two threads.
const PARALLEL_THRESHOLD: usize = 8192;
/// Cost of one traversal step in units of one primitive test: a four-wide
/// node tests four boxes at once, about what one triangle test costs.
const TRAVERSAL_COST: f32 = 1.0;
/// Most primitives a leaf holds.
pub const MAX_LEAF_SIZE: usize = 4;
/// Depth beyond which splits are made at the object median.
const MAX_SAH_DEPTH: usize = 48;

/// One primitive as the builder sees it.
#[derive(Clone, Copy, Debug)]
pub struct BuildItem {
    pub bounds: Bounds32,
    /// Twice the box centre (min + max), so no multiplication is needed.
    pub centroid2: [f32; 3],
    /// Index into the caller's primitives.
    pub index: u32,
    /// Primitives of different kinds never share a leaf.
    pub kind: u8,
}

impl BuildItem {
    pub fn new(bounds: Bounds32, index: u32, kind: u8) -> Self {
        Self {
            bounds,
            centroid2: std::array::from_fn(|axis| bounds.min[axis] + bounds.max[axis]),
            index,
            kind,
        }
    }
}

/// A node of the binary tree, in depth-first order (the left child follows
/// its parent).
#[derive(Clone, Copy, Debug)]
pub struct BinaryNode {
    pub bounds: Bounds32,
    pub content: BinaryContent,
}

#[derive(Clone, Copy, Debug)]
pub enum BinaryContent {
    /// Items `first .. first + count` of the reordered item list, all of one kind.
    Leaf { first: u32, count: u32, kind: u8 },
    /// The left child is the next node; the right child is at `right`.
    Interior { right: u32 },
}

/// Builds the binary tree over `items`, reordering them into leaf order.
/// `items` must not be empty.
pub fn build(items: &mut [BuildItem]) -> Vec<BinaryNode> {
    let mut nodes = Vec::with_capacity(2 * items.len() / MAX_LEAF_SIZE.max(1) + 1);
    build_into(items, 0, 0, &mut nodes);
    nodes
}

/// Appends the subtree over `items` (whose first item sits at `first` in
/// the final order) to `nodes`, with indices relative to the start of `nodes`.
fn build_into(items: &mut [BuildItem], first: usize, depth: usize, nodes: &mut Vec<BinaryNode>) {
    let bounds = items.iter().fold(Bounds32::EMPTY, |b, item| b.union(&item.bounds));
    let split = choose_split(items, &bounds, depth);
    let Some(mid) = split else {
        nodes.push(BinaryNode {
            bounds,
            content: BinaryContent::Leaf {
                first: first as u32,
                count: items.len() as u32,
                kind: items[0].kind,
            },
        });
        return;
    };
    let parent = nodes.len();
    nodes.push(BinaryNode {
        bounds,
        content: BinaryContent::Interior { right: 0 },
    });
    let (left_items, right_items) = items.split_at_mut(mid);
    if items_len(left_items, right_items) > PARALLEL_THRESHOLD {
        // Build the right subtree on another thread into its own list, then
        // append it with its indices shifted.
        let mut right_nodes = Vec::new();
        rayon::join(
            || build_into(left_items, first, depth + 1, nodes),
            || build_into(right_items, first + mid, depth + 1, &mut right_nodes),
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
        build_into(left_items, first, depth + 1, nodes);
        let right = nodes.len() as u32;
        nodes[parent].content = BinaryContent::Interior { right };
        build_into(right_items, first + mid, depth + 1, nodes);
    }
}

fn items_len(a: &[BuildItem], b: &[BuildItem]) -> usize {
    a.len() + b.len()
}

/// Where to split `items` (reordering them so the left part comes first),
/// or `None` to make them a leaf.
fn choose_split(items: &mut [BuildItem], bounds: &Bounds32, depth: usize) -> Option<usize> {
    let count = items.len();
    let one_kind = items.iter().all(|item| item.kind == items[0].kind);
    if count <= 1 {
        return None;
    }
    if !one_kind && count <= 2 * MAX_LEAF_SIZE {
        // Small and mixed: separate the kinds; each side then may become a leaf.
        let kind = items[0].kind;
        return Some(partition(items, |item| item.kind == kind));
    }
    let centroid_bounds = items.iter().fold(Bounds32::EMPTY, |b, item| b.include(item.centroid2));
    let extent = centroid_bounds.extent();
    if depth >= MAX_SAH_DEPTH || extent.iter().all(|&e| e <= 0.0) {
        // No plane separates the centroids, or the tree is already deep:
        // a leaf if allowed, else the object median.
        if count <= MAX_LEAF_SIZE && one_kind {
            return None;
        }
        let axis = largest_axis(extent);
        let mid = count / 2;
        items.select_nth_unstable_by(mid, |a, b| a.centroid2[axis].total_cmp(&b.centroid2[axis]));
        return Some(mid);
    }

    // Bin every centroid along each axis.
    let mut bins = [[Bin::EMPTY; BIN_COUNT]; 3];
    let scale: [f32; 3] = std::array::from_fn(|axis| {
        if extent[axis] > 0.0 {
            BIN_COUNT as f32 * (1.0 - 1e-6) / extent[axis]
        } else {
            0.0
        }
    });
    let bin_of = |item: &BuildItem, axis: usize| -> usize {
        (((item.centroid2[axis] - centroid_bounds.min[axis]) * scale[axis]) as usize).min(BIN_COUNT - 1)
    };
    for item in items.iter() {
        for (axis, axis_bins) in bins.iter_mut().enumerate() {
            let bin = &mut axis_bins[bin_of(item, axis)];
            bin.bounds = bin.bounds.union(&item.bounds);
            bin.count += 1;
        }
    }

    // For each axis, sweep from the right for the area and count right of
    // each plane, then from the left to find the cheapest plane.
    let mut best = (f32::INFINITY, 0usize, 0usize);
    for (axis, axis_bins) in bins.iter().enumerate() {
        if extent[axis] <= 0.0 {
            continue;
        }
        let mut right_cost = [0.0f32; BIN_COUNT];
        let (mut right_bounds, mut right_count) = (Bounds32::EMPTY, 0u32);
        for plane in (1..BIN_COUNT).rev() {
            right_bounds = right_bounds.union(&axis_bins[plane].bounds);
            right_count += axis_bins[plane].count;
            right_cost[plane] = right_bounds.half_area() * right_count as f32;
        }
        let (mut left_bounds, mut left_count) = (Bounds32::EMPTY, 0u32);
        for plane in 1..BIN_COUNT {
            left_bounds = left_bounds.union(&axis_bins[plane - 1].bounds);
            left_count += axis_bins[plane - 1].count;
            if left_count == 0 || left_count as usize == count {
                continue;
            }
            let cost = left_bounds.half_area() * left_count as f32 + right_cost[plane];
            if cost < best.0 {
                best = (cost, axis, plane);
            }
        }
    }
    let (best_cost, axis, plane) = best;
    let split_cost = TRAVERSAL_COST + best_cost / bounds.half_area().max(f32::MIN_POSITIVE);
    if one_kind && count <= MAX_LEAF_SIZE && split_cost >= count as f32 {
        return None;
    }
    if !best_cost.is_finite() {
        let mid = count / 2;
        let axis = largest_axis(extent);
        items.select_nth_unstable_by(mid, |a, b| a.centroid2[axis].total_cmp(&b.centroid2[axis]));
        return Some(mid);
    }
    Some(partition(items, |item| bin_of(item, axis) < plane))
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

#[derive(Clone, Copy)]
struct Bin {
    bounds: Bounds32,
    count: u32,
}

impl Bin {
    const EMPTY: Bin = Bin {
        bounds: Bounds32::EMPTY,
        count: 0,
    };
}

/// Moves items satisfying `goes_left` to the front; returns how many there are.
fn partition(items: &mut [BuildItem], goes_left: impl Fn(&BuildItem) -> bool) -> usize {
    let mut split = 0;
    for i in 0..items.len() {
        if goes_left(&items[i]) {
            items.swap(i, split);
            split += 1;
        }
    }
    split
}

#[cfg(test)]
mod tests {
    use super::*;

    fn item(min: [f32; 3], max: [f32; 3], index: u32, kind: u8) -> BuildItem {
        BuildItem::new(Bounds32 { min, max }, index, kind)
    }

    /// Every item lands in exactly one leaf, leaves hold at most
    /// MAX_LEAF_SIZE items of one kind, and every node's box contains its children's.
    #[test]
    fn leaves_cover_every_item_once_and_boxes_nest() {
        let mut items: Vec<BuildItem> = (0..1000u32)
            .map(|i| {
                let x = (i as f32 * 0.618_034).fract() * 100.0;
                let y = (i as f32 * 0.414_213).fract() * 100.0;
                item([x, y, 0.0], [x + 1.0, y + 1.0, 1.0], i, (i % 3 == 0) as u8)
            })
            .collect();
        let nodes = build(&mut items);
        let mut seen = vec![0; items.len()];
        for node in &nodes {
            if let BinaryContent::Leaf { first, count, kind } = node.content {
                assert!(count as usize <= MAX_LEAF_SIZE && count > 0);
                for item in &items[first as usize..(first + count) as usize] {
                    assert_eq!(item.kind, kind);
                    assert!(node.bounds.contains(&item.bounds));
                    seen[item.index as usize] += 1;
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
                assert!(nodes[index].bounds.contains(&nodes[index + 1].bounds));
                assert!(nodes[index].bounds.contains(&nodes[right as usize].bounds));
                let after_left = check_nesting(nodes, index + 1);
                assert_eq!(after_left, right as usize);
                check_nesting(nodes, right as usize)
            }
        }
    }

    /// A thousand copies of one box cannot be separated by any plane: the
    /// median fallback still ends in small leaves.
    #[test]
    fn identical_boxes_end_in_small_leaves() {
        let mut items: Vec<BuildItem> = (0..1000).map(|i| item([0.0; 3], [1.0; 3], i, 0)).collect();
        let nodes = build(&mut items);
        for node in &nodes {
            if let BinaryContent::Leaf { count, .. } = node.content {
                assert!(count as usize <= MAX_LEAF_SIZE);
            }
        }
    }
}
