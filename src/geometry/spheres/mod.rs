//! The scene's spheres as the BVH's leaves read them: up to four per leaf,
//! tested together, one sphere per lane of four-lane double-precision
//! vectors.
//!
//! Scenes built of spheres often have spheres whose boxes overlap (smallpt's
//! walls are spheres of radius 10⁵ whose boxes hold the whole room), so a
//! ray enters nearly every sphere's box and the tree's boxes cull nothing:
//! each sphere then costs a traversal step, a jump on the shape's kind and
//! the test's data-dependent exits. Here four are tested at once, the
//! exits are masks, and the SAH ([`crate::accel`]) keeps apart the spheres
//! whose boxes do not overlap.
//!
//! Every lane performs exactly the scalar test's operations
//! ([`Sphere::hit_distance`]), in the same order and precision, so each
//! lane's two roots are bit for bit the scalar test's. Which root a sphere
//! reports depends on `t_max` (the nearer one unless it is out of range),
//! and `t_max` falls with each hit, so the choice is replayed lane by lane
//! ([`Spheres::intersect_leaf`]): a leaf reports the sphere and distance a
//! scalar loop over it would.
//!
//! The vector part (the four pairs of roots) is compiled twice, as the
//! BVH's traversal is (`accel::kernel`): with `wide`'s vectors, two SSE2
//! halves in a baseline build, and in AVX instructions ([`avx2`]) for the
//! AVX2 traversal; the same operations in the same order, so the same bits.
//!
//! **Layout.** Centre x, y, z and radius are four arrays in leaf order, so
//! four consecutive spheres' values are one load each. Lanes past a leaf's
//! count read the next leaf's spheres (or zeros, which the arrays end with)
//! and are masked off.

#[cfg(target_arch = "x86_64")]
mod avx2;

use super::Sphere;
use crate::accel::Avx2;
use crate::math::Ray;
use crate::math::lane_mask::select;
use wide::{CmpGt, CmpLt, f64x4};

/// Zeros after each array: a one-sphere leaf at the end reads three past it.
const PADDING: usize = 3;
/// Leaves of at most this many spheres are tested one sphere at a time.
const SCALAR_COUNT: u32 = 2;

/// The spheres' centres and radii, in leaf order.
#[derive(Clone, Debug, Default)]
pub struct Spheres {
    /// Centre x, y, z, then radius; each ends with [`PADDING`] zeros.
    values: [Vec<f64>; 4],
    /// The same spheres one by one, for the scalar test of small leaves.
    list: Vec<Sphere>,
}

/// A sphere hit found in a leaf.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereHit {
    /// Index of the sphere in leaf order.
    pub index: u32,
    /// Ray parameter of the hit.
    pub t: f64,
}

/// Both roots of each lane whose discriminant is not negative (bit i of
/// `mask` for lane i), nearer first.
struct Roots {
    mask: u32,
    near: [f64; 4],
    far: [f64; 4],
}

