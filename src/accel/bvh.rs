//! An eight-wide bounding volume hierarchy: the binned-SAH binary tree
//! ([`super::build`]) collapsed so each node holds up to eight children,
//! whose boxes are tested together (Wald et al. 2008, "Getting rid of
//! packets"; Embree's BVH8). A node is one 256-byte, cache-line-aligned
//! record: the children's single-precision bounds as structure-of-arrays
//! (all min x, then all max x, …), so the eight slab tests are eight-lane
//! vector arithmetic (two four-lane halves on SSE2), then the children's
//! references.
//!
//! Why eight and not four: a ray's cost is mostly its chain of dependent
//! node loads, and eight-wide nodes make that chain a third shorter (a
//! tree of depth log₈ n rather than log₄ n) for the same bytes per child.
//! The two halves of a node's test are independent, so they overlap. On
//! the bunny meshes (3.7k, 59k, 941k triangles) rays ran 4–19% faster than
//! with four-wide nodes; the shipped scenes ran level (docs/performance.md).
//!
//! The tree's traversal, front to back, with the box test conservative so
//! that it never culls a primitive the exact primitive test would hit, is
//! [`super::traversal`]. The BVH knows only boxes and leaves: what a leaf's
//! primitives are, and how to hit them, is the caller's
//! [`super::LeafVisitor`]. Leaves hold primitives of one kind (the scene's:
//! triangles, spheres, other shapes), numbered within that kind.

use super::bounds::Bounds32;
use super::build::{self, BinaryContent, BinaryNode, Box4, BuildItem, LeafKind, MAX_LEAF_SIZE};
use super::collapse::Collapse;
use super::kernel::{Avx2, Kernel};
use crate::math::Aabb;
use arrayvec::ArrayVec;

/// Children per node.
pub const WIDTH: usize = 8;
/// Kinds of primitive the leaves distinguish (the scene's are triangles,
/// spheres and other shapes).
pub const KIND_COUNT: usize = 3;

/// A child reference is a node index, or a leaf: `LEAF_BIT`, the kind in
/// bits 29–30, the primitive count − 1 in bits 27–28, the first primitive
/// in the low 27 bits. So one 32-bit word says everything a traversal step
/// needs, and a stack entry (reference and entry distance) is 64 bits.
pub(super) const LEAF_BIT: u32 = 1 << 31;
const KIND_SHIFT: u32 = 29;
const COUNT_SHIFT: u32 = 27;
const FIRST_MASK: u32 = (1 << COUNT_SHIFT) - 1;
/// Most primitives of one kind a BVH can index.
pub const MAX_PRIMITIVES_PER_KIND: usize = 1 << COUNT_SHIFT;
const _: () = assert!(KIND_COUNT * MAX_PRIMITIVES_PER_KIND <= build::MAX_ITEMS);
/// An unused child slot (its box is empty, so no ray enters it).
const EMPTY_CHILD: u32 = u32::MAX;

/// One node: bounds of eight children as structure-of-arrays, then what they are.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Node {
    /// `bounds[2 * axis]` holds the children's minima on `axis`,
    /// `bounds[2 * axis + 1]` their maxima.
    pub(super) bounds: [[f32; WIDTH]; 6],
    /// Node index or leaf reference (see `LEAF_BIT`); `EMPTY_CHILD` for unused slots.
    pub(super) children: [u32; WIDTH],
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
    };

    fn set_bounds(&mut self, lane: usize, bounds: &Box4) {
        let (lower, upper) = (bounds.lower(), bounds.upper());
        for axis in 0..3 {
            self.bounds[2 * axis][lane] = lower[axis];
            self.bounds[2 * axis + 1][lane] = upper[axis];
        }
    }
}

/// A leaf: primitives `first .. first + count` of one kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Leaf {
    /// Kind of every primitive in the leaf (below [`KIND_COUNT`]).
    pub kind: u8,
    /// Index of the first primitive within its kind's leaf-ordered list.
    pub first: u32,
    /// Number of primitives, 1 to [`MAX_LEAF_SIZE`].
    pub count: u32,
}

