//! The ray core's answers against exact arithmetic: for 10⁶ random rays
//! through a closed mesh, the triangle the BVH reports as the nearest hit
//! (or its report of a miss) must be what exact rational arithmetic says,
//! on the stored (single-precision) vertices and the exact ray. Exact ties
//! (a ray through a shared edge or vertex) accept any of the tied faces.
//!
//! What this guards: the four-wide BVH's single-precision box tests must
//! never cull a triangle the exact test hits (they are rounded outward and
//! widened; rays grazing box faces happen thousands of times in 10⁶ rays),
//! and the watertight test must agree with exact signs away from edges.
//!
//! The reference is independent of the BVH: every triangle is a candidate,
//! pruned only by a conservative bounding-sphere test; edge signs are
//! computed in `f64` with a forward error bound and, where that cannot
//! decide, exactly with big integers (every `f64` is an integer times
//! 2⁻¹¹⁰⁰).

use glam::DVec3;
use num_bigint::BigInt;
use num_traits::{Signed, Zero};
use prism::bench::scaling::sphere_mesh;
use prism::geometry::triangle::TriangleRay;
use prism::math::Ray;
use prism::sampler::{Sampler, SamplerKind};
use prism::scene::Scene;
use rayon::prelude::*;
use std::cmp::Ordering;

const RAYS: u64 = 1_000_000;

/// `x` as an exact integer multiple of 2⁻¹¹⁰⁰.
fn exact(x: f64) -> BigInt {
    if x == 0.0 {
        return BigInt::zero();
    }
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i64;
    let fraction = bits & ((1u64 << 52) - 1);
    let (mantissa, power) = if exponent == 0 {
        (fraction, -1074)
    } else {
        (fraction | (1u64 << 52), exponent - 1075)
    };
    let magnitude = BigInt::from(mantissa) << ((power + 1100) as usize);
    if x < 0.0 { -magnitude } else { magnitude }
}

type Exact3 = [BigInt; 3];

fn exact3(v: DVec3) -> Exact3 {
    [exact(v.x), exact(v.y), exact(v.z)]
}

fn sub(a: &Exact3, b: &Exact3) -> Exact3 {
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}

fn det(a: &Exact3, b: &Exact3, c: &Exact3) -> BigInt {
    &a[0] * (&b[1] * &c[2] - &b[2] * &c[1]) - &a[1] * (&b[0] * &c[2] - &b[2] * &c[0]) + &a[2] * (&b[0] * &c[1] - &b[1] * &c[0])
}

fn sign(x: &BigInt) -> i32 {
    if x.is_positive() {
        1
    } else if x.is_negative() {
        -1
    } else {
        0
    }
}

/// A hit the reference found: face, plane distance t = N / D in f64 with a
/// bound on its error, and the exact fraction when it was needed.
struct ReferenceHit {
    face: usize,
    t: f64,
    t_error: f64,
    exact: Option<(BigInt, BigInt)>,
}

impl ReferenceHit {
    /// N and D exactly: N = (a − o)·n, D = d·n, n = (b − a) × (c − a).
    fn exact_fraction([a, b, c]: [DVec3; 3], origin: DVec3, direction: DVec3) -> (BigInt, BigInt) {
        let (ea, eb, ec, eo, ed) = (exact3(a), exact3(b), exact3(c), exact3(origin), exact3(direction));
        let (ab, ac, ua) = (sub(&eb, &ea), sub(&ec, &ea), sub(&ea, &eo));
        let n = [
            &ab[1] * &ac[2] - &ab[2] * &ac[1],
            &ab[2] * &ac[0] - &ab[0] * &ac[2],
            &ab[0] * &ac[1] - &ab[1] * &ac[0],
        ];
        let dot = |x: &Exact3| &x[0] * &n[0] + &x[1] * &n[1] + &x[2] * &n[2];
        (dot(&ua), dot(&ed))
    }

