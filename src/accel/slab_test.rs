//! The conservative single-precision slab test of a node's eight children
//! (Kay & Kajiya 1986; the eight lanes of Wald et al. 2008), in the
//! baseline copy (`wide`'s two four-lane halves) and the AVX2 copy (one
//! eight-lane operation) of the traversal, and the bound on entry
//! distances that goes with it.

use super::bounds::{round_up, sign_mask32};
use super::bvh::{Node, WIDTH};
use super::kernel::Avx2;
use crate::math::Ray;
use wide::{CmpLe, f32x8};

/// `1 + 2γ₃` in single precision (γₙ = nu/(1 − nu), u = 2⁻²⁴), rounded up
/// generously: a far slab distance computed with three roundings (the
/// subtraction, the reciprocal and the product) times this is at least the
/// exact one (pbrt-v4 §6.8.2).
const FAR_SCALE: f32 = 1.0 + 4.0 * f32::EPSILON;

/// The farthest entry distance worth visiting when the nearest hit so far
/// is at `t_max`: rounded up to `f32` and widened by [`FAR_SCALE`] like the
/// exit distances. A ray passing a hair outside a box's corner (which the
/// widened exit distances still let in) enters its last slab a hair after
/// the corner, while the triangle test, itself rounded, may report a hit of
/// a triangle at that corner as no farther than `t_max`; without the same
/// widening here that leaf would be skipped, and a ray through a shared
/// vertex could find neither of the triangles that meet there.
#[inline]
pub(super) fn traversal_limit(t_max: f64) -> f32 {
    (round_up(t_max) * FAR_SCALE).next_up()
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
/// maximum and minimum are the `maxps`/`minps` instructions, which keep
/// their second operand (the running value) when the first is NaN, so such
/// a slab is simply not counted against the ray: conservative.
#[derive(Clone, Copy, Debug)]
pub struct TraversalRay {
    /// Per axis, splatted over the eight lanes: the origin for the entry
    /// planes, the origin for the exit planes, the reciprocal direction,
    /// and the reciprocal times [`FAR_SCALE`] for the exit distances.
    entry_origin: [f32x8; 3],
    exit_origin: [f32x8; 3],
    reciprocal: [f32x8; 3],
    exit_reciprocal: [f32x8; 3],
    /// Index into a node's `bounds` of the entry and exit plane of each axis.
    entry_plane: [usize; 3],
    exit_plane: [usize; 3],
}

impl TraversalRay {
    /// Prepares `ray` for the eight-lane box tests: the
    /// outward-bracketed origin, the reciprocal direction and the entry and
    /// exit plane of each axis, by the sign of the direction.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let reciprocal: [f32; 3] = std::array::from_fn(|axis| (1.0 / ray.direction[axis]) as f32);
        // All ones for the axes the ray crosses towards −∞, entering through
        // the maximum: a mask, not a branch, as the signs are unpredictable.
        let towards_minus = reciprocal.map(|r| sign_mask32(r.to_bits()));
        let origins: [(f32, f32); 3] = std::array::from_fn(|axis| {
            // Entering through the minimum, (min − o)·r is smallest for the
            // largest o; through the maximum (r < 0), for the smallest.
            let (down, up) = super::bounds::bracket(ray.origin[axis]);
            let (down, up) = (down.to_bits(), up.to_bits());
            let swap = (down ^ up) & towards_minus[axis];
            (f32::from_bits(up ^ swap), f32::from_bits(down ^ swap))
        });
        TraversalRay {
            entry_origin: origins.map(|(entry, _)| f32x8::splat(entry)),
            exit_origin: origins.map(|(_, exit)| f32x8::splat(exit)),
            reciprocal: reciprocal.map(f32x8::splat),
            // Four roundings in all ((b − o), r, r·scale, the product) stay
            // within 1 − 4u of exact, which the 1 + 2⁻²¹ scale covers.
            exit_reciprocal: reciprocal.map(|r| f32x8::splat(r * FAR_SCALE)),
            entry_plane: std::array::from_fn(|axis| 2 * axis + (towards_minus[axis] & 1) as usize),
            exit_plane: std::array::from_fn(|axis| 2 * axis + 1 - (towards_minus[axis] & 1) as usize),
        }
    }

    /// [`TraversalRay::enter_children`], in AVX2 instructions when given
    /// `avx2`, the proof that the CPU has them (a constant in each compiled
    /// copy of the traversal).
    #[inline(always)]
    pub(super) fn enter(&self, node: &Node, t_max: f32, avx2: Option<Avx2>) -> ([f32; WIDTH], u32) {
        #[cfg(target_arch = "x86_64")]
        if avx2.is_some() {
            // SAFETY: `avx2` exists only if this CPU has AVX2 (`Avx2::detect`).
            #[allow(unsafe_code)]
            return unsafe { self.enter_children_avx2(node, t_max) };
        }
        let _ = avx2;
        self.enter_children(node, t_max)
    }

    /// Entry distances of the eight children and a bit mask (bit i for
    /// lane i) of those the ray enters before `t_max`.
    #[inline(always)]
    fn enter_children(&self, node: &Node, t_max: f32) -> ([f32; WIDTH], u32) {
        let mut t_entry = f32x8::ZERO;
        let mut t_exit = f32x8::splat(t_max);
        for axis in 0..3 {
            let entry = (f32x8::from(node.bounds[self.entry_plane[axis]]) - self.entry_origin[axis]) * self.reciprocal[axis];
            let exit = (f32x8::from(node.bounds[self.exit_plane[axis]]) - self.exit_origin[axis]) * self.exit_reciprocal[axis];
            // maxps/minps return their second operand when the first is NaN.
            t_entry = entry.fast_max(t_entry);
            t_exit = exit.fast_min(t_exit);
        }
        (t_entry.to_array(), t_entry.cmp_le(t_exit).move_mask() as u32)
    }

    /// [`TraversalRay::enter_children`] in eight-lane AVX instructions
    /// (`wide`'s eight lanes are two four-lane halves unless the whole
    /// program is compiled for AVX): the same operations, operands and
    /// order, so the same answers bit for bit.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    fn enter_children_avx2(&self, node: &Node, t_max: f32) -> ([f32; WIDTH], u32) {
        use std::arch::x86_64::{
            __m256, _CMP_LE_OQ, _mm256_cmp_ps, _mm256_max_ps, _mm256_min_ps, _mm256_movemask_ps, _mm256_mul_ps, _mm256_set1_ps,
            _mm256_setzero_ps, _mm256_sub_ps,
        };
        let lanes = |values: &[f32; WIDTH]| bytemuck::cast::<[f32; WIDTH], __m256>(*values);
        let splat = |value: f32x8| bytemuck::cast::<f32x8, __m256>(value);
        let mut t_entry = _mm256_setzero_ps();
        let mut t_exit = _mm256_set1_ps(t_max);
        for axis in 0..3 {
            let entry = _mm256_mul_ps(
                _mm256_sub_ps(lanes(&node.bounds[self.entry_plane[axis]]), splat(self.entry_origin[axis])),
                splat(self.reciprocal[axis]),
            );
            let exit = _mm256_mul_ps(
                _mm256_sub_ps(lanes(&node.bounds[self.exit_plane[axis]]), splat(self.exit_origin[axis])),
                splat(self.exit_reciprocal[axis]),
            );
            // As `maxps`/`minps` above: the second operand when the first is NaN.
            t_entry = _mm256_max_ps(entry, t_entry);
            t_exit = _mm256_min_ps(exit, t_exit);
        }
        let entered = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_entry, t_exit)) as u32;
        (bytemuck::cast(t_entry), entered)
    }
}