impl Leaf {
    /// The leaf a child reference with `LEAF_BIT` set stands for.
    #[inline(always)]
    pub(super) fn from_reference(reference: u32) -> Self {
        Leaf {
            kind: ((reference >> KIND_SHIFT) & 3) as u8,
            first: reference & FIRST_MASK,
            count: ((reference >> COUNT_SHIFT) & 3) + 1,
        }
    }
}

/// A primitive to build over: its exact bounds and its kind.
#[derive(Clone, Copy, Debug)]
pub struct BuildPrimitive {
    /// Exact bounds; rounded outward to `f32` for the tree.
    pub bounds: Aabb,
    /// Below [`KIND_COUNT`].
    pub kind: u8,
}

/// The eight-wide BVH: nodes in an array (root at 0), built once per scene
/// and read only afterwards, so traversal needs no locks.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    pub(super) nodes: Vec<Node>,
    bounds: Aabb,
    leaf_count: usize,
    /// Interior nodes on the longest path from the root.
    depth: usize,
    /// Whether the nodes outgrow the caches near a core, so that the
    /// traversal prefetches the children it defers.
    pub(super) prefetches: bool,
    /// Present when traversals run compiled for AVX2 (see [`Kernel`]).
    pub(super) avx2: Option<Avx2>,
}

/// Node bytes above which the traversal prefetches the children it defers.
/// Measured on the subdivided bunnies: the 0.8 MB tree of 59k triangles ran
/// up to 7% slower with prefetches (its nodes stay in the caches near the
/// core, so they only add instructions), the 12 MB tree of 941k triangles
/// 13–38% faster (docs/performance.md). The bound lies between.
const PREFETCH_MIN_BYTES: usize = 4 << 20;

impl Bvh {
    /// Builds over `primitives` with leaves of up to four primitives.
    /// Returns the tree and, per kind, the order in which the caller must
    /// store that kind's primitives: leaves index into these per-kind lists.
    pub fn build(primitives: &[BuildPrimitive]) -> (Self, [Vec<u32>; KIND_COUNT]) {
        Self::build_with_leaf_kinds(primitives, [LeafKind::sized(MAX_LEAF_SIZE); KIND_COUNT])
    }

    /// As [`Bvh::build`], with leaves of kind k made as `kinds[k]` says:
    /// up to 1, 2 or 4 primitives tested together (3 is taken as 2; 1 suits
    /// primitives whose test costs far more than a box test), and what
    /// testing them costs against a traversal step.
    pub fn build_with_leaf_kinds(primitives: &[BuildPrimitive], kinds: [LeafKind; KIND_COUNT]) -> (Self, [Vec<u32>; KIND_COUNT]) {
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
        let binary = build::build(&mut items, &kinds);

        // Number each kind's primitives in leaf order.
        let mut orders: [Vec<u32>; KIND_COUNT] = Default::default();
        let mut index_within_kind = Vec::with_capacity(items.len());
        for item in &items {
            let order = &mut orders[item.kind() as usize];
            index_within_kind.push(order.len() as u32);
            order.push(item.index());
        }

        let mut collapser = Collapser {
            binary: &binary,
            collapse: Collapse::new(&binary),
            index_within_kind: &index_within_kind,
            // A large tree's nodes on huge pages.
            nodes: super::huge_pages::with_capacity(binary.len() / 2 + 1),
            leaf_count: 0,
            depth: 0,
        };
        collapser.node(0, 1);
        let bounds = binary[0].bounds.to_bounds().to_aabb();
        let prefetches = collapser.nodes.len() * std::mem::size_of::<Node>() > PREFETCH_MIN_BYTES;
        (
            Self {
                nodes: collapser.nodes,
                bounds,
                leaf_count: collapser.leaf_count,
                depth: collapser.depth,
                prefetches,
                avx2: Avx2::detect(),
            },
            orders,
        )
    }

    /// The proof of AVX2 when traversals run compiled for it, for callers
    /// that compile their own loops to match ([`Avx2::run`]).
    pub fn avx2(&self) -> Option<Avx2> {
        self.avx2
    }