    /// Orders two hits by distance; exactly when their f64 intervals overlap.
    fn cmp_distance(&self, other: &ReferenceHit, faces: &[[DVec3; 3]], origin: DVec3, direction: DVec3) -> Ordering {
        if self.t + self.t_error < other.t - other.t_error {
            return Ordering::Less;
        }
        if self.t - self.t_error > other.t + other.t_error {
            return Ordering::Greater;
        }
        let mine = self
            .exact
            .clone()
            .unwrap_or_else(|| Self::exact_fraction(faces[self.face], origin, direction));
        let theirs = other
            .exact
            .clone()
            .unwrap_or_else(|| Self::exact_fraction(faces[other.face], origin, direction));
        let order = (&mine.0 * &theirs.1).cmp(&(&theirs.0 * &mine.1));
        if sign(&mine.1) * sign(&theirs.1) < 0 {
            order.reverse()
        } else {
            order
        }
    }
}

/// The sign of det(a − o, b − o, d) in f64 when the forward error bound
/// decides it, else `None`.
fn filtered_edge_sign(a: DVec3, b: DVec3, o: DVec3, d: DVec3) -> Option<i32> {
    let (u, v) = (a - o, b - o);
    let value = u.dot(v.cross(d));
    // Each of u, v carries one rounding; the triple product adds a few
    // more: 1e-12 of the magnitude bound is far beyond them.
    let bound = 1e-12 * u.length() * v.length() * d.length();
    if value > bound {
        Some(1)
    } else if value < -bound {
        Some(-1)
    } else {
        None
    }
}

/// Whether the exact ray hits face `[a, b, c]` at t > 0, and where.
fn reference_hit(face: usize, [a, b, c]: [DVec3; 3], origin: DVec3, direction: DVec3) -> Option<ReferenceHit> {
    let filtered = [
        filtered_edge_sign(a, b, origin, direction),
        filtered_edge_sign(b, c, origin, direction),
        filtered_edge_sign(c, a, origin, direction),
    ];
    let certain: Vec<i32> = filtered.iter().flatten().copied().collect();
    if certain.contains(&1) && certain.contains(&-1) {
        return None;
    }
    // Plane distance in f64, with a generous relative error bound.
    let n = (b - a).cross(c - a);
    let (numerator, denominator) = ((a - origin).dot(n), direction.dot(n));
    let t = numerator / denominator;
    let t_error = 1e-9 * t.abs() + 1e-12 * ((a - origin).length() * n.length() / denominator.abs());
    let decided = certain.len() == 3 && t.is_finite() && t - t_error > 0.0;
    if decided {
        return Some(ReferenceHit {
            face,
            t,
            t_error,
            exact: None,
        });
    }
    // Undecided in f64: exact signs and distance.
    let (ea, eb, ec, eo, ed) = (exact3(a), exact3(b), exact3(c), exact3(origin), exact3(direction));
    let (ua, ub, uc) = (sub(&ea, &eo), sub(&eb, &eo), sub(&ec, &eo));
    let signs = [det(&ua, &ub, &ed), det(&ub, &uc, &ed), det(&uc, &ua, &ed)].map(|s| sign(&s));
    let (positive, negative) = (signs.contains(&1), signs.contains(&-1));
    if positive && negative || !(positive || negative) {
        return None;
    }
    let (numerator, denominator) = ReferenceHit::exact_fraction([a, b, c], origin, direction);
    if denominator.is_zero() || sign(&numerator) * sign(&denominator) <= 0 {
        return None;
    }
    Some(ReferenceHit {
        face,
        t: if t.is_finite() { t } else { 0.0 },
        t_error: f64::INFINITY,
        exact: Some((numerator, denominator)),
    })
}

/// Faces grouped by position (Morton order of their centroids), each face
/// and group with a bounding sphere: candidates for a ray are the faces
/// whose sphere the ray's line passes, a conservative and BVH-free prune.
struct Candidates {
    faces: Vec<[DVec3; 3]>,
    face_spheres: Vec<(DVec3, f64)>,
    groups: Vec<(DVec3, f64, Vec<usize>)>,
}

