//! Binned surface area heuristic builder (Wald 2007, "On fast construction of
//! SAH-based bounding volume hierarchies"): O(n log n), parallel over subtrees.

use crate::math::Aabb;

/// Bins per axis: 16 is within a few per cent of the full sweep's quality.
const BIN_COUNT: usize = 16;
/// Subtrees larger than this are built on two threads.
const PARALLEL_THRESHOLD: usize = 4096;
/// Relative cost of a traversal step against one primitive test.
const TRAVERSAL_COST: f64 = 0.5;
pub const MAX_LEAF_SIZE: usize = 4;

#[derive(Clone, Copy)]
pub struct BuildItem {
    pub bounds: Aabb,
    pub centroid: glam::DVec3,
    pub index: u32,
}

pub enum BuildNode {
    Leaf {
        bounds: Aabb,
        first: usize,
        count: usize,
    },
    Interior {
        bounds: Aabb,
        axis: usize,
        children: Box<[BuildNode; 2]>,
        node_count: usize,
    },
}

impl BuildNode {
    pub fn node_count(&self) -> usize {
        match self {
            BuildNode::Leaf { .. } => 1,
            BuildNode::Interior { node_count, .. } => *node_count,
        }
    }
}

/// Builds the subtree over `items`, whose first element sits at `first` in
/// the final primitive order; `items` is reordered in place.
pub fn build(items: &mut [BuildItem], first: usize) -> BuildNode {
    let bounds = items.iter().fold(Aabb::EMPTY, |b, i| b.union(i.bounds));
    let leaf = BuildNode::Leaf {
        bounds,
        first,
        count: items.len(),
    };
    if items.len() <= 1 {
        return leaf;
    }
    let centroid_bounds = items.iter().fold(Aabb::EMPTY, |b, i| b.include(i.centroid));
    let axis = centroid_bounds.largest_axis();
    let (low, high) = (centroid_bounds.min[axis], centroid_bounds.max[axis]);

    let mid = if high - low <= 0.0 {
        // All centroids coincide: no plane separates them.
        if items.len() <= MAX_LEAF_SIZE {
            return leaf;
        }
        items.len() / 2
    } else {
        // Put every centroid into a bin along the axis.
        let scale = BIN_COUNT as f64 / (high - low);
        let bin_of = |item: &BuildItem| (((item.centroid[axis] - low) * scale) as usize).min(BIN_COUNT - 1);
        let mut bin_bounds = [Aabb::EMPTY; BIN_COUNT];
        let mut bin_counts = [0usize; BIN_COUNT];
        for item in items.iter() {
            let b = bin_of(item);
            bin_bounds[b] = bin_bounds[b].union(item.bounds);
            bin_counts[b] += 1;
        }
        // Sweep from the right to get the area and count right of each plane.
        let mut right_area = [0.0; BIN_COUNT];
        let mut right_count = [0usize; BIN_COUNT];
        let (mut acc_bounds, mut acc_count) = (Aabb::EMPTY, 0);
        for b in (1..BIN_COUNT).rev() {
            acc_bounds = acc_bounds.union(bin_bounds[b]);
            acc_count += bin_counts[b];
            right_area[b] = acc_bounds.surface_area();
            right_count[b] = acc_count;
        }
        // Find the plane that minimises the SAH cost, sweeping from the left.
        let (mut best_cost, mut best_plane) = (f64::INFINITY, 1);
        let (mut left_bounds, mut left_count) = (Aabb::EMPTY, 0);
        for plane in 1..BIN_COUNT {
            left_bounds = left_bounds.union(bin_bounds[plane - 1]);
            left_count += bin_counts[plane - 1];
            if left_count == 0 || right_count[plane] == 0 {
                continue;
            }
            let cost = left_bounds.surface_area() * left_count as f64 + right_area[plane] * right_count[plane] as f64;
            if cost < best_cost {
                best_cost = cost;
                best_plane = plane;
            }
        }
        let parent_area = bounds.surface_area();
        let split_cost = TRAVERSAL_COST + best_cost / parent_area.max(f64::MIN_POSITIVE);
        if items.len() <= MAX_LEAF_SIZE && split_cost >= items.len() as f64 {
            return leaf;
        }
        if !best_cost.is_finite() {
            items.len() / 2
        } else {
            partition(items, |item| bin_of(item) < best_plane)
        }
    };

    // Recurse; large halves in parallel.
    let (left_items, right_items) = items.split_at_mut(mid);
    let (left, right) = if left_items.len() + right_items.len() > PARALLEL_THRESHOLD {
        rayon::join(|| build(left_items, first), || build(right_items, first + mid))
    } else {
        (build(left_items, first), build(right_items, first + mid))
    };
    let node_count = 1 + left.node_count() + right.node_count();
    BuildNode::Interior {
        bounds,
        axis,
        children: Box::new([left, right]),
        node_count,
    }
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