    /// The kernel traversals run with.
    pub fn kernel(&self) -> Kernel {
        match self.avx2 {
            Some(_) => Kernel::Avx2,
            None => Kernel::Portable,
        }
    }

    /// Runs traversals with `kernel`, if this CPU has it (else the portable
    /// one): to compare the kernels. Builds choose [`Kernel::chosen`].
    pub fn set_kernel(&mut self, kernel: Kernel) {
        self.avx2 = match kernel {
            Kernel::Avx2 => Avx2::detect(),
            Kernel::Portable => None,
        };
    }

    /// Number of eight-wide nodes (interior nodes only; leaves are references).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Number of leaves.
    pub fn leaf_count(&self) -> usize {
        self.leaf_count
    }

    /// The leaves holding primitives of `kind`, in the order of their
    /// first primitive: they cover that kind's leaf-ordered list once.
    pub fn leaves(&self, kind: u8) -> Vec<Leaf> {
        let mut leaves: Vec<Leaf> = self
            .nodes
            .iter()
            .flat_map(|node| node.children)
            .filter(|&child| child != EMPTY_CHILD && child & LEAF_BIT != 0)
            .map(Leaf::from_reference)
            .filter(|leaf| leaf.kind == kind)
            .collect();
        leaves.sort_unstable_by_key(|leaf| leaf.first);
        leaves
    }

    /// Bytes the nodes occupy.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>()
    }

    /// Bounds of everything in the tree (outward-rounded to `f32`).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Interior nodes on the longest path from the root.
    pub fn depth(&self) -> usize {
        self.depth
    }
}

/// Turns the binary tree into eight-wide nodes, depth first, as [`Collapse`] plans.
struct Collapser<'a> {
    binary: &'a [BinaryNode],
    collapse: Collapse<'a>,
    index_within_kind: &'a [u32],
    nodes: Vec<Node>,
    leaf_count: usize,
    depth: usize,
}

