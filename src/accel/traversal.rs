//! The traversal of the eight-wide BVH ([`super::bvh`]): front to back,
//! the children a ray enters visited nearest first (or in any order, for
//! occlusion), with the subtrees beyond the nearest hit so far skipped; the
//! leaves' tests are the caller's [`LeafVisitor`], compiled into the loop.
//! The box test is conservative ([`TraversalRay`]), so the traversal never
//! culls a primitive the exact primitive test would hit.
//!
//! The loop is compiled twice, for baseline x86-64 and for AVX2, and the
//! [`Traversal`] routes say which copy a query runs ([`super::kernel`]).

use super::bvh::{Bvh, LEAF_BIT, Leaf, WIDTH};
use super::kernel::Avx2;
use super::slab_test::{TraversalRay, traversal_limit};
use crate::math::Ray;
use crate::math::lane_mask::set_lanes;
use arrayvec::ArrayVec;

/// What a traversal does at the leaves it reaches. Its methods are
/// compiled into the traversal (mark them `#[inline(always)]`): the
/// traversal is compiled once per [`super::Kernel`], and a leaf test reached from
/// two copies would otherwise stay an out-of-line call per leaf.
pub trait LeafVisitor {
    /// Tests `leaf`'s primitives, lowers `*t_max` to the nearest hit it
    /// finds, and returns true to end the traversal.
    /// `avx2` is present when the traversal calling it is the AVX2 copy
    /// (the proof that the CPU has AVX2, for leaf tests of their own in
    /// those instructions), and is a constant in each copy.
    fn visit(&mut self, leaf: Leaf, t_max: &mut f64, avx2: Option<Avx2>) -> bool;

    /// Starts loading the primitives of `leaf`, which the traversal has
    /// deferred (called only in trees larger than the caches).
    fn prefetch(&self, _leaf: Leaf) {}
}

/// How a caller's nearest-hit queries reach the traversal: [`Dispatched`]
/// through the tree's own choice of kernel, or, for a caller compiled for
/// AVX2 ([`Avx2::run`]), [`Avx2`], the AVX2 traversal compiled into it.
pub trait Traversal: Copy {
    /// [`Bvh::traverse_nearest`], by this route.
    fn nearest(self, bvh: &Bvh, ray: &Ray, t_max: &mut f64, visitor: &mut impl LeafVisitor);
    /// [`Bvh::traverse_any`], by this route.
    fn any(self, bvh: &Bvh, ray: &Ray, t_max: &mut f64, visitor: &mut impl LeafVisitor);
}

/// The tree's own choice of kernel, made per query ([`Bvh::traverse_nearest`]).
#[derive(Clone, Copy, Debug)]
pub struct Dispatched;

impl Traversal for Dispatched {
    #[inline(always)]
    fn nearest(self, bvh: &Bvh, ray: &Ray, t_max: &mut f64, visitor: &mut impl LeafVisitor) {
        bvh.traverse_nearest(ray, t_max, visitor);
    }
    #[inline(always)]
    fn any(self, bvh: &Bvh, ray: &Ray, t_max: &mut f64, visitor: &mut impl LeafVisitor) {
        bvh.traverse_any(ray, t_max, visitor);
    }
}

/// The baseline kernel compiled into the caller, whatever the tree's choice.
#[derive(Clone, Copy, Debug)]
pub struct Portable;

impl Traversal for Portable {
    #[inline(always)]
    fn nearest(self, bvh: &Bvh, ray: &Ray, t_max: &mut f64, visitor: &mut impl LeafVisitor) {
        bvh.traverse_compiled::<true>(None, ray, t_max, visitor);
    }
    #[inline(always)]
    fn any(self, bvh: &Bvh, ray: &Ray, t_max: &mut f64, visitor: &mut impl LeafVisitor) {
        bvh.traverse_compiled::<false>(None, ray, t_max, visitor);
    }
}

