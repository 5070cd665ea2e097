//! The scene's triangles as the BVH's leaves read them, apart from the
//! generic shape enum and from what only the final hit needs (which face
//! it was, for normals and uv; its material).
//!
//! **Stored geometry.** A vertex is the double-precision sum anchor +
//! offset: the anchor is the centre of its mesh's bounds, the offset an
//! `f32`. The scene rounds every mesh position to that form once, before
//! anything else reads it, so intersection, light sampling and shading all
//! see the same triangles, and vertices shared by two faces stay shared bit
//! for bit (watertightness needs that). Offsets from a nearby anchor keep
//! the precision of a mesh far from the world's origin (a 10⁻⁴-sized mesh
//! 10⁵ units out keeps 24 bits relative to its own size, where absolute
//! `f32` coordinates would collapse it). The watertight test runs in double
//! precision on those values.
//!
//! **Leaf layout.** A leaf of n ≤ 4 triangles starting at triangle f (in
//! leaf order) keeps its offsets as structure-of-arrays, coordinate by
//! coordinate: coordinate k (x, y, z of vertex 0, then 1 and 2) of its
//! i-th triangle is `offsets[9f + k·n + i]`. A leaf is thus 36·n
//! contiguous bytes (at most 144: two or three cache lines), and reading
//! four floats from `9f + k·n` gives coordinate k of all its triangles in
//! four lanes ([`lanes`] tests them together); lanes past n read the next
//! coordinates (or, at the end, padding) and are masked off. The test
//! takes a leaf as one fixed 36-float window from `9f`, so its nine loads
//! need no bounds checks of their own. Per triangle there is also a
//! 12-byte record: a word with its mesh (for the anchor) and its lane and
//! leaf size (to find its offsets again), its face and its material, 48
//! bytes per triangle in all. The record is one piece because the final
//! hit needs all three, and on a mesh too large for the caches each
//! separate array read cost the hit a cache miss of its own.

mod lanes;

use super::mesh::Mesh;
use super::triangle::{Triangle, TriangleHit, TriangleRay};
use crate::accel::{Avx2, Leaf, huge_pages};
use glam::DVec3;

/// Which face of which mesh a stored triangle is, and its material.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TriangleSource {
    /// Index of the scene mesh the triangle belongs to.
    pub mesh: u32,
    /// Index of the face within that mesh (for its normals and uv).
    pub face: u32,
    /// Index of the triangle's material in the scene's material list.
    pub material: u32,
}

/// A triangle's mesh in the low bits of its placement word, its lane and
/// its leaf's size − 1 in the top four.
const MESH_BITS: u32 = 28;
const MESH_MASK: u32 = (1 << MESH_BITS) - 1;
/// Most meshes the triangles can refer to.
pub const MAX_MESHES: usize = 1 << MESH_BITS;
/// Floats of a full leaf (four triangles, nine coordinates each). The leaf
/// test reads this many from a leaf's start whatever its size, so the
/// offsets end with enough padding for the last leaf's window.
const LEAF_FLOATS: usize = 36;
/// Zeros after the last offset: a one-triangle leaf at the end reads 27
/// floats past its nine.
const OFFSET_PADDING: usize = LEAF_FLOATS - 9;
/// Zero records after the last one: a leaf's four lanes read four placement words.
const RECORD_PADDING: usize = 3;

/// A triangle's record (see the module doc).
#[derive(Clone, Copy, Debug, Default)]
struct Record {
    /// Mesh, lane and leaf size (see [`MESH_BITS`]).
    placement: u32,
    face: u32,
    material: u32,
}

/// Triangles in leaf order.
#[derive(Clone, Debug, Default)]
pub struct Triangles {
    /// Vertex offsets from the mesh anchors, leaf by leaf as
    /// structure-of-arrays (see the module doc), then [`OFFSET_PADDING`] zeros.
    offsets: Vec<f32>,
    /// Per triangle, then [`RECORD_PADDING`] zero records.
    records: Vec<Record>,
    /// Per mesh: the point offsets are measured from.
    anchors: Vec<DVec3>,
    /// The anchor of every triangle when they all share one (the common
    /// case of one mesh), which spares the leaf test a gather per lane.
    shared_anchor: Option<DVec3>,
}

/// A leaf as the four-lane tests ([`lanes`]) read it.
struct LeafData<'a> {
    /// The [`LEAF_FLOATS`] offsets from the leaf's first.
    block: &'a [f32; LEAF_FLOATS],
    /// Its number of triangles, 1 to 4.
    count: usize,
    /// Per permuted axis of the ray, the anchor of each lane's mesh.
    anchors: [[f64; 4]; 3],
}

