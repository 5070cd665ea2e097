//! Which binary nodes become eight-wide nodes: the collapse of the binned
//! SAH tree ([`super::build`]) that minimises the SAH cost of the wide
//! tree, found exactly by dynamic programming over the binary tree
//! (Pinto 2010, "Fast and efficient collapsing of binary BVHs"; Ylitie et
//! al. 2017, "Efficient incoherent ray traversal on GPUs through
//! compressed wide BVHs", §3.1).
//!
//! The binary tree's leaves stay as they are, so their share of the SAH
//! cost is fixed and the cost left to minimise is the sum, over the wide
//! nodes, of their surface areas (each one traversal step, in units of the
//! root's area). A binary interior node either becomes a wide node (one
//! child slot of its parent, its own eight slots below it) or is opened
//! (its two subtrees take the parent's slots). Opening where slots allow
//! is what fills nodes: a greedy top-down collapse that always opens the
//! largest child leaves slots empty that a better choice higher up would
//! have used, and every wide node saved is 256 bytes and one box test.

use super::build::{BinaryContent, BinaryNode};
use super::bvh::WIDTH;
use arrayvec::ArrayVec;

/// What the collapse decided for one binary node, for each number of
/// slots k = 1 … [`WIDTH`] it may occupy in its parent.
#[derive(Clone, Copy, Debug)]
struct Choice {
    /// Least sum of wide-node areas for the subtree within k slots.
    cost: [f32; WIDTH],
    /// Slots given to the left subtree when opened within k slots, or 0
    /// when the node takes one slot itself (a wide node, or a leaf).
    left_slots: [u8; WIDTH],
    /// Slots given to the left subtree below the node's own wide node.
    left_slots_below: u8,
}

impl Choice {
    /// A leaf: one slot, no wide node.
    const LEAF: Choice = Choice {
        cost: [0.0; WIDTH],
        left_slots: [0; WIDTH],
        left_slots_below: 0,
    };
}

/// The collapse of one binary tree.
pub struct Collapse<'a> {
    binary: &'a [BinaryNode],
    choices: Vec<Choice>,
}

impl<'a> Collapse<'a> {
    /// Plans the collapse of `binary` (depth first, left child after its
    /// parent, as [`super::build::build`] makes it), children before parents.
    pub fn new(binary: &'a [BinaryNode]) -> Self {
        let mut choices = vec![Choice::LEAF; binary.len()];
        for index in (0..binary.len()).rev() {
            let BinaryContent::Interior { right } = binary[index].content else {
                continue;
            };
            let (left, right) = (choices[index + 1], choices[right as usize]);
            // Opened into exactly k slots: the best division between the
            // subtrees (costs only fall as slots are added, so "at most k"
            // is "exactly k").
            let mut opened = [(f32::INFINITY, 1u8); WIDTH + 1];
            for (k, best) in opened.iter_mut().enumerate().skip(2) {
                for left_slots in 1..k {
                    let cost = left.cost[left_slots - 1] + right.cost[k - left_slots - 1];
                    if cost < best.0 {
                        *best = (cost, left_slots as u8);
                    }
                }
            }
            let own = binary[index].bounds.half_area() + opened[WIDTH].0;
            let mut choice = Choice {
                cost: [own; WIDTH],
                left_slots: [0; WIDTH],
                left_slots_below: opened[WIDTH].1,
            };
            for (k, &(cost, left_slots)) in opened.iter().enumerate().skip(2) {
                // On a tie, open: one wide node fewer.
                if cost <= own {
                    choice.cost[k - 1] = cost;
                    choice.left_slots[k - 1] = left_slots;
                }
            }
            choices[index] = choice;
        }
        Self { binary, choices }
    }

    /// The children of the wide node standing for binary interior node
    /// `index`: binary nodes that are leaves or wide nodes themselves, left to right.
    pub fn children(&self, index: usize) -> ArrayVec<usize, WIDTH> {
        let mut children = ArrayVec::new();
        if let BinaryContent::Interior { right } = self.binary[index].content {
            let left_slots = usize::from(self.choices[index].left_slots_below);
            self.fill(index + 1, left_slots, &mut children);
            self.fill(right as usize, WIDTH - left_slots, &mut children);
        }
        children
    }