/// The AVX2 kernel compiled into the caller, which should itself be
/// compiled for AVX2 (run inside [`Avx2::run`]).
impl Traversal for Avx2 {
    #[inline(always)]
    fn nearest(self, bvh: &Bvh, ray: &Ray, t_max: &mut f64, visitor: &mut impl LeafVisitor) {
        bvh.traverse_compiled::<true>(Some(self), ray, t_max, visitor);
    }
    #[inline(always)]
    fn any(self, bvh: &Bvh, ray: &Ray, t_max: &mut f64, visitor: &mut impl LeafVisitor) {
        bvh.traverse_compiled::<false>(Some(self), ray, t_max, visitor);
    }
}

/// A closure as a [`LeafVisitor`] that prefetches nothing.
pub(super) struct VisitFn<F>(pub(super) F);

impl<F: FnMut(Leaf, &mut f64) -> bool> LeafVisitor for VisitFn<F> {
    #[inline(always)]
    fn visit(&mut self, leaf: Leaf, t_max: &mut f64, _avx2: Option<Avx2>) -> bool {
        (self.0)(leaf, t_max)
    }
}

impl Bvh {
    /// Visits the leaves `ray` enters, nearest first, skipping those beyond
    /// `*t_max`. `visit` tests a leaf's primitives, lowers `*t_max` to the
    /// nearest hit it finds, and returns true to end the traversal.
    #[inline]
    pub fn traverse(&self, ray: &Ray, t_max: &mut f64, visit: impl FnMut(Leaf, &mut f64) -> bool) {
        self.traverse_nearest(ray, t_max, &mut VisitFn(visit));
    }

    /// Visits the leaves `ray` enters, nearest first, as [`Bvh::traverse`]
    /// does, with `visitor`'s test (always compiled into the traversal);
    /// in a tree larger than the caches, calls [`LeafVisitor::prefetch`]
    /// for each leaf it defers.
    #[inline(always)]
    pub fn traverse_nearest(&self, ray: &Ray, t_max: &mut f64, visitor: &mut impl LeafVisitor) {
        self.traverse_sized::<true>(ray, t_max, visitor);
    }

    /// Visits the leaves `ray` enters in any order (no sorting) until
    /// `visitor` returns true: for any-hit (occlusion) queries. Prefetches
    /// as [`Bvh::traverse_nearest`] does.
    #[inline(always)]
    pub fn traverse_any(&self, ray: &Ray, t_max: &mut f64, visitor: &mut impl LeafVisitor) {
        self.traverse_sized::<false>(ray, t_max, visitor);
    }

    /// The traversal, with the kernel this tree runs (see [`super::Kernel`]):
    /// compiled for AVX2 where the CPU has it, with the leaf tests inside.
    #[inline(always)]
    fn traverse_sized<const NEAREST_FIRST: bool>(&self, ray: &Ray, t_max: &mut f64, visitor: &mut impl LeafVisitor) {
        match self.avx2 {
            Some(avx2) => avx2.run(
                #[inline(always)]
                || self.traverse_compiled::<NEAREST_FIRST>(Some(avx2), ray, t_max, visitor),
            ),
            None => self.traverse_compiled::<NEAREST_FIRST>(None, ray, t_max, visitor),
        }
    }

    /// The traversal, compiled into whichever function calls it. With
    /// `avx2` (the proof that the CPU has AVX2; a constant wherever this is
    /// compiled in): AVX2's node test, and the visitor's own AVX2 tests.
    #[inline(always)]
    fn traverse_compiled<const NEAREST_FIRST: bool>(
        &self,
        avx2: Option<Avx2>,
        ray: &Ray,
        t_max: &mut f64,
        visitor: &mut impl LeafVisitor,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        // Prepared here, in this frame, so the 432-byte record is never copied.
        let ray = &TraversalRay::new(ray);
        let mut stack = TraversalStack::new();
        self.traverse_with::<NEAREST_FIRST>(avx2, &mut stack, ray, t_max, visitor);
    }

