//! A four-wide bounding volume hierarchy: the binned-SAH binary tree
//! ([`super::build`]) collapsed so each node holds up to four children,
//! whose boxes are tested together (Wald et al. 2008, "Getting rid of
//! packets"; Embree's BVH4). A node is one 128-byte, cache-line-aligned
//! record: the children's single-precision bounds as structure-of-arrays
//! (all min x, then all max x, …), so the four slab tests are four-lane
//! vector arithmetic, then the children's references.
//!
//! Traversal is front to back: the children a ray enters are visited
//! nearest first, and a subtree whose entry distance lies beyond the
//! nearest hit so far is skipped. The box test is conservative (see
//! [`TraversalRay`]), so the BVH never culls a primitive the exact
//! primitive test would hit.
//!
//! The BVH knows only boxes and leaves: what a leaf's primitives are, and
//! how to hit them, is the caller's closure. Leaves hold primitives of one
//! kind (triangles, or other shapes), numbered within that kind.

use super::bounds::{Bounds32, round_up};
use super::build::{self, BinaryContent, BinaryNode, BuildItem};
use crate::math::{Aabb, Ray};

/// Children per node.
pub const WIDTH: usize = 4;
/// Kinds of primitive the leaves distinguish (triangles, shapes).
pub const KIND_COUNT: usize = 2;

/// Marks a child reference as a leaf (its low bits are the first primitive).
const LEAF_BIT: u32 = 1 << 31;
/// An unused child slot (its box is empty, so no ray enters it).
const EMPTY_CHILD: u32 = u32::MAX;

/// Entries of the traversal stack: a four-wide tree built with the depth
/// bound of the builder never needs more (3 per level below the root).
const STACK_SIZE: usize = 256;

/// `1 + 2γ₃` in single precision (γₙ = nu/(1 − nu), u = 2⁻²⁴), rounded up
/// generously: a far slab distance computed with three roundings (the
/// subtraction, the reciprocal and the product) times this is at least the
/// exact one (pbrt-v4 §6.8.2).
const FAR_SCALE: f32 = 1.0 + 4.0 * f32::EPSILON;

/// One node: bounds of four children as structure-of-arrays, then what they are.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node {
    /// `bounds[2 * axis]` holds the children's minima on `axis`,
    /// `bounds[2 * axis + 1]` their maxima.
    bounds: [[f32; WIDTH]; 6],
    /// Interior child: node index. Leaf: `LEAF_BIT | first primitive`.
    /// `EMPTY_CHILD` for unused slots.
    children: [u32; WIDTH],
    /// Primitives in each leaf child (0 for interior or unused slots).
    leaf_count: [u8; WIDTH],
    /// Kind of each leaf child's primitives.
    leaf_kind: [u8; WIDTH],
}

impl Node {
    const EMPTY: Node = Node {
        bounds: [
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
        ],
        children: [EMPTY_CHILD; WIDTH],
        leaf_count: [0; WIDTH],
        leaf_kind: [0; WIDTH],
    };

    fn set_bounds(&mut self, lane: usize, bounds: &Bounds32) {
        for axis in 0..3 {
            self.bounds[2 * axis][lane] = bounds.min[axis];
            self.bounds[2 * axis + 1][lane] = bounds.max[axis];
        }
    }
}

/// A leaf: primitives `first .. first + count` of one kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Leaf {
    pub kind: u8,
    pub first: u32,
    pub count: u32,
}

/// A primitive to build over: its exact bounds and its kind.
#[derive(Clone, Copy, Debug)]
pub struct BuildPrimitive {
    pub bounds: Aabb,
    /// Below [`KIND_COUNT`].
    pub kind: u8,
}

#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    bounds: Aabb,
    leaf_count: usize,
}