impl Collapser<'_> {
    /// Emits the eight-wide node standing for binary node `index` (or, for
    /// a binary leaf at the root, a node with that one leaf) and returns its index.
    fn node(&mut self, index: usize, depth: usize) -> u32 {
        self.depth = self.depth.max(depth);
        let children = match self.binary[index].content {
            BinaryContent::Leaf { .. } => ArrayVec::from_iter([index]),
            BinaryContent::Interior { .. } => self.collapse.children(index),
        };

        let me = self.nodes.len();
        self.nodes.push(Node::EMPTY);
        for (lane, &child) in children.iter().enumerate() {
            let binary = self.binary[child];
            let reference = match binary.content {
                BinaryContent::Leaf { first, count, kind } => {
                    self.leaf_count += 1;
                    let first = self.index_within_kind[first as usize];
                    debug_assert!((first as usize) < MAX_PRIMITIVES_PER_KIND && (1..=4).contains(&count));
                    LEAF_BIT | (u32::from(kind) << KIND_SHIFT) | ((count - 1) << COUNT_SHIFT) | first
                }
                BinaryContent::Interior { .. } => self.node(child, depth + 1),
            };
            let node = &mut self.nodes[me];
            node.set_bounds(lane, &binary.bounds);
            node.children[lane] = reference;
        }
        me as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::traversal::{FIXED_STACK, LeafVisitor, VisitFn};
    use crate::math::Ray;
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
                kind: (i % KIND_COUNT) as u8,
            })
            .collect();
        let (bvh, orders) = Bvh::build(&primitives);
        let mut all: Vec<u32> = orders.iter().flatten().copied().collect();
        all.sort_unstable();
        assert_eq!(all, (0..boxes.len() as u32).collect::<Vec<_>>());
        let probe = random_boxes(2000, 999);
        for b in &probe {
            let ray = Ray::new(b.min * 1.2 - DVec3::splat(10.0), b.max - DVec3::splat(50.0));
            let (brute, t_max) = nearest_box_both_ways(&bvh, &orders, &boxes, &ray);
            assert_eq!(brute, t_max);
        }
    }

    /// A visitor that counts the leaves prefetched.
    struct Counting<'a, F> {
        visit: F,
        prefetched: &'a std::cell::Cell<usize>,
    }

    impl<F: FnMut(Leaf, &mut f64) -> bool> LeafVisitor for Counting<'_, F> {
        fn visit(&mut self, leaf: Leaf, t_max: &mut f64, _avx2: Option<Avx2>) -> bool {
            (self.visit)(leaf, t_max)
        }

        fn prefetch(&self, _leaf: Leaf) {
            self.prefetched.set(self.prefetched.get() + 1);
        }
    }

    /// With prefetching forced on (as in a tree larger than the caches),
    /// the traversal visits the same leaves and gives the same answers:
    /// the nearest hit equals brute force's, occlusion agrees, and leaves
    /// were indeed prefetched.
    #[test]
    fn prefetching_changes_no_answer() {
        let boxes = random_boxes(3000, 777);
        let primitives: Vec<BuildPrimitive> = boxes.iter().map(|b| BuildPrimitive { bounds: *b, kind: 0 }).collect();
        let (mut bvh, orders) = Bvh::build(&primitives);
        assert!(!bvh.prefetches, "a small tree does not prefetch");
        bvh.prefetches = true;
        let prefetched = std::cell::Cell::new(0usize);
        for b in &random_boxes(2000, 4242) {
            let ray = Ray::new(b.min * 1.3 - DVec3::splat(20.0), b.max - DVec3::splat(40.0));
            let inverse = DVec3::ONE / ray.direction;
            let hit = |leaf: Leaf, t_max: f64| {
                (leaf.first..leaf.first + leaf.count)
                    .filter_map(|i| boxes[orders[0][i as usize] as usize].hit_distance(ray.origin, inverse, t_max))
                    .reduce(f64::min)
            };
            let brute = boxes
                .iter()
                .filter_map(|b| b.hit_distance(ray.origin, inverse, f64::INFINITY))
                .fold(f64::INFINITY, f64::min);
            let mut nearest = f64::INFINITY;
            bvh.traverse_nearest(
                &ray,
                &mut nearest,
                &mut Counting {
                    visit: |leaf: Leaf, t_max: &mut f64| {
                        if let Some(t) = hit(leaf, *t_max) {
                            *t_max = t;
                        }
                        false
                    },
                    prefetched: &prefetched,
                },
            );
            assert_eq!(nearest, brute);
            let mut any = f64::INFINITY;
            let mut occluded = false;
            bvh.traverse_any(
                &ray,
                &mut any,
                &mut Counting {
                    visit: |leaf: Leaf, t_max: &mut f64| {
                        occluded = hit(leaf, *t_max).is_some();
                        occluded
                    },
                    prefetched: &prefetched,
                },
            );
            assert_eq!(occluded, brute.is_finite());
        }
        assert!(prefetched.get() > 0);
    }

    /// Both kernels visit the same leaves in the same order with the same
    /// bounds, so every answer is the same bit for bit: random boxes, rays
    /// from all around (among them axis-parallel ones, whose zero direction
    /// components give infinite reciprocals), nearest-first and any-order.
    #[test]
    fn kernels_visit_the_same_leaves() {
        if !Kernel::Avx2.available() {
            eprintln!("this CPU has no AVX2: only the portable kernel runs here");
            return;
        }
        let boxes = random_boxes(3000, 99);
        let primitives: Vec<BuildPrimitive> = boxes.iter().map(|b| BuildPrimitive { bounds: *b, kind: 0 }).collect();
        let (mut bvh, orders) = Bvh::build(&primitives);
        let mut rays: Vec<Ray> = random_boxes(1500, 5)
            .iter()
            .map(|b| Ray::new(b.min * 1.3 - DVec3::splat(20.0), b.max - DVec3::splat(40.0)))
            .collect();
        for axis in [DVec3::X, DVec3::NEG_Y, DVec3::Z] {
            rays.push(Ray::new(DVec3::splat(-60.0) + axis * 10.0, axis));
            rays.push(Ray::new(boxes[0].min, axis));
        }
        // Per ray: the leaves visited with the bound each was met with, and
        // the final distance, for the nearest-hit and the any-hit traversal.
        type Visits = (Vec<(Leaf, u64)>, u64, Vec<Leaf>);
        let trace = |bvh: &Bvh| -> Vec<Visits> {
            rays.iter()
                .map(|ray| {
                    let inverse = DVec3::ONE / ray.direction;
                    let mut visited = Vec::new();
                    let mut t = f64::INFINITY;
                    bvh.traverse(ray, &mut t, |leaf, t_max| {
                        visited.push((leaf, t_max.to_bits()));
                        for i in leaf.first..leaf.first + leaf.count {
                            let original = orders[0][i as usize] as usize;
                            if let Some(hit) = boxes[original].hit_distance(ray.origin, inverse, *t_max) {
                                *t_max = hit;
                            }
                        }
                        false
                    });
                    let mut any = Vec::new();
                    bvh.traverse_any(
                        ray,
                        &mut f64::INFINITY.clone(),
                        &mut VisitFn(|leaf: Leaf, _: &mut f64| {
                            any.push(leaf);
                            false
                        }),
                    );
                    (visited, t.to_bits(), any)
                })
                .collect()
        };
        bvh.set_kernel(Kernel::Avx2);
        assert_eq!(bvh.kernel(), Kernel::Avx2);
        let avx2 = trace(&bvh);
        bvh.set_kernel(Kernel::Portable);
        assert_eq!(bvh.kernel(), Kernel::Portable);
        let portable = trace(&bvh);
        assert!(
            avx2.iter()
                .any(|(visited, t, _)| visited.len() > 1 && f64::from_bits(*t).is_finite())
        );
        assert_eq!(avx2, portable);
    }

    /// The nearest box hit along `ray`, by testing every box and through the BVH.
    fn nearest_box_both_ways(bvh: &Bvh, orders: &[Vec<u32>; KIND_COUNT], boxes: &[Aabb], ray: &Ray) -> (f64, f64) {
        let inverse = DVec3::ONE / ray.direction;
        let brute = boxes
            .iter()
            .filter_map(|b| b.hit_distance(ray.origin, inverse, f64::INFINITY))
            .fold(f64::INFINITY, f64::min);
        let mut t_max = f64::INFINITY;
        bvh.traverse(ray, &mut t_max, |leaf, t_max| {
            for i in leaf.first..leaf.first + leaf.count {
                let original = orders[leaf.kind as usize][i as usize] as usize;
                if let Some(t) = boxes[original].hit_distance(ray.origin, inverse, *t_max) {
                    *t_max = t;
                }
            }
            false
        });
        (brute, t_max)
    }

    /// Boxes spaced geometrically along a line make the SAH peel off a few
    /// at a time: a tree deeper than the fixed stack allows, which must
    /// traverse (with the growable stack) to the same answers.
    #[test]
    fn deep_trees_traverse_with_a_growable_stack() {
        let boxes: Vec<Aabb> = (0..400)
            .map(|i| {
                let x = 1.2f64.powi(i);
                Aabb::new(DVec3::new(x, -1.0, -1.0), DVec3::new(x * 1.05, 1.0, 1.0))
            })
            .collect();
        let primitives: Vec<BuildPrimitive> = boxes.iter().map(|b| BuildPrimitive { bounds: *b, kind: 0 }).collect();
        let (bvh, orders) = Bvh::build(&primitives);
        assert!((WIDTH - 1) * bvh.depth() > FIXED_STACK, "depth {}", bvh.depth());
        for i in 0..100 {
            let origin = DVec3::new(-10.0, 0.3 * (i as f64 / 100.0) - 0.1, 0.2);
            let ray = Ray::new(origin, DVec3::new(1.0, 0.0, 0.001 * i as f64));
            let (brute, t_max) = nearest_box_both_ways(&bvh, &orders, &boxes, &ray);
            assert_eq!(brute, t_max);
        }
    }

    /// Nodes fill one 256-byte record, aligned to cache lines.
    #[test]
    fn nodes_are_four_cache_lines() {
        assert_eq!(std::mem::size_of::<Node>(), 256);
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
            bvh.traverse(&ray, &mut t_max, |_, _| {
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