impl LeafData<'_> {
    /// Coordinate `k` (x, y, z of vertex 0, then 1 and 2) of the four
    /// lanes' triangles: four offsets from `k · count`. As `k ≤ 8` and
    /// `count ≤ 4`, the clamp changes nothing but spares a bounds check.
    #[inline(always)]
    fn offsets(&self, k: usize) -> [f32; 4] {
        let start = (k * self.count).min(LEAF_FLOATS - 4);
        std::array::from_fn(|lane| self.block[start..start + 4][lane])
    }

    /// Bit i set for each lane holding one of the leaf's triangles.
    #[inline(always)]
    fn active(&self) -> u32 {
        (1 << self.count) - 1
    }
}

/// The nearest triangle hit found in a leaf.
#[derive(Clone, Copy, Debug)]
pub struct LeafHit {
    /// Index of the triangle in leaf order.
    pub index: u32,
    /// Ray parameter and barycentric coordinates of the hit.
    pub hit: TriangleHit,
}

impl Triangles {
    /// Stores `triangles` (whose vertices must already be in stored form,
    /// see [`store_mesh_positions`]), each with its material, in the order
    /// `order`, grouped into `leaves` (which must cover `0 .. order.len()`
    /// once, as the BVH's triangle leaves do); `anchors` are the meshes'
    /// anchors. Meshes past [`MAX_MESHES`] are not representable and are
    /// stored as mesh 0.
    pub fn new(triangles: &[(Triangle, u32)], order: &[u32], leaves: &[Leaf], anchors: Vec<DVec3>) -> Self {
        let count = order.len();
        // A large mesh's leaves on huge pages (`accel::huge_pages`).
        let mut offsets = huge_pages::filled(9 * count + OFFSET_PADDING, 0.0f32);
        let mut records = huge_pages::filled(count + RECORD_PADDING, Record::default());
        let anchor_of = |mesh: u32| anchors.get(mesh as usize).copied().unwrap_or(DVec3::ZERO);
        for leaf in leaves {
            let n = leaf.count as usize;
            for lane in 0..n {
                let slot = leaf.first as usize + lane;
                let Some(&index) = order.get(slot) else { continue };
                let (triangle, material) = &triangles[index as usize];
                let mesh = if (triangle.mesh as usize) < MAX_MESHES {
                    triangle.mesh
                } else {
                    0
                };
                let anchor = anchor_of(mesh);
                for (vertex, position) in triangle.vertices.iter().enumerate() {
                    let offset = (*position - anchor).to_array();
                    for axis in 0..3 {
                        offsets[9 * leaf.first as usize + (3 * vertex + axis) * n + lane] = offset[axis] as f32;
                    }
                }
                records[slot] = Record {
                    placement: mesh | ((lane as u32) << MESH_BITS) | ((n as u32 - 1) << (MESH_BITS + 2)),
                    face: triangle.face,
                    material: *material,
                };
            }
        }
        let first_anchor = records[..count].first().map(|record| anchor_of(record.placement & MESH_MASK));
        let shared_anchor = first_anchor.filter(|&first| {
            records[..count].iter().all(|record| {
                anchor_of(record.placement & MESH_MASK).to_array().map(f64::to_bits) == first.to_array().map(f64::to_bits)
            })
        });
        Self {
            offsets,
            records,
            anchors,
            shared_anchor,
        }
    }

    /// Number of triangles stored.
    pub fn len(&self) -> usize {
        self.records.len().saturating_sub(RECORD_PADDING)
    }

    /// Whether no triangle is stored.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Bytes per triangle of leaf and hit data: nine offsets and the
    /// record (placement word, face and material).
    pub const BYTES_PER_TRIANGLE: usize = 9 * 4 + std::mem::size_of::<Record>();

    fn anchor(&self, mesh: u32) -> DVec3 {
        self.anchors.get(mesh as usize).copied().unwrap_or(DVec3::ZERO)
    }

    /// Triangle `index` (in leaf order) in double precision: the stored vertices.
    pub fn get(&self, index: u32) -> Triangle {
        let record = self.records[index as usize];
        let word = record.placement;
        let lane = (word >> MESH_BITS) & 3;
        let n = (word >> (MESH_BITS + 2)) as usize + 1;
        let base = 9 * (index - lane) as usize + lane as usize;
        let anchor = self.anchor(word & MESH_MASK);
        let vertex = |v: usize| {
            DVec3::from_array(std::array::from_fn(|axis| {
                anchor[axis] + f64::from(self.offsets[base + (3 * v + axis) * n])
            }))
        };
        Triangle {
            vertices: [vertex(0), vertex(1), vertex(2)],
            mesh: word & MESH_MASK,
            face: record.face,
        }
    }