    /// Appends the slots binary node `index` takes when given `slots` of them.
    fn fill(&self, index: usize, slots: usize, children: &mut ArrayVec<usize, WIDTH>) {
        let left_slots = usize::from(self.choices[index].left_slots[slots - 1]);
        match self.binary[index].content {
            BinaryContent::Interior { right } if left_slots > 0 => {
                self.fill(index + 1, left_slots, children);
                self.fill(right as usize, slots - left_slots, children);
            }
            _ => children.push(index),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bounds::Bounds32;
    use crate::accel::build::{BuildItem, MAX_LEAF_SIZE, build};

    fn random_tree(count: u32, seed: u64) -> Vec<BinaryNode> {
        let mut state = seed;
        let mut next = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut items: Vec<BuildItem> = (0..count)
            .map(|index| {
                let min = [next() * 100.0, next() * 100.0, next() * 100.0];
                let max = min.map(|m| m + next() * 5.0);
                BuildItem::new(Bounds32 { min, max }, index, 0)
            })
            .collect();
        build(&mut items, &[super::super::build::LeafKind::sized(MAX_LEAF_SIZE)])
    }

    /// Sum of the wide nodes' areas (in `f64`) below and including the
    /// wide node for `index`, and how many wide nodes, visiting each slot;
    /// `leaves` counts the visits of each binary leaf.
    fn walk(
        binary: &[BinaryNode],
        index: usize,
        children: &dyn Fn(usize) -> ArrayVec<usize, WIDTH>,
        leaves: &mut [u32],
    ) -> (f64, usize) {
        let (mut cost, mut count) = (f64::from(binary[index].bounds.half_area()), 1);
        for child in children(index) {
            match binary[child].content {
                BinaryContent::Leaf { .. } => leaves[child] += 1,
                BinaryContent::Interior { .. } => {
                    let (c, n) = walk(binary, child, children, leaves);
                    cost += c;
                    count += n;
                }
            }
        }
        (cost, count)
    }

    /// The top-down greedy collapse: open the widest interior child until
    /// the node has eight.
    fn greedy_children(binary: &[BinaryNode], index: usize) -> ArrayVec<usize, WIDTH> {
        let mut children = ArrayVec::new();
        if let BinaryContent::Interior { right } = binary[index].content {
            children.extend([index + 1, right as usize]);
        }
        while children.len() < WIDTH {
            let widest = (0..children.len())
                .filter(|&slot| matches!(binary[children[slot]].content, BinaryContent::Interior { .. }))
                .max_by(|&a, &b| {
                    let area = |slot: usize| binary[children[slot]].bounds.half_area();
                    area(a).total_cmp(&area(b))
                });
            let Some(slot) = widest else { break };
            let opened = children[slot];
            let BinaryContent::Interior { right } = binary[opened].content else {
                break;
            };
            children[slot] = opened + 1;
            children.push(right as usize);
        }
        children
    }

    /// Least cost of the wide node for `index` by trying every frontier of
    /// at most eight slots below it (exhaustive, unlike the table).
    fn exhaustive(binary: &[BinaryNode], index: usize) -> f64 {
        fn frontiers(binary: &[BinaryNode], index: usize, most: usize) -> Vec<Vec<usize>> {
            let mut all = vec![vec![index]];
            if most < 2 {
                return all;
            }
            if let BinaryContent::Interior { right } = binary[index].content {
                for left_part in frontiers(binary, index + 1, most - 1) {
                    for right_part in frontiers(binary, right as usize, most - left_part.len()) {
                        all.push([left_part.clone(), right_part].concat());
                    }
                }
            }
            all.retain(|f| f.len() <= most);
            all
        }
        let BinaryContent::Interior { right } = binary[index].content else {
            return 0.0;
        };
        let mut best = f64::INFINITY;
        for left_part in frontiers(binary, index + 1, WIDTH - 1) {
            for right_part in frontiers(binary, right as usize, WIDTH - left_part.len()) {
                let cost: f64 = left_part
                    .iter()
                    .chain(&right_part)
                    .map(|&child| exhaustive(binary, child))
                    .sum();
                best = best.min(cost);
            }
        }
        f64::from(binary[index].bounds.half_area()) + best
    }

    /// Every binary leaf is reached exactly once, and the planned collapse
    /// costs no more than the greedy one (it is optimal; the greedy is
    /// one of the collapses it considers), with fewer nodes here. Costs are
    /// sums of a few thousand `f32` areas, compared with 10⁻⁵ relative
    /// slack for the table's `f32` additions.
    #[test]
    fn planned_collapse_covers_every_leaf_and_beats_greedy() {
        let binary = random_tree(5000, 7);
        let collapse = Collapse::new(&binary);
        let mut leaves = vec![0u32; binary.len()];
        let (planned, planned_nodes) = walk(&binary, 0, &|index| collapse.children(index), &mut leaves);
        for (node, &visits) in binary.iter().zip(&leaves) {
            let expected = u32::from(matches!(node.content, BinaryContent::Leaf { .. }));
            assert_eq!(visits, expected);
        }
        let (greedy, greedy_nodes) = walk(&binary, 0, &|index| greedy_children(&binary, index), &mut leaves);
        assert!(planned <= greedy * (1.0 + 1e-5), "{planned} > {greedy}");
        assert!(planned_nodes < greedy_nodes, "{planned_nodes} ≥ {greedy_nodes}");
    }

    /// On small trees the plan's cost equals the least over every
    /// possible collapse (to the same 10⁻⁵ relative slack).
    #[test]
    fn planned_collapse_is_optimal_on_small_trees() {
        for seed in 0..20 {
            let binary = random_tree(40 + seed as u32, seed);
            let collapse = Collapse::new(&binary);
            let mut leaves = vec![0u32; binary.len()];
            let (planned, _) = walk(&binary, 0, &|index| collapse.children(index), &mut leaves);
            let best = exhaustive(&binary, 0);
            assert!((planned - best).abs() <= 1e-5 * best, "seed {seed}: {planned} vs {best}");
        }
    }
}