impl Bvh {
    /// Builds over `primitives`. Returns the tree and, per kind, the order
    /// in which the caller must store that kind's primitives: leaves index
    /// into these per-kind lists.
    pub fn build(primitives: &[BuildPrimitive]) -> (Self, [Vec<u32>; KIND_COUNT]) {
        if primitives.is_empty() {
            return (
                Self {
                    bounds: Aabb::EMPTY,
                    ..Self::default()
                },
                Default::default(),
            );
        }
        let mut items: Vec<BuildItem> = primitives
            .iter()
            .enumerate()
            .map(|(i, p)| BuildItem::new(Bounds32::enclosing(&p.bounds), i as u32, p.kind))
            .collect();
        let binary = build::build(&mut items);

        // Number each kind's primitives in leaf order.
        let mut orders: [Vec<u32>; KIND_COUNT] = Default::default();
        let mut index_within_kind = Vec::with_capacity(items.len());
        for item in &items {
            let order = &mut orders[item.kind as usize];
            index_within_kind.push(order.len() as u32);
            order.push(item.index);
        }

        let mut collapser = Collapser {
            binary: &binary,
            index_within_kind: &index_within_kind,
            nodes: Vec::with_capacity(binary.len() / 2 + 1),
            leaf_count: 0,
        };
        collapser.node(0);
        let bounds = binary[0].bounds.to_aabb();
        let leaf_count = collapser.leaf_count;
        (
            Self {
                nodes: collapser.nodes,
                bounds,
                leaf_count,
            },
            orders,
        )
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub fn leaf_count(&self) -> usize {
        self.leaf_count
    }

    /// Bytes the nodes occupy.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>()
    }

    /// Bounds of everything in the tree (outward-rounded to `f32`).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Visits the leaves `ray` enters, nearest first, skipping those beyond
    /// `*t_max`. `visit` tests a leaf's primitives, lowers `*t_max` to the
    /// nearest hit it finds, and returns true to end the traversal (any-hit
    /// queries stop at the first hit).
    #[inline]
    pub fn traverse(&self, ray: &TraversalRay, t_max: &mut f64, mut visit: impl FnMut(Leaf, &mut f64) -> bool) {
        if self.nodes.is_empty() {
            return;
        }
        let mut limit = traversal_limit(*t_max);
        let mut stack = [StackEntry::ROOT; STACK_SIZE];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let entry = stack[depth];
            if entry.t_near > limit {
                continue;
            }
            if entry.child & LEAF_BIT != 0 {
                let leaf = Leaf {
                    kind: entry.kind,
                    first: entry.child & !LEAF_BIT,
                    count: entry.count as u32,
                };
                if visit(leaf, t_max) {
                    return;
                }
                limit = traversal_limit(*t_max);
                continue;
            }
            let node = &self.nodes[entry.child as usize];
            let (t_near, hit) = ray.enter_children(node, limit);
            // Push the children entered, farthest first, so the nearest is popped next.
            let mut order = [0usize; WIDTH];
            let mut entered = 0;
            for lane in 0..WIDTH {
                if hit[lane] {
                    // Insertion into `order`, sorted by decreasing distance.
                    let mut position = entered;
                    while position > 0 && t_near[order[position - 1]] < t_near[lane] {
                        order[position] = order[position - 1];
                        position -= 1;
                    }
                    order[position] = lane;
                    entered += 1;
                }
            }
            for &lane in &order[..entered] {
                stack[depth] = StackEntry {
                    child: node.children[lane],
                    t_near: t_near[lane],
                    count: node.leaf_count[lane],
                    kind: node.leaf_kind[lane],
                };
                depth += 1;
            }
        }
    }
}

/// The farthest entry distance worth visiting when the nearest hit so far
/// is at `t_max`: rounded up to `f32` and widened by [`FAR_SCALE`] like the
/// exit distances. A ray passing a hair outside a box's corner (which the
/// widened exit distances still let in) enters its last slab a hair after
/// the corner, while the triangle test, itself rounded, may report a hit of
/// a triangle at that corner as no farther than `t_max`; without the same
/// widening here that leaf would be skipped, and a ray through a shared
/// vertex could find neither of the triangles that meet there.
#[inline]
fn traversal_limit(t_max: f64) -> f32 {
    (round_up(t_max) * FAR_SCALE).next_up()
}

#[derive(Clone, Copy, Debug)]
struct StackEntry {
    child: u32,
    t_near: f32,
    count: u8,
    kind: u8,
}

impl StackEntry {
    const ROOT: StackEntry = StackEntry {
        child: 0,
        t_near: 0.0,
        count: 0,
        kind: 0,
    };
}