    /// Which mesh, face and material triangle `index` (in leaf order) comes from.
    pub fn source(&self, index: u32) -> TriangleSource {
        let record = self.records[index as usize];
        TriangleSource {
            mesh: record.placement & MESH_MASK,
            face: record.face,
            material: record.material,
        }
    }

    /// What the four-lane tests read of the leaf of triangles
    /// `first .. first + count`: its window of offsets and, per lane, the
    /// anchor of its triangle's mesh along each of the ray's permuted axes.
    #[inline(always)]
    fn leaf_data(&self, ray: &TriangleRay, first: u32, count: u32) -> Option<LeafData<'_>> {
        let first = first as usize;
        let block: &[f32; LEAF_FLOATS] = self.offsets.get(9 * first..)?.first_chunk()?;
        let anchors = match self.shared_anchor {
            Some(anchor) => ray.axes.map(|axis| [anchor[axis]; 4]),
            None => {
                let words: [u32; 4] = std::array::from_fn(|lane| self.records[first + lane].placement);
                let anchors = words.map(|word| self.anchor(word & MESH_MASK));
                ray.axes.map(|axis| anchors.map(|a| a[axis]))
            }
        };
        Some(LeafData {
            block,
            count: count as usize,
            anchors,
        })
    }

    /// Starts loading the vertex block of the leaf whose first triangle is
    /// `first` (every cache line of its `LEAF_FLOATS` floats).
    #[inline(always)]
    pub fn prefetch_leaf(&self, first: u32) {
        let start = 9 * first as usize;
        for offset in [0, 16, 32, LEAF_FLOATS - 1] {
            if let Some(value) = self.offsets.get(start + offset) {
                crate::accel::traversal::prefetch(value);
            }
        }
    }

    /// The nearest hit in `(0, t_max)` among triangles `first .. first + count`
    /// (a leaf): the one the scalar test ([`TriangleRay::intersect`]) finds
    /// when run over them in order, each with `t_max` lowered to the hit
    /// before it.
    #[inline(always)]
    pub fn intersect_leaf(&self, avx2: Option<Avx2>, ray: &TriangleRay, first: u32, count: u32, t_max: f64) -> Option<LeafHit> {
        let leaf = self.leaf_data(ray, first, count)?;
        let candidates = lanes::intersect(avx2, ray, &leaf, t_max)?;
        let (lane, hit) = candidates.nearest(t_max)?;
        let index = first + lane as u32;
        // Start loading the record now, though only the final hit needs it:
        // on a mesh larger than the caches its line then arrives while the
        // traversal goes on, rather than after it. A prefetch, unlike a read,
        // never holds up the instructions after it while the line is missing.
        if let Some(record) = self.records.get(index as usize) {
            crate::accel::traversal::prefetch(record);
        }
        Some(LeafHit { index, hit })
    }

    /// Whether any of triangles `first .. first + count` (a leaf) is hit in `(0, t_max)`.
    #[inline(always)]
    pub fn occludes_leaf(&self, avx2: Option<Avx2>, ray: &TriangleRay, first: u32, count: u32, t_max: f64) -> bool {
        self.leaf_data(ray, first, count)
            .and_then(|leaf| lanes::intersect(avx2, ray, &leaf, t_max))
            .is_some()
    }
}
/// The point a mesh's offsets are measured from: the centre of its bounds.
pub fn anchor_of(mesh: &Mesh) -> DVec3 {
    let (low, high) = mesh
        .positions
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(low, high), p| {
            (low.min(*p), high.max(*p))
        });
    if low.cmpgt(high).any() {
        DVec3::ZERO
    } else {
        0.5 * (low + high)
    }
}

/// `point` in stored form: `anchor` plus the offset rounded to `f32`.
pub fn stored_position(anchor: DVec3, point: DVec3) -> DVec3 {
    anchor + (point - anchor).as_vec3().as_dvec3()
}