impl Spheres {
    /// Stores `spheres`, already in leaf order.
    pub fn new<'a>(spheres: impl IntoIterator<Item = &'a Sphere>) -> Self {
        let mut values: [Vec<f64>; 4] = Default::default();
        let list: Vec<Sphere> = spheres.into_iter().copied().collect();
        for sphere in &list {
            let [x, y, z] = sphere.center.to_array();
            for (array, value) in values.iter_mut().zip([x, y, z, sphere.radius]) {
                array.push(value);
            }
        }
        for array in &mut values {
            array.extend([0.0; PADDING]);
        }
        Self { values, list }
    }

    /// Number of spheres stored.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// Whether no sphere is stored.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Sphere `index` (in leaf order).
    #[inline(always)]
    fn sphere(&self, index: u32) -> Option<&Sphere> {
        self.list.get(index as usize)
    }

    /// Value `k` (centre x, y, z, radius) of spheres `first .. first + 4`.
    #[inline(always)]
    fn lanes(&self, k: usize, first: usize) -> Option<f64x4> {
        let four: &[f64; 4] = self.values[k].get(first..)?.first_chunk()?;
        Some(f64x4::new(*four))
    }

    /// [`Sphere::hit_distance`]'s roots for the four spheres from `first`;
    /// `None` when no lane below `count` has any.
    #[inline(always)]
    fn roots(&self, ray: &Ray, first: u32, count: u32) -> Option<Roots> {
        let first = first as usize;
        let [center_x, center_y, center_z, radius] = [
            self.lanes(0, first)?,
            self.lanes(1, first)?,
            self.lanes(2, first)?,
            self.lanes(3, first)?,
        ];
        let [d_x, d_y, d_z] = ray.direction.to_array().map(f64x4::splat);
        let [o_x, o_y, o_z] = ray.origin.to_array().map(f64x4::splat);
        let sign = f64x4::splat(-0.0);

        let (f_x, f_y, f_z) = (o_x - center_x, o_y - center_y, o_z - center_z);
        let b = f_x * d_x + f_y * d_y + f_z * d_z;
        let radius_squared = radius * radius;
        let c = (f_x * f_x + f_y * f_y + f_z * f_z) - radius_squared;
        // r² − |f − (f·d) d|², as the scalar test computes it (see there).
        let (closest_x, closest_y, closest_z) = (f_x - b * d_x, f_y - b * d_y, f_z - b * d_z);
        let discriminant = radius_squared - (closest_x * closest_x + closest_y * closest_y + closest_z * closest_z);
        let real = !discriminant.cmp_lt(f64x4::ZERO);
        let mask = real.move_mask() as u32 & ((1 << count) - 1);
        if mask == 0 {
            return None;
        }
        // q = −b − copysign(√discriminant, b); the negation flips the sign
        // bit, as the scalar `-b` does (0 − b would turn −0 into +0).
        let q = (b ^ sign) - discriminant.sqrt().copysign(b);
        let a = c / q;
        let a_nearer = a.cmp_lt(q);
        Some(Roots {
            mask,
            near: a_nearer.blend(a, q).to_array(),
            far: a_nearer.blend(q, a).to_array(),
        })
    }

    /// The nearest hit in `(0, t_max)` among spheres `first .. first + count`
    /// (a leaf): the one [`Sphere::hit_distance`] finds when run over them
    /// in order, each with `t_max` lowered to the hit before it. Compiled
    /// for AVX2 when given `avx2`, the proof that the CPU has it.
    #[inline(always)]
    pub fn intersect_leaf(&self, avx2: Option<Avx2>, ray: &Ray, first: u32, count: u32, t_max: f64) -> Option<SphereHit> {
        #[cfg(target_arch = "x86_64")]
        if avx2.is_some() {
            // SAFETY: `avx2` exists only if this CPU has AVX2 (`Avx2::detect`).
            #[allow(unsafe_code)]
            return unsafe { self.intersect_leaf_avx2(ray, first, count, t_max) };
        }
        let _ = avx2;
        self.intersect_leaf_portable(ray, first, count, t_max)
    }

    /// Whether any of spheres `first .. first + count` (a leaf) is hit in
    /// `(0, t_max)`; compiled for AVX2 when given `avx2`.
    #[inline(always)]
    pub fn occludes_leaf(&self, avx2: Option<Avx2>, ray: &Ray, first: u32, count: u32, t_max: f64) -> bool {
        #[cfg(target_arch = "x86_64")]
        if avx2.is_some() {
            // SAFETY: `avx2` exists only if this CPU has AVX2 (`Avx2::detect`).
            #[allow(unsafe_code)]
            return unsafe { self.occludes_leaf_avx2(ray, first, count, t_max) };
        }
        let _ = avx2;
        self.occludes_leaf_portable(ray, first, count, t_max)
    }

    // The leaf tests are out of line: inlined into the BVH traversal they
    // would cost every scene registers and spills, sphere leaves or none.
    // Each is compiled twice, for baseline x86-64 and for AVX2, as the
    // traversal is (`accel::kernel`), from the same source: the same
    // operations in the same order, so the same answers bit for bit.

    #[inline(never)]
    fn intersect_leaf_portable(&self, ray: &Ray, first: u32, count: u32, t_max: f64) -> Option<SphereHit> {
        self.intersect_leaf_inlined(ray, first, count, t_max, || self.roots(ray, first, count))
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline(never)]
    fn intersect_leaf_avx2(&self, ray: &Ray, first: u32, count: u32, t_max: f64) -> Option<SphereHit> {
        self.intersect_leaf_inlined(ray, first, count, t_max, || self.roots_avx2(ray, first, count))
    }

    #[inline(never)]
    fn occludes_leaf_portable(&self, ray: &Ray, first: u32, count: u32, t_max: f64) -> bool {
        self.occludes_leaf_inlined(ray, first, count, t_max, || self.roots(ray, first, count))
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline(never)]
    fn occludes_leaf_avx2(&self, ray: &Ray, first: u32, count: u32, t_max: f64) -> bool {
        self.occludes_leaf_inlined(ray, first, count, t_max, || self.roots_avx2(ray, first, count))
    }

    #[inline(always)]
    fn intersect_leaf_inlined(
        &self,
        ray: &Ray,
        first: u32,
        count: u32,
        t_max: f64,
        roots: impl FnOnce() -> Option<Roots>,
    ) -> Option<SphereHit> {
        if count <= SCALAR_COUNT {
            // One or two live lanes of four cost more than the scalar tests.
            let mut nearest = None;
            let mut bound = t_max;
            for index in first..first + count {
                if let Some(t) = self.sphere(index)?.hit_distance(ray, bound) {
                    bound = t;
                    nearest = Some(SphereHit { index, t });
                }
            }
            return nearest;
        }
        let roots = roots()?;
        // The scalar loop's answer without its branches, which mispredict
        // (whether a lane's root beats the bound is a coin toss): a lane's
        // root is its nearer one if positive, else its farther one
        // ([`Sphere::root_within`]; the nearer one at or past the bound
        // leaves the farther past it too), and the loop reports the first
        // lane of the smallest root in (0, t_max), lowering the bound as it
        // goes. Each step below is that, by selects.
        let (mut bound, mut nearest_lane) = (t_max, u32::MAX);
        for lane in 0..4 {
            let (near, far) = (roots.near[lane], roots.far[lane]);
            let root = select(near > 0.0, near, far);
            let taken = (roots.mask >> lane & 1 == 1) & (root > 0.0) & (root < bound);
            bound = select(taken, root, bound);
            nearest_lane = if taken { lane as u32 } else { nearest_lane };
        }
        (nearest_lane != u32::MAX).then(|| SphereHit {
            index: first + nearest_lane,
            t: bound,
        })
    }

    #[inline(always)]
    fn occludes_leaf_inlined(
        &self,
        ray: &Ray,
        first: u32,
        count: u32,
        t_max: f64,
        roots: impl FnOnce() -> Option<Roots>,
    ) -> bool {
        if count <= SCALAR_COUNT {
            return (first..first + count).any(|index| {
                self.sphere(index)
                    .is_some_and(|sphere| sphere.hit_distance(ray, t_max).is_some())
            });
        }
        roots().is_some_and(|roots| {
            let (zero, bound) = (f64x4::ZERO, f64x4::splat(t_max));
            let in_range = |t: [f64; 4]| {
                let t = f64x4::new(t);
                (t.cmp_gt(zero) & t.cmp_lt(bound)).move_mask() as u32
            };
            roots.mask & (in_range(roots.near) | in_range(roots.far)) != 0
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A small deterministic generator (the tests need no statistical quality).
    struct Lcg(u64);

    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }

        fn vector(&mut self, scale: f64) -> DVec3 {
            DVec3::new(self.next() - 0.5, self.next() - 0.5, self.next() - 0.5) * scale
        }
    }

    fn sphere(center: DVec3, radius: f64) -> Sphere {
        Sphere { center, radius }
    }

    /// The scalar loop the leaf test must reproduce.
    fn scalar_nearest(spheres: &[Sphere], first: usize, count: usize, ray: &Ray, t_max: f64) -> Option<SphereHit> {
        let mut bound = t_max;
        let mut nearest = None;
        for (index, sphere) in spheres.iter().enumerate().skip(first).take(count) {
            if let Some(t) = sphere.hit_distance(ray, bound) {
                bound = t;
                nearest = Some(SphereHit { index: index as u32, t });
            }
        }
        nearest
    }

    /// Random spheres, smallpt's walls of radius 10⁵, repeated spheres
    /// (lanes that tie) and concentric ones, in leaves of every size 1–4,
    /// hit by rays from outside and inside, grazing, tangent and missing:
    /// the four-lane test must give the scalar answers bit for bit, with
    /// and without a bound, and the same occlusion answers.
    #[test]
    fn leaves_match_the_scalar_test_bit_for_bit() {
        let mut random = Lcg(11);
        let mut spheres: Vec<Sphere> = Vec::new();
        for i in 0..400 {
            let sphere = match i % 6 {
                0 => sphere(DVec3::new(1e5 + 1.0, 40.8, 81.6), 1e5),
                1 => spheres.last().copied().unwrap_or_else(|| sphere(DVec3::ZERO, 1.0)),
                2 => sphere(random.vector(1.0), 0.5 + random.next()),
                _ => sphere(random.vector(40.0), 0.1 + 10.0 * random.next()),
            };
            spheres.push(sphere);
        }
        let store = Spheres::new(&spheres);
        assert_eq!(store.len(), spheres.len());
        let (mut first, mut leaf, mut hits) = (0, 0, 0);
        while first < spheres.len() {
            let count = (leaf % 4 + 1).min(spheres.len() - first);
            leaf += 1;
            for _ in 0..250 {
                let target_sphere = spheres[first + (random.next() * count as f64) as usize];
                let towards = random.vector(2.0).normalize_or(DVec3::X);
                // A point on the sphere, inside it, or just outside it (grazing rays).
                let scale = [1.0, 0.3, 1.0 + 1e-9, 1.2][(random.next() * 4.0) as usize];
                let target = target_sphere.center + towards * target_sphere.radius * scale;
                let origin = if random.next() < 0.2 {
                    target_sphere.center
                } else {
                    random.vector(60.0)
                };
                let ray = Ray::new(origin, target - origin);
                for t_max in [f64::INFINITY, random.next() * 2.0] {
                    let expected = scalar_nearest(&spheres, first, count, &ray, t_max);
                    let bits = |hit: Option<SphereHit>| hit.map(|h| (h.index, h.t.to_bits()));
                    // Both compiled copies, where the CPU has AVX2.
                    for avx2 in [None, Avx2::detect()] {
                        let found = store.intersect_leaf(avx2, &ray, first as u32, count as u32, t_max);
                        assert_eq!(bits(found), bits(expected), "leaf at {first}, {count} spheres, ray {ray:?}");
                        assert_eq!(
                            store.occludes_leaf(avx2, &ray, first as u32, count as u32, t_max),
                            expected.is_some()
                        );
                    }
                    hits += usize::from(expected.is_some());
                }
            }
            first += count;
        }
        assert!(hits > 20_000, "{hits} hits");
    }
}