/// A ray prepared for conservative single-precision box tests.
///
/// The slab distance to a plane b is (b − o)/d. Each is computed in `f32`
/// from an origin rounded *towards the safe side*: for the planes a ray
/// enters, an origin that makes the distance no larger than the exact one,
/// and for the planes it leaves, one that makes it no smaller. The
/// remaining error is relative (three roundings), which scaling the exit
/// distances by [`FAR_SCALE`] covers. So a box the exact ray touches is
/// always entered, however far the origin lies from the box.
///
/// A zero direction component has an infinite reciprocal: the slab's
/// distances are then ±∞ (the ray is inside it for all t or for none), or
/// NaN when the origin lies exactly in the plane (0 · ∞). The running
/// maximum and minimum are written as `if x > m { x } else { m }`, which
/// keeps `m` when `x` is NaN (as the `maxps`/`minps` instructions do), so
/// such a slab is simply not counted against the ray: conservative.
#[derive(Clone, Copy, Debug)]
pub struct TraversalRay {
    /// Origin for the entry planes, per axis.
    entry_origin: [f32; 3],
    /// Origin for the exit planes, per axis.
    exit_origin: [f32; 3],
    reciprocal: [f32; 3],
    /// Index into a node's `bounds` of the entry and exit plane of each axis.
    entry_plane: [usize; 3],
    exit_plane: [usize; 3],
}

impl TraversalRay {
    pub fn new(ray: &Ray) -> Self {
        let mut prepared = TraversalRay {
            entry_origin: [0.0; 3],
            exit_origin: [0.0; 3],
            reciprocal: [0.0; 3],
            entry_plane: [0; 3],
            exit_plane: [0; 3],
        };
        for axis in 0..3 {
            let direction = ray.direction[axis];
            let origin = ray.origin[axis];
            let down = super::bounds::round_down(origin);
            let up = round_up(origin);
            let reciprocal = (1.0 / direction) as f32;
            prepared.reciprocal[axis] = reciprocal;
            if reciprocal >= 0.0 {
                // Enters through the minimum: (min − o)·r is smallest for the largest o.
                prepared.entry_plane[axis] = 2 * axis;
                prepared.exit_plane[axis] = 2 * axis + 1;
                prepared.entry_origin[axis] = up;
                prepared.exit_origin[axis] = down;
            } else {
                prepared.entry_plane[axis] = 2 * axis + 1;
                prepared.exit_plane[axis] = 2 * axis;
                prepared.entry_origin[axis] = down;
                prepared.exit_origin[axis] = up;
            }
        }
        prepared
    }

    /// Entry distances of the four children and which of them the ray
    /// enters before `t_max`.
    #[inline(always)]
    fn enter_children(&self, node: &Node, t_max: f32) -> ([f32; WIDTH], [bool; WIDTH]) {
        let mut t_entry = [0.0f32; WIDTH];
        let mut t_exit = [t_max; WIDTH];
        for axis in 0..3 {
            let entry_planes = &node.bounds[self.entry_plane[axis]];
            let exit_planes = &node.bounds[self.exit_plane[axis]];
            for lane in 0..WIDTH {
                let enter = (entry_planes[lane] - self.entry_origin[axis]) * self.reciprocal[axis];
                let exit = (exit_planes[lane] - self.exit_origin[axis]) * self.reciprocal[axis] * FAR_SCALE;
                t_entry[lane] = if enter > t_entry[lane] { enter } else { t_entry[lane] };
                t_exit[lane] = if exit < t_exit[lane] { exit } else { t_exit[lane] };
            }
        }
        let mut hit = [false; WIDTH];
        for lane in 0..WIDTH {
            hit[lane] = t_entry[lane] <= t_exit[lane];
        }
        (t_entry, hit)
    }
}

/// Turns the binary tree into four-wide nodes, depth first.
struct Collapser<'a> {
    binary: &'a [BinaryNode],
    index_within_kind: &'a [u32],
    nodes: Vec<Node>,
    leaf_count: usize,
}