/// Rounds a mesh's positions to stored form (see the module doc) and
/// returns its anchor; everything that reads the mesh afterwards agrees
/// with the BVH's leaves.
pub fn store_mesh_positions(mesh: &mut Mesh) -> DVec3 {
    let anchor = anchor_of(mesh);
    for position in &mut mesh.positions {
        *position = stored_position(anchor, *position);
    }
    anchor
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Ray;

    /// A small deterministic generator (the tests need no statistical quality).
    struct Lcg(u64);

    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Two meshes of a jittered height field sharing vertices between
    /// faces, the second 10⁵ units away (its own anchor), with every fifth
    /// face repeated (equal distances inside one leaf), in leaves of every
    /// size 1–4: the four-lane test, in both its copies (baseline x86-64
    /// and AVX2), must give the scalar test's answers bit for bit,
    /// including at shared edges and vertices and at ties.
    #[test]
    fn leaf_test_matches_the_scalar_test_bit_for_bit() {
        let mut random = Lcg(7);
        let side = 8;
        let mut triangles = Vec::new();
        let mut anchors = Vec::new();
        for (mesh, shift) in [(0u32, DVec3::ZERO), (1, DVec3::new(1e5, -3e4, 2.0))] {
            let heights: Vec<f64> = (0..side * side).map(|_| random.next()).collect();
            let point = |i: usize, j: usize| shift + DVec3::new(i as f64, j as f64, heights[i * side + j]) * 0.37;
            let anchor = shift + DVec3::splat(1.3);
            anchors.push(anchor);
            for i in 0..side - 1 {
                for j in 0..side - 1 {
                    let [a, b, c, d] =
                        [point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)].map(|p| stored_position(anchor, p));
                    for (face, vertices) in [[a, b, c], [a, c, d]].into_iter().enumerate() {
                        let triangle = Triangle {
                            vertices,
                            mesh,
                            face: face as u32,
                        };
                        triangles.push((triangle, 0));
                        if triangles.len() % 5 == 0 {
                            triangles.push((triangle, 1));
                        }
                    }
                }
            }
        }
        let order: Vec<u32> = (0..triangles.len() as u32).collect();
        let mut leaves = Vec::new();
        let mut first = 0;
        for size in [4, 3, 2, 1].into_iter().cycle() {
            if first == order.len() as u32 {
                break;
            }
            let count = size.min(order.len() as u32 - first);
            leaves.push(Leaf { kind: 0, first, count });
            first += count;
        }
        let stored = Triangles::new(&triangles, &order, &leaves, anchors);
        for (index, (triangle, _)) in triangles.iter().enumerate() {
            assert_eq!(stored.get(index as u32).vertices, triangle.vertices);
        }

        let (mut hits, mut edge_hits, mut ties) = (0, 0, 0);
        for _ in 0..3000 {
            // Aim at a vertex, an edge midpoint or a random point of a face.
            let (target_triangle, _) = triangles[(random.next() * triangles.len() as f64) as usize];
            let [a, b, c] = target_triangle.vertices;
            let target = match (random.next() * 3.0) as u32 {
                0 => a,
                1 => 0.5 * (a + b),
                _ => {
                    let (u, v) = (random.next(), random.next());
                    let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
                    a + u * (b - a) + v * (c - a)
                }
            };
            // A third of the rays straight down, which makes the edge
            // functions of vertex and midpoint hits exactly zero.
            let direction = if random.next() < 1.0 / 3.0 {
                -DVec3::Z
            } else {
                DVec3::new(random.next() - 0.5, random.next() - 0.5, random.next() - 0.5).normalize()
            };
            let ray = Ray::new(target - 5.0 * direction, direction);
            let triangle_ray = TriangleRay::new(&ray);
            for leaf in &leaves {
                for t_max in [f64::INFINITY, 5.0, 5.0 + 1e-12] {
                    let mut scalar: Option<LeafHit> = None;
                    let mut bound = t_max;
                    for index in leaf.first..leaf.first + leaf.count {
                        let [p, q, r] = stored.get(index).vertices;
                        let v = [p.x, p.y, p.z, q.x, q.y, q.z, r.x, r.y, r.z];
                        if let Some(hit) = triangle_ray.intersect(&v, bound) {
                            if scalar.is_some_and(|s| s.hit.t == hit.t) {
                                ties += 1;
                            }
                            bound = hit.t;
                            scalar = Some(LeafHit { index, hit });
                        }
                    }
                    let bits = |h: Option<LeafHit>| h.map(|h| (h.index, h.hit.t.to_bits(), h.hit.barycentric.map(f64::to_bits)));
                    // Both compiled copies of the test, where the CPU has AVX2.
                    for avx2 in [None, Avx2::detect()] {
                        let lanes = stored.intersect_leaf(avx2, &triangle_ray, leaf.first, leaf.count, t_max);
                        assert_eq!(bits(lanes), bits(scalar), "{ray:?} leaf {leaf:?} t_max {t_max} {avx2:?}");
                        let occluded = stored.occludes_leaf(avx2, &triangle_ray, leaf.first, leaf.count, t_max);
                        assert_eq!(occluded, scalar.is_some());
                    }
                    if let Some(hit) = scalar {
                        hits += 1;
                        edge_hits += usize::from(hit.hit.barycentric.contains(&0.0));
                    }
                }
            }
        }
        // The cases that can go wrong must have happened.
        assert!(
            hits > 5000 && edge_hits > 100 && ties > 100,
            "{hits} hits, {edge_hits} on edges, {ties} ties"
        );
    }
}