    #[inline(always)]
    fn traverse_with<const NEAREST_FIRST: bool>(
        &self,
        avx2: Option<Avx2>,
        stack: &mut TraversalStack,
        ray: &TraversalRay,
        t_max: &mut f64,
        visitor: &mut impl LeafVisitor,
    ) {
        // Defers a child, first starting its load when the tree is larger
        // than the caches: its miss then overlaps the traversal of the
        // subtree visited first, instead of stalling the step that pops it.
        let prefetches = self.prefetches;
        let defer = |stack: &mut TraversalStack, visitor: &mut _, entry: u64| {
            if prefetches {
                let child = entry as u32;
                if child & LEAF_BIT == 0 {
                    self.prefetch_node(child);
                } else {
                    LeafVisitor::prefetch(visitor, Leaf::from_reference(child));
                }
            }
            stack.push(entry);
        };
        let mut limit = traversal_limit(*t_max);
        // The child being visited.
        let mut current = 0u32;
        loop {
            if current & LEAF_BIT == 0 {
                let node = &self.nodes[current as usize];
                let (t_near, hit) = ray.enter(node, limit, avx2);
                // Whether the ray enters none, one or several children is a
                // branch that often mispredicts, so it is decided by bit
                // tests that resolve at once, and the entered children are
                // counted as they are gathered: the baseline x86-64 target
                // has no popcount instruction, and its software count put
                // two multiplications before the branch.
                if hit == 0 {
                    // Nothing entered: go on with the deferred children.
                } else if hit & (hit - 1) == 0 {
                    // The common case needs no ordering.
                    current = node.children[hit.trailing_zeros() as usize];
                    continue;
                } else if NEAREST_FIRST {
                    // Entered children as keys that sort by entry distance
                    // (the distance's bits lead, and they order like the
                    // non-negative floats they are), gathered to the front;
                    // the rest are all ones, which sort last. A sorting
                    // network orders them without data-dependent branches.
                    let mut keys = [u64::MAX; WIDTH];
                    // At most eight (one bit per lane), so the masks below
                    // change nothing and spare bounds checks.
                    let mut entered = 0;
                    for lane in set_lanes(hit) {
                        keys[entered & (WIDTH - 1)] = pack(node.children[lane], t_near[lane]);
                        entered += 1;
                    }
                    if entered <= 4 {
                        sort_by_network::<4>(keys.first_chunk_mut().expect("eight keys"), &FOUR_KEY_NETWORK);
                    } else {
                        sort_by_network(&mut keys, &EIGHT_KEY_NETWORK);
                    }
                    // Leave the farther ones for later, farthest deepest; go on with the nearest.
                    for &key in keys[1..entered.min(WIDTH)].iter().rev() {
                        defer(stack, &mut *visitor, key);
                    }
                    current = keys[0] as u32;
                    continue;
                } else {
                    // Any order will do: the first entered now, the others later.
                    let mut lanes = set_lanes(hit);
                    current = node.children[lanes.next().unwrap_or_default()];
                    for lane in lanes {
                        defer(stack, &mut *visitor, pack(node.children[lane], t_near[lane]));
                    }
                    continue;
                }
            } else {
                if visitor.visit(Leaf::from_reference(current), t_max, avx2) {
                    return;
                }
                limit = traversal_limit(*t_max);
            }
            // Next: the nearest deferred child still in front of the nearest hit.
            loop {
                let Some(entry) = stack.pop() else { return };
                let (child, t_near) = unpack(entry);
                if t_near <= limit {
                    current = child;
                    break;
                }
            }
        }
    }

    /// Starts loading the four cache lines of interior node `child`.
    #[inline(always)]
    fn prefetch_node(&self, child: u32) {
        if let Some(node) = self.nodes.get(child as usize) {
            for axis in 0..3 {
                prefetch(&node.bounds[2 * axis]);
            }
            prefetch(&node.children);
        }
    }
}

/// Starts loading the cache line holding `value` without waiting for it
/// (the `prefetcht0` instruction; nothing where it is missing).
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse"))]
    safe_arch::prefetch_t0(value);
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse")))]
    let _ = value;
}

