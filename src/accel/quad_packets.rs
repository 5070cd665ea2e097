//! Ray queries four rays at a time against a scene of a few quads, with
//! no tree: every quad is tested against the four rays, one ray per lane.
//!
//! A ray in a scene of a dozen or two quads (a Cornell box of walls, a
//! light and two boxes) spends most of its time not in the quad tests but
//! around them: preparing the traversal ray, the node test's branches,
//! the stack, and quad tests that leave early at data-dependent branches
//! the predictor misses. Tested four rays at a time, each quad's data is
//! loaded once for all four, the tests run without branches (masks say
//! which lanes hit), and the four rays' dependency chains run side by side
//! in one vector. On Mitsuba's Cornell box (18 quads) a closest hit fell
//! from 96 to 62 ns, a shadow ray from 50 to 41 ns (docs/performance.md,
//! "Rays four at a time on a scene of quads"). This is the packet idea of
//! Wald et al. ("Interactive Rendering with Coherent Ray Tracing", 2001)
//! taken to its limit for scenes so small that every ray meets every
//! quad's bounds anyway, so incoherent rays lose nothing by travelling
//! together.
//!
//! **Same answers as the tree.** Each lane performs [`Quad::solve`]'s
//! operations in the same order (glam's cross and dot products), so each
//! distance and edge coordinate is the scalar test's bit for bit; a zero
//! determinant needs no test of its own (its reciprocal is infinite, so
//! the edge coordinate is infinite or NaN and fails its range test). The
//! nearest hit is the least distance, as the tree finds it; only on an
//! exact tie between two quads' distances may the two pick different
//! quads (the tree keeps the first it visits, this the lower index).
//!
//! The lanes are AVX's four-lane `f64` vectors, so the queries run only
//! where AVX2 does (an [`Avx2`] proves it); elsewhere the scene's tree
//! answers, one ray at a time. Plain `[f64; 4]` arrays operated on element
//! by element were tried first: the compiler kept most of the arithmetic
//! scalar and shuffled between lanes, and the queries ran slower than the
//! tree's.

use super::Avx2;
use crate::geometry::quad::Quad;
use crate::math::Ray;
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::{
    __m256d, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_LT_OQ, _CMP_NEQ_UQ, _mm256_add_pd, _mm256_and_pd, _mm256_blendv_pd, _mm256_cmp_pd,
    _mm256_div_pd, _mm256_movemask_pd, _mm256_mul_pd, _mm256_or_pd, _mm256_set1_pd, _mm256_setzero_pd, _mm256_sub_pd,
};
use std::array::from_fn;

/// Most quads a scene may have for its queries to be answered here rather
/// than by its BVH. Every ray tests every quad, so the cost grows with the
/// count, where the tree's grows with its depth. Mitsuba's Cornell box with
/// small boxes added, rendered by the diffuse kernel and by the path
/// tracer, ran 1.25–1.34× faster at 18 and 24 quads, 1.10–1.12× at 30, and
/// 0.92–0.93× at 42 (docs/performance.md, "How many quads").
pub const MAX_QUADS: usize = 32;

/// Four rays, coordinate by coordinate (structure of arrays).
#[derive(Clone, Copy, Debug, Default)]
pub struct RayLanes {
    origin: [[f64; 4]; 3],
    direction: [[f64; 4]; 3],
}

impl RayLanes {
    /// Four rays in lanes; fewer are padded with copies of the last (whose
    /// answers the caller ignores).
    #[inline(always)]
    pub fn new(rays: &[Ray]) -> Self {
        let ray = |lane: usize| rays[lane.min(rays.len() - 1)];
        Self {
            origin: from_fn(|c| from_fn(|lane| ray(lane).origin[c])),
            direction: from_fn(|c| from_fn(|lane| ray(lane).direction[c])),
        }
    }
}

/// A quad's hit in one lane: its index, distance and edge coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadHit {
    /// Position of the quad in [`QuadPackets`]' list.
    pub index: u32,
    /// Distance along the ray.
    pub t: f64,
    /// Coordinate along the quad's `edge_u`.
    pub a: f64,
    /// Coordinate along its `edge_v`.
    pub b: f64,
}

