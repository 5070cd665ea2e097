//! The watertight ray–triangle test of Woop, Benthin & Wald (JCGT 2013)
//! for the up to four triangles of a leaf at once, one triangle per lane of
//! four-lane double-precision vectors.
//!
//! Every lane performs exactly the operations of the scalar test
//! ([`TriangleRay::intersect`]), in the same order and precision: the same
//! translation, permutation and shear, the same edge functions and sign
//! tests, the same rounding-error bound on the hit distance (pbrt-v4
//! §6.5.3). IEEE 754 arithmetic is deterministic per operation and Rust
//! never contracts a product and a sum into one fused operation, so each
//! lane's answer is bit for bit the scalar test's. The only place a
//! sequence matters, the shrinking `t_max` as a leaf's triangles are tested
//! one after another, is replayed lane by lane by the caller
//! ([`Candidates::nearest`]). The maxima use the NaN-ignoring `max` of
//! `f64::max`, so even non-finite inputs give the scalar answers.
//!
//! The test is compiled twice, as the BVH's traversal is
//! (`accel::kernel`): with `wide`'s vectors, which are two SSE2 halves in a
//! baseline x86-64 build, and in four-lane AVX instructions ([`avx2`]) for
//! the AVX2 copy of the traversal. Both perform the same operations in the
//! same order, so they too agree bit for bit.

#[cfg(target_arch = "x86_64")]
mod avx2;

use super::super::triangle::{TriangleHit, TriangleRay};
use super::LeafData;
use crate::accel::Avx2;
use crate::math::gamma;
use crate::math::lane_mask::set_lanes;
use wide::{CmpEq, CmpGe, CmpGt, CmpLe, CmpLt, f64x4};

/// Four lanes of `f64`.
pub type Lanes = f64x4;

/// Triangles that pass the test in a leaf, with what is needed to order
/// them and to finish the nearest one's hit.
///
/// The scalar test's `t_max` does not only shrink: a hit's distance
/// t = t_scaled / det is rounded, and may come out a hair *beyond* the bound
/// `t_scaled ≤ t_max · det` it passed. The triangle tested next then meets a
/// bound a hair larger than the leaf's, and may pass where it would fail
/// the leaf's own. So lanes hit beyond the leaf's `t_max` are kept too, and
/// [`Candidates::nearest`] replays the bound lane by lane.
pub struct Candidates {
    /// Bit `i` set: lane `i`'s triangle is hit in front of the origin,
    /// whatever the bound.
    mask: u32,
    t_scaled: [f64; 4],
    det: [f64; 4],
    t: [f64; 4],
    inverse_det: [f64; 4],
    edges: [[f64; 4]; 3],
}

impl Candidates {
    /// The hit the scalar test would report when run over the lanes in
    /// order, each with `t_max` set to the hit before it: the lane and its
    /// hit. Each lane is held against the bound it would meet there, as the
    /// scalar test does (`t_scaled` against `t_max · det`), the one
    /// condition of the test that depends on `t_max`.
    #[inline(always)]
    pub fn nearest(&self, t_max: f64) -> Option<(usize, TriangleHit)> {
        let mut t_max = t_max;
        let mut nearest = None;
        for lane in set_lanes(self.mask) {
            let (t_scaled, det) = (self.t_scaled[lane], self.det[lane]);
            let beyond = if det < 0.0 {
                t_scaled < t_max * det
            } else {
                t_scaled > t_max * det
            };
            if beyond {
                continue;
            }
            t_max = self.t[lane];
            let inverse_det = self.inverse_det[lane];
            nearest = Some((
                lane,
                TriangleHit {
                    t: t_max,
                    barycentric: self.edges.map(|e| e[lane] * inverse_det),
                },
            ));
        }
        nearest
    }
}

/// Tests the triangles of `leaf` for hits in `(0, t_max)`; `None` when no
/// lane is hit (so `Some` answers an any-hit query). In AVX instructions
/// when given `avx2`, the proof that the CPU has them.
#[inline(always)]
pub(super) fn intersect(avx2: Option<Avx2>, ray: &TriangleRay, leaf: &LeafData, t_max: f64) -> Option<Candidates> {
    #[cfg(target_arch = "x86_64")]
    if let Some(avx2) = avx2 {
        return avx2::intersect(avx2, ray, leaf, t_max);
    }
    let _ = avx2;
    intersect_portable(ray, leaf, t_max)
}