/// An optimal sorting network for four keys: five compare-exchanges.
const FOUR_KEY_NETWORK: [(usize, usize); 5] = [(0, 1), (2, 3), (0, 2), (1, 3), (1, 2)];

/// An optimal sorting network for eight keys: nineteen compare-exchanges
/// (Knuth, TAOCP vol. 3 §5.3.4).
#[rustfmt::skip]
const EIGHT_KEY_NETWORK: [(usize, usize); 19] = [
    (0, 2), (1, 3), (4, 6), (5, 7),
    (0, 4), (1, 5), (2, 6), (3, 7),
    (0, 1), (2, 3), (4, 5), (6, 7),
    (2, 4), (3, 5),
    (1, 4), (3, 6),
    (1, 2), (3, 4), (5, 6),
];

/// Sorts `keys` ascending by `network`, each compare-exchange a pair of
/// conditional moves (no data-dependent branches).
#[inline(always)]
fn sort_by_network<const N: usize>(keys: &mut [u64; N], network: &[(usize, usize)]) {
    for &(a, b) in network {
        let (low, high) = (keys[a].min(keys[b]), keys[a].max(keys[b]));
        keys[a] = low;
        keys[b] = high;
    }
}

/// A stack entry: the child reference in the low half, its entry distance's bits in the high half.
#[inline(always)]
fn pack(child: u32, t_near: f32) -> u64 {
    (u64::from(t_near.to_bits()) << 32) | u64::from(child)
}

#[inline(always)]
fn unpack(entry: u64) -> (u32, f32) {
    (entry as u32, f32::from_bits((entry >> 32) as u32))
}

/// The traversal's stack of deferred children: a fixed-capacity array on
/// the call stack (no allocation and, unlike a plain array, nothing to
/// clear first), continued on the heap in the rare tree too deep for it.
/// Entries leave in the reverse order they came whichever part holds them:
/// the overflow fills only when the array is full, so it holds the newest.
struct TraversalStack {
    fixed: ArrayVec<u64, FIXED_STACK>,
    overflow: Vec<u64>,
}

impl TraversalStack {
    #[inline(always)]
    fn new() -> Self {
        Self {
            fixed: ArrayVec::new_const(),
            overflow: Vec::new(),
        }
    }

    #[inline(always)]
    fn push(&mut self, entry: u64) {
        if let Err(full) = self.fixed.try_push(entry) {
            self.overflow.push(full.element());
        }
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<u64> {
        if self.overflow.is_empty() {
            self.fixed.pop()
        } else {
            self.overflow.pop()
        }
    }
}

/// Entries of the traversal stack kept on the call stack. Each interior
/// node visited leaves at most seven siblings behind, so trees up to 9
/// levels deep (8⁹ leaves: every scene of up to hundreds of millions of
/// triangles in practice) never spill to the heap; deeper trees continue
/// on a growable overflow.
pub(super) const FIXED_STACK: usize = 64;

#[cfg(test)]
mod tests {
    use super::*;

    /// The sorting networks sort every input of zeros and ones, hence
    /// every input (Knuth's 0–1 principle).
    #[test]
    fn sorting_networks_sort() {
        for bits in 0u32..256 {
            let mut eight: [u64; 8] = std::array::from_fn(|i| u64::from((bits >> i) & 1));
            let ones = bits.count_ones() as usize;
            sort_by_network(&mut eight, &EIGHT_KEY_NETWORK);
            assert!(
                eight.iter().enumerate().all(|(i, &k)| k == u64::from(i >= 8 - ones)),
                "{bits:08b}"
            );
            if bits < 16 {
                let mut four: [u64; 4] = std::array::from_fn(|i| u64::from((bits >> i) & 1));
                sort_by_network(&mut four, &FOUR_KEY_NETWORK);
                assert!(
                    four.iter().enumerate().all(|(i, &k)| k == u64::from(i >= 4 - ones)),
                    "{bits:04b}"
                );
            }
        }
    }
}