/// A scene's quads for four-ray queries.
#[derive(Clone, Debug)]
pub struct QuadPackets {
    quads: Vec<Quad>,
}

impl QuadPackets {
    /// The queries for a scene whose primitives are exactly `quads`
    /// (primitive i is `quads[i]`), if there are few enough to pay.
    pub fn new(quads: Vec<Quad>) -> Option<Self> {
        (!quads.is_empty() && quads.len() <= MAX_QUADS).then_some(Self { quads })
    }

    /// Quad `index`.
    #[inline(always)]
    pub fn quad(&self, index: u32) -> &Quad {
        &self.quads[index as usize]
    }

    /// The nearest hit of each of four rays in `(0, ∞)`, passing over quad
    /// `skipped[lane]` in its lane (`u32::MAX`: none). Always inlined: in
    /// a caller compiled for AVX2 ([`Avx2::run`]) its instructions are.
    #[inline(always)]
    pub fn nearest(&self, avx2: Avx2, rays: &RayLanes, skipped: [u32; 4]) -> [Option<QuadHit>; 4] {
        let _ = avx2;
        // SAFETY: an `Avx2` exists only if this CPU has AVX2 (`Avx2::detect`).
        #[cfg(target_arch = "x86_64")]
        #[allow(unsafe_code)]
        let ([t, a, b], index) = unsafe { avx::nearest(&self.quads, rays, skipped.map(f64::from)) };
        #[cfg(not(target_arch = "x86_64"))]
        let ([t, a, b], index): ([[f64; 4]; 3], [f64; 4]) = unreachable!("an Avx2 exists only on x86-64: {rays:?} {skipped:?}");
        from_fn(|lane| {
            // Indices are small integers, exact in `f64`; −1 is none.
            (index[lane] >= 0.0).then_some(QuadHit {
                index: index[lane] as u32,
                t: t[lane],
                a: a[lane],
                b: b[lane],
            })
        })
    }

    /// Whether anything but quads `skipped[lane]` and `target[lane]` lies
    /// on each of four rays in `(0, t_max[lane])`.
    #[inline(always)]
    pub fn occluded(&self, avx2: Avx2, rays: &RayLanes, t_max: [f64; 4], skipped: [u32; 4], target: [u32; 4]) -> [bool; 4] {
        let _ = avx2;
        // SAFETY: as in `nearest`.
        #[cfg(target_arch = "x86_64")]
        #[allow(unsafe_code)]
        let mask = unsafe { avx::occluded(&self.quads, rays, t_max, skipped.map(f64::from), target.map(f64::from)) };
        #[cfg(not(target_arch = "x86_64"))]
        let mask: u32 = unreachable!("an Avx2 exists only on x86-64: {rays:?} {t_max:?} {skipped:?} {target:?}");
        from_fn(|lane| mask & (1 << lane) != 0)
    }
}