impl Candidates {
    const GROUP: usize = 16;

    fn new(faces: Vec<[DVec3; 3]>) -> Self {
        let sphere_of = |points: &[DVec3]| {
            let center = points.iter().copied().sum::<DVec3>() / points.len() as f64;
            let radius = points.iter().map(|p| (*p - center).length()).fold(0.0, f64::max);
            (center, radius * (1.0 + 1e-6) + 1e-9)
        };
        let face_spheres: Vec<(DVec3, f64)> = faces.iter().map(|f| sphere_of(f)).collect();
        let (lo, hi) = faces
            .iter()
            .flatten()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        let morton = |p: DVec3| {
            let q = ((p - lo) / (hi - lo).max(DVec3::splat(1e-30)) * 1023.0).as_uvec3();
            (0..10).fold(0u64, |code, bit| {
                code | ((((q.x >> bit) & 1) as u64) << (3 * bit))
                    | ((((q.y >> bit) & 1) as u64) << (3 * bit + 1))
                    | ((((q.z >> bit) & 1) as u64) << (3 * bit + 2))
            })
        };
        let mut order: Vec<usize> = (0..faces.len()).collect();
        order.sort_by_key(|&i| morton(face_spheres[i].0));
        let groups = order
            .chunks(Self::GROUP)
            .map(|members| {
                let points: Vec<DVec3> = members.iter().flat_map(|&i| faces[i]).collect();
                let (center, radius) = sphere_of(&points);
                (center, radius, members.to_vec())
            })
            .collect();
        Self {
            faces,
            face_spheres,
            groups,
        }
    }

    /// Whether the ray's half-line (t > −radius) comes within `radius` of `center`.
    fn near(ray: &Ray, center: DVec3, radius: f64) -> bool {
        let to_center = center - ray.origin;
        let along = to_center.dot(ray.direction);
        let miss_distance_squared = to_center.length_squared() - along * along;
        miss_distance_squared <= radius * radius * (1.0 + 1e-6) && along >= -radius
    }

    fn for_ray(&self, ray: Ray) -> impl Iterator<Item = usize> + '_ {
        self.groups
            .iter()
            .filter(move |(center, radius, _)| Self::near(&ray, *center, *radius))
            .flat_map(|(_, _, members)| members.iter().copied())
            .filter(move |&face| Self::near(&ray, self.face_spheres[face].0, self.face_spheres[face].1))
    }
}

/// A closed mesh (a UV sphere: fans of thin faces meet at its poles) as
/// the scene stores it, and its faces for the references.
fn test_scene() -> (prism::scene::Scene, Candidates) {
    let scene = Scene::from_mesh(sphere_mesh(1200, DVec3::new(0.3, -0.2, 0.1), 1.7));
    let stored = &scene.meshes[0];
    let faces = stored.faces.iter().map(|f| f.map(|i| stored.positions[i as usize])).collect();
    (scene, Candidates::new(faces))
}

/// Origin `i` of a fixed random stream: uniform on a sphere 1.5 bounding
/// radii around the scene, plus two more uniform numbers.
fn random_origin(scene: &prism::scene::Scene, i: u64) -> (DVec3, Sampler) {
    let bounds = scene.bounds();
    let (center, radius) = (bounds.centroid(), 0.5 * bounds.extent().length());
    let mut sampler = Sampler::new(SamplerKind::Random, i, 0, 0xe4ac7);
    let origin = center + 1.5 * radius * prism::math::warp::square_to_uniform_sphere(sampler.next_2d());
    (origin, sampler)
}