impl Collapser<'_> {
    /// Emits the four-wide node standing for binary node `index` (or, for
    /// a binary leaf at the root, a node with that one leaf) and returns its index.
    fn node(&mut self, index: usize) -> u32 {
        // Open the binary subtree: repeatedly replace the interior child of
        // largest area by its two children, up to four children.
        let mut children: Vec<usize> = match self.binary[index].content {
            BinaryContent::Leaf { .. } => vec![index],
            BinaryContent::Interior { right } => vec![index + 1, right as usize],
        };
        while children.len() < WIDTH {
            let widest = children
                .iter()
                .enumerate()
                .filter(|&(_, &child)| matches!(self.binary[child].content, BinaryContent::Interior { .. }))
                .max_by(|a, b| {
                    let area = |i: usize| self.binary[i].bounds.half_area();
                    area(*a.1).total_cmp(&area(*b.1))
                })
                .map(|(slot, _)| slot);
            let Some(slot) = widest else { break };
            let opened = children[slot];
            let BinaryContent::Interior { right } = self.binary[opened].content else {
                break;
            };
            children[slot] = opened + 1;
            children.push(right as usize);
        }

        let me = self.nodes.len();
        self.nodes.push(Node::EMPTY);
        for (lane, &child) in children.iter().enumerate() {
            let binary = self.binary[child];
            let (reference, count, kind) = match binary.content {
                BinaryContent::Leaf { first, count, kind } => {
                    self.leaf_count += 1;
                    let first = self.index_within_kind[first as usize];
                    (LEAF_BIT | first, count as u8, kind)
                }
                BinaryContent::Interior { .. } => (self.node(child), 0, 0),
            };
            let node = &mut self.nodes[me];
            node.set_bounds(lane, &binary.bounds);
            node.children[lane] = reference;
            node.leaf_count[lane] = count;
            node.leaf_kind[lane] = kind;
        }
        me as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn random_boxes(count: usize, seed: u64) -> Vec<Aabb> {
        let mut state = seed;
        let mut next = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..count)
            .map(|_| {
                let c = DVec3::new(next(), next(), next()) * 100.0;
                let e = DVec3::new(next(), next(), next()) * 2.0;
                Aabb::new(c - e, c + e)
            })
            .collect()
    }

    /// Random boxes; the BVH's nearest hit must equal brute force's, and an
    /// any-hit query must agree on whether there is one.
    #[test]
    fn matches_brute_force_on_random_boxes() {
        let boxes = random_boxes(2000, 12345);
        let primitives: Vec<BuildPrimitive> = boxes
            .iter()
            .enumerate()
            .map(|(i, b)| BuildPrimitive {
                bounds: *b,
                kind: (i % 2) as u8,
            })
            .collect();
        let (bvh, orders) = Bvh::build(&primitives);
        let mut all: Vec<u32> = orders.iter().flatten().copied().collect();
        all.sort_unstable();
        assert_eq!(all, (0..boxes.len() as u32).collect::<Vec<_>>());
        let probe = random_boxes(2000, 999);
        for b in &probe {
            let ray = Ray::new(b.min * 1.2 - DVec3::splat(10.0), b.max - DVec3::splat(50.0));
            let inverse = DVec3::ONE / ray.direction;
            let brute = boxes
                .iter()
                .filter_map(|b| b.hit_distance(ray.origin, inverse, f64::INFINITY))
                .fold(f64::INFINITY, f64::min);
            let traversal = TraversalRay::new(&ray);
            let mut t_max = f64::INFINITY;
            bvh.traverse(&traversal, &mut t_max, |leaf, t_max| {
                for i in leaf.first..leaf.first + leaf.count {
                    let original = orders[leaf.kind as usize][i as usize] as usize;
                    if let Some(t) = boxes[original].hit_distance(ray.origin, inverse, *t_max) {
                        *t_max = t;
                    }
                }
                false
            });
            assert_eq!(brute, t_max);
        }
    }

    /// Nodes fill one 128-byte record, aligned to cache lines.
    #[test]
    fn nodes_are_two_cache_lines() {
        assert_eq!(std::mem::size_of::<Node>(), 128);
        assert_eq!(std::mem::align_of::<Node>(), 64);
    }

    /// A ray grazing a box face, with a zero (or negative zero) direction
    /// component in that axis, still enters the box; one just outside does not.
    #[test]
    fn grazing_rays_enter_and_near_misses_do_not() {
        let primitives = [BuildPrimitive {
            bounds: Aabb::new(DVec3::splat(-1.0), DVec3::splat(1.0)),
            kind: 0,
        }];
        let (bvh, _) = Bvh::build(&primitives);
        let count_leaves = |ray: Ray| {
            let mut visits = 0;
            let mut t_max = f64::INFINITY;
            bvh.traverse(&TraversalRay::new(&ray), &mut t_max, |_, _| {
                visits += 1;
                false
            });
            visits
        };
        for direction in [DVec3::X, DVec3::new(1.0, -0.0, 0.0)] {
            assert_eq!(count_leaves(Ray::new(DVec3::new(-3.0, 1.0, 0.0), direction)), 1);
            assert_eq!(count_leaves(Ray::new(DVec3::new(-3.0, 1.0 + 1e-6, 0.0), direction)), 0);
        }
        // A far-away origin whose f32 rounding would otherwise shift it off the box.
        let origin = DVec3::new(-1e7 - 0.3, 1.0, 0.0);
        assert_eq!(count_leaves(Ray::new(origin, DVec3::X)), 1);
    }
}