/// The queries in AVX instructions. Not `#[target_feature]` functions of
/// their own: those stay out-of-line calls, and a call per query is what
/// the packets save (see `geometry::triangles::lanes::avx2`).
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx {
    use super::*;

    fn load(lanes: [f64; 4]) -> __m256d {
        bytemuck::cast(lanes)
    }

    fn store(lanes: __m256d) -> [f64; 4] {
        bytemuck::cast(lanes)
    }

    /// [`Quad::solve`] in four lanes: the lanes that hit in `(0, t_max)`
    /// (all-ones), and their distances and edge coordinates. The same
    /// operations in the same order as the scalar test (glam's cross and
    /// dot products); a zero determinant needs no test of its own, as its
    /// reciprocal is infinite and the first edge coordinate is then
    /// infinite or NaN, which fails the range test.
    ///
    /// # Safety
    /// The CPU must have AVX.
    #[inline(always)]
    unsafe fn solve(quad: &Quad, origin: &[__m256d; 3], direction: &[__m256d; 3], t_max: __m256d) -> [__m256d; 4] {
        // SAFETY: the caller's promise; the intrinsics touch no memory.
        unsafe {
            let (sub, mul) = (_mm256_sub_pd, _mm256_mul_pd);
            let splat3 = |v: glam::DVec3| [_mm256_set1_pd(v.x), _mm256_set1_pd(v.y), _mm256_set1_pd(v.z)];
            let cross = |a: [__m256d; 3], b: [__m256d; 3]| {
                [
                    sub(mul(a[1], b[2]), mul(b[1], a[2])),
                    sub(mul(a[2], b[0]), mul(b[2], a[0])),
                    sub(mul(a[0], b[1]), mul(b[0], a[1])),
                ]
            };
            let dot = |a: [__m256d; 3], b: [__m256d; 3]| {
                _mm256_add_pd(_mm256_add_pd(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2]))
            };
            let (corner, edge_u, edge_v) = (splat3(quad.corner), splat3(quad.edge_u), splat3(quad.edge_v));
            let p = cross(*direction, edge_v);
            let inverse_det = _mm256_div_pd(_mm256_set1_pd(1.0), dot(edge_u, p));
            let s = [
                sub(origin[0], corner[0]),
                sub(origin[1], corner[1]),
                sub(origin[2], corner[2]),
            ];
            let a = mul(dot(s, p), inverse_det);
            let q = cross(s, edge_u);
            let b = mul(dot(*direction, q), inverse_det);
            let t = mul(dot(edge_v, q), inverse_det);
            let (zero, one) = (_mm256_setzero_pd(), _mm256_set1_pd(1.0));
            let le = |x, y| _mm256_cmp_pd::<_CMP_LE_OQ>(x, y);
            let and = _mm256_and_pd;
            let inside = and(and(le(zero, a), le(a, one)), and(le(zero, b), le(b, one)));
            let ahead = and(_mm256_cmp_pd::<_CMP_GT_OQ>(t, zero), _mm256_cmp_pd::<_CMP_LT_OQ>(t, t_max));
            [and(inside, ahead), t, a, b]
        }
    }

    /// The rays' lanes as vectors.
    fn vectors(rays: &RayLanes) -> ([__m256d; 3], [__m256d; 3]) {
        (rays.origin.map(load), rays.direction.map(load))
    }

    /// [`QuadPackets::nearest`]: (distance, a, b) and index (−1: none) per lane.
    ///
    /// # Safety
    /// The CPU must have AVX.
    #[inline(always)]
    pub(super) unsafe fn nearest(quads: &[Quad], rays: &RayLanes, skipped: [f64; 4]) -> ([[f64; 4]; 3], [f64; 4]) {
        // SAFETY: the caller's promise; the intrinsics touch no memory.
        unsafe {
            let (origin, direction) = vectors(rays);
            let skipped = load(skipped);
            let mut nearest = [_mm256_set1_pd(f64::INFINITY), _mm256_setzero_pd(), _mm256_setzero_pd()];
            let mut nearest_index = _mm256_set1_pd(-1.0);
            for (index, quad) in quads.iter().enumerate() {
                let index = _mm256_set1_pd(index as f64);
                let [hit, t, a, b] = solve(quad, &origin, &direction, nearest[0]);
                let take = _mm256_and_pd(hit, _mm256_cmp_pd::<_CMP_NEQ_UQ>(skipped, index));
                nearest = [
                    _mm256_blendv_pd(nearest[0], t, take),
                    _mm256_blendv_pd(nearest[1], a, take),
                    _mm256_blendv_pd(nearest[2], b, take),
                ];
                nearest_index = _mm256_blendv_pd(nearest_index, index, take);
            }
            (nearest.map(store), store(nearest_index))
        }
    }

    /// [`QuadPackets::occluded`]: a bit per lane.
    ///
    /// # Safety
    /// The CPU must have AVX.
    #[inline(always)]
    pub(super) unsafe fn occluded(quads: &[Quad], rays: &RayLanes, t_max: [f64; 4], skipped: [f64; 4], target: [f64; 4]) -> u32 {
        // SAFETY: the caller's promise; the intrinsics touch no memory.
        unsafe {
            let (origin, direction) = vectors(rays);
            let (t_max, skipped, target) = (load(t_max), load(skipped), load(target));
            let mut occluded = _mm256_setzero_pd();
            for (index, quad) in quads.iter().enumerate() {
                let index = _mm256_set1_pd(index as f64);
                let [hit, _, _, _] = solve(quad, &origin, &direction, t_max);
                let other = _mm256_and_pd(
                    _mm256_cmp_pd::<_CMP_NEQ_UQ>(skipped, index),
                    _mm256_cmp_pd::<_CMP_NEQ_UQ>(target, index),
                );
                occluded = _mm256_or_pd(occluded, _mm256_and_pd(hit, other));
                // Every lane blocked: nothing left to learn.
                if _mm256_movemask_pd(occluded) == 0b1111 {
                    break;
                }
            }
            _mm256_movemask_pd(occluded) as u32
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// Random quads in the unit cube, random rays through it: every lane's
    /// answer is the scalar test's over all quads, bit for bit, with and
    /// without a skipped quad, for nearest and any hits.
    #[test]
    fn four_lanes_answer_as_the_scalar_test_does() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        // xorshift64: uniform numbers in [0, 1).
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let point = |next: &mut dyn FnMut() -> f64| DVec3::new(next(), next(), next());
        let quads: Vec<Quad> = (0..20)
            .map(|_| {
                Quad::new(
                    point(&mut next),
                    point(&mut next) - DVec3::splat(0.5),
                    point(&mut next) - DVec3::splat(0.5),
                )
            })
            .collect();
        let packets = QuadPackets::new(quads.clone()).expect("20 quads");
        let Some(avx2) = Avx2::detect() else {
            eprintln!("no AVX2 on this CPU: the four-ray queries are never used here");
            return;
        };
        let (mut hits, mut occluded_count) = (0, 0);
        for round in 0..2000 {
            let rays: Vec<Ray> = (0..4)
                .map(|_| {
                    let origin = point(&mut next) * 3.0 - DVec3::ONE;
                    Ray::new(origin, point(&mut next) - origin)
                })
                .collect();
            let skipped: [u32; 4] = from_fn(|lane| {
                if (round + lane) % 3 == 0 {
                    u32::MAX
                } else {
                    ((round * 7 + lane) % 20) as u32
                }
            });
            let target: [u32; 4] = from_fn(|lane| ((round * 3 + lane * 5) % 20) as u32);
            let t_max: [f64; 4] = from_fn(|_| next() * 3.0);
            let lanes = RayLanes::new(&rays);
            let nearest = packets.nearest(avx2, &lanes, skipped);
            let occluded = packets.occluded(avx2, &lanes, t_max, skipped, target);
            for lane in 0..4 {
                let ray = &rays[lane];
                let mut expected: Option<QuadHit> = None;
                for (index, quad) in quads.iter().enumerate() {
                    if index as u32 == skipped[lane] {
                        continue;
                    }
                    let bound = expected.map_or(f64::INFINITY, |hit| hit.t);
                    if let Some((t, a, b)) = quad.solve(ray, bound) {
                        expected = Some(QuadHit {
                            index: index as u32,
                            t,
                            a,
                            b,
                        });
                    }
                }
                assert_eq!(nearest[lane], expected, "round {round}, lane {lane}");
                hits += usize::from(expected.is_some());
                let blocked = quads.iter().enumerate().any(|(index, quad)| {
                    index as u32 != skipped[lane] && index as u32 != target[lane] && quad.solve(ray, t_max[lane]).is_some()
                });
                assert_eq!(occluded[lane], blocked, "round {round}, lane {lane}");
                occluded_count += usize::from(blocked);
            }
        }
        // Both answers occur often, so the comparison means something.
        assert!(hits > 2000 && hits < 7000, "{hits} hits of 8000");
        assert!(
            occluded_count > 1000 && occluded_count < 7000,
            "{occluded_count} occluded of 8000"
        );
    }

    #[test]
    fn only_a_few_quads_are_taken() {
        let quad = Quad::new(DVec3::ZERO, DVec3::X, DVec3::Y);
        assert!(QuadPackets::new(vec![]).is_none());
        assert!(QuadPackets::new(vec![quad; MAX_QUADS]).is_some());
        assert!(QuadPackets::new(vec![quad; MAX_QUADS + 1]).is_none());
    }
}