#[test]
fn a_million_random_rays_agree_with_exact_arithmetic() {
    let (scene, candidates) = test_scene();
    let bounds = scene.bounds();
    let faces = &candidates.faces;
    let disagreements: Vec<u64> = (0..RAYS)
        .into_par_iter()
        .filter(|&i| {
            let (origin, mut sampler) = random_origin(&scene, i);
            let u = sampler.next_2d();
            let target = bounds.min + bounds.extent() * DVec3::new(u.x, u.y, sampler.next_1d());
            let ray = Ray::new(origin, target - origin);

            // Exact reference: all hits, then the nearest (with ties).
            let hits: Vec<ReferenceHit> = candidates
                .for_ray(ray)
                .filter_map(|face| reference_hit(face, faces[face], ray.origin, ray.direction))
                .collect();
            let order = |a: &ReferenceHit, b: &ReferenceHit| a.cmp_distance(b, faces, ray.origin, ray.direction);
            let nearest = hits.iter().min_by(|a, b| order(a, b));
            let fast = scene.intersect(&ray, f64::INFINITY);
            let agree = match (fast, nearest) {
                (None, None) => true,
                (Some(found), Some(nearest)) => {
                    let face = scene.triangle_source(found.primitive).map(|s| s.face as usize);
                    hits.iter()
                        .filter(|h| order(h, nearest) == Ordering::Equal)
                        .any(|h| Some(h.face) == face)
                }
                _ => false,
            };
            // An occlusion query must agree on whether anything is hit.
            let occluded = scene.occluded(&ray, f64::INFINITY);
            !agree || occluded != nearest.is_some()
        })
        .collect();
    assert!(
        disagreements.is_empty(),
        "{} of {RAYS} rays disagree with exact arithmetic, e.g. ray {:?}",
        disagreements.len(),
        disagreements.first()
    );
}

/// Rays aimed exactly at the stored vertices graze the BVH's boxes (which
/// are tight around those vertices) at their corners, the hardest case for
/// conservative box tests. The reference applies the same watertight
/// triangle test to every candidate face; the BVH must visit the leaf of
/// every face that test hits (up to the distance the BVH settles on), and
/// so find the same nearest distance, to within the last-place rounding of
/// the watertight test's scaled comparison with `t_max` (several faces
/// meet at a vertex, at distances one ulp apart). Occlusion must agree too.
#[test]
fn rays_at_vertices_visit_every_leaf_the_triangle_test_hits() {
    let (scene, candidates) = test_scene();
    let vertices = &scene.meshes[0].positions;
    let count = 200_000u64;
    let culled: Vec<u64> = (0..count)
        .into_par_iter()
        .filter(|&i| {
            let (origin, _) = random_origin(&scene, i);
            let target = vertices[(i as usize * 7919) % vertices.len()];
            let ray = Ray::new(origin, target - origin);
            let triangle_ray = TriangleRay::new(&ray);
            let hits: Vec<(u32, f64)> = candidates
                .for_ray(ray)
                .filter_map(|face| {
                    let [a, b, c] = candidates.faces[face];
                    let hit = triangle_ray.intersect(&[a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z], f64::INFINITY)?;
                    Some((face as u32, hit.t))
                })
                .collect();
            let nearest = hits.iter().map(|h| h.1).fold(f64::INFINITY, f64::min);
            // The BVH's traversal, recording every face of every leaf it visits.
            let mut visited = Vec::new();
            let mut t = f64::INFINITY;
            scene.bvh().traverse(&ray, &mut t, |leaf, t_max| {
                visited.extend((leaf.first..leaf.first + leaf.count).map(|k| scene.triangles().source(k).face));
                if let Some(found) =
                    scene
                        .triangles()
                        .intersect_leaf(scene.bvh().avx2(), &triangle_ray, leaf.first, leaf.count, *t_max)
                {
                    *t_max = found.hit.t;
                }
                false
            });
            let missed_leaf = hits.iter().any(|(face, hit_t)| *hit_t <= t && !visited.contains(face));
            let close = (t - nearest).abs() <= 4.0 * f64::EPSILON * nearest || t == nearest;
            missed_leaf || !close || scene.occluded(&ray, f64::INFINITY) != nearest.is_finite()
        })
        .collect();
    assert!(
        culled.is_empty(),
        "{} of {count} vertex rays differ, e.g. {:?}",
        culled.len(),
        culled.first()
    );
}