/// The test in `wide`'s vectors.
#[inline(always)]
fn intersect_portable(ray: &TriangleRay, leaf: &LeafData, t_max: f64) -> Option<Candidates> {
    // Vertex i's coordinate on the permuted axis j, as anchor + offset.
    let vertices: [[Lanes; 3]; 3] = std::array::from_fn(|vertex| {
        std::array::from_fn(|j| Lanes::new(leaf.anchors[j]) + Lanes::new(leaf.offsets(3 * vertex + ray.axes[j]).map(f64::from)))
    });
    let origin = ray.origin.map(Lanes::splat);
    let (shear_x, shear_y) = (Lanes::splat(ray.shear_x), Lanes::splat(ray.shear_y));
    // Translate to the ray origin, permute, shear so the ray is +z.
    let transform = |i: usize| {
        let [x, y, z] = vertices[i];
        let (x, y, z) = (x - origin[0], y - origin[1], z - origin[2]);
        [x + shear_x * z, y + shear_y * z, z]
    };
    let p = [transform(0), transform(1), transform(2)];
    let e0 = p[1][0] * p[2][1] - p[1][1] * p[2][0];
    let e1 = p[2][0] * p[0][1] - p[2][1] * p[0][0];
    let e2 = p[0][0] * p[1][1] - p[0][1] * p[1][0];
    let zero = Lanes::ZERO;
    let any_negative = e0.cmp_lt(zero) | e1.cmp_lt(zero) | e2.cmp_lt(zero);
    let any_positive = e0.cmp_gt(zero) | e1.cmp_gt(zero) | e2.cmp_gt(zero);
    let det = e0 + e1 + e2;
    // Rejected: mixed signs, or a zero determinant.
    let rejected = (any_negative & any_positive) | det.cmp_eq(zero);
    let mut mask = leaf.active() & !(rejected.move_mask() as u32);
    if mask == 0 {
        return None;
    }

    let shear_z = Lanes::splat(ray.shear_z);
    let z = [p[0][2] * shear_z, p[1][2] * shear_z, p[2][2] * shear_z];
    let t_scaled = e0 * z[0] + e1 * z[1] + e2 * z[2];
    let behind = (det.cmp_lt(zero) & t_scaled.cmp_ge(zero)) | (det.cmp_gt(zero) & t_scaled.cmp_le(zero));
    mask &= !(behind.move_mask() as u32);
    let bound = Lanes::splat(t_max) * det;
    let beyond = (det.cmp_lt(zero) & t_scaled.cmp_lt(bound)) | (det.cmp_gt(zero) & t_scaled.cmp_gt(bound));
    let beyond = beyond.move_mask() as u32;
    // A lane beyond `t_max` can still be the answer (see `Candidates`), but
    // only after one within it: with none within, nothing is hit.
    if mask & !beyond == 0 {
        return None;
    }

    let inverse_det = Lanes::ONE / det;
    let t = t_scaled * inverse_det;
    // The conservative lower bound on t of the scalar test (pbrt-v4 §6.5.3).
    let max_abs = |a: Lanes, b: Lanes, c: Lanes| a.abs().max(b.abs()).max(c.abs());
    let max_z = max_abs(z[0], z[1], z[2]);
    let delta_z = Lanes::splat(gamma(3)) * max_z;
    let max_x = max_abs(p[0][0], p[1][0], p[2][0]);
    let max_y = max_abs(p[0][1], p[1][1], p[2][1]);
    let delta_x = Lanes::splat(gamma(5)) * (max_x + max_z);
    let delta_y = Lanes::splat(gamma(5)) * (max_y + max_z);
    let delta_e = Lanes::splat(2.0) * (Lanes::splat(gamma(2)) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    let max_e = max_abs(e0, e1, e2);
    let delta_t =
        Lanes::splat(3.0) * (Lanes::splat(gamma(3)) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inverse_det.abs();
    mask &= !(t.cmp_le(delta_t).move_mask() as u32);
    if mask & !beyond == 0 {
        return None;
    }
    Some(Candidates {
        mask,
        t_scaled: t_scaled.to_array(),
        det: det.to_array(),
        t: t.to_array(),
        inverse_det: inverse_det.to_array(),
        edges: [e0.to_array(), e1.to_array(), e2.to_array()],
    })
}
