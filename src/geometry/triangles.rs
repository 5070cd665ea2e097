//! The scene's triangles as the BVH's leaves read them: in leaf order, each
//! as nine single-precision offsets from its mesh's anchor point plus the
//! mesh's index (40 bytes, so a four-triangle leaf spans about two and a
//! half cache lines), apart from the generic shape enum and from what only
//! the final hit needs (which face it was, for normals and uv; its material).
//!
//! The stored geometry is exactly what the leaves hold: a vertex is the
//! double-precision sum anchor + offset, the anchor being the centre of its
//! mesh's bounds. The scene rounds every mesh position to that form once,
//! before anything else reads it, so intersection, light sampling and
//! shading all see the same triangles, and vertices shared by two faces stay
//! shared bit for bit (watertightness needs that). Offsets from a nearby
//! anchor keep the precision of a mesh far from the world's origin (a
//! 10⁻⁴-sized mesh 10⁵ units out keeps 24 bits relative to its own size,
//! where absolute `f32` coordinates would collapse it). The watertight test
//! runs in double precision on those values.

use super::mesh::Mesh;
use super::triangle::{Triangle, TriangleHit, TriangleRay};
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

/// What a leaf reads of one triangle.
#[derive(Clone, Copy, Debug)]
struct PackedTriangle {
    /// x, y, z of each vertex, relative to the mesh's anchor.
    offsets: [f32; 9],
    mesh: u32,
}

/// What only the final hit needs.
#[derive(Clone, Copy, Debug)]
struct ColdData {
    face: u32,
    material: u32,
}

/// Triangles in leaf order.
#[derive(Clone, Debug, Default)]
pub struct Triangles {
    packed: Vec<PackedTriangle>,
    cold: Vec<ColdData>,
    /// Per mesh: the point offsets are measured from.
    anchors: Vec<DVec3>,
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
    /// see [`store_mesh_positions`]), each with its material, in the given
    /// order; `anchors` are the meshes' anchors.
    pub fn new(triangles: &[(Triangle, u32)], order: &[u32], anchors: Vec<DVec3>) -> Self {
        let mut packed = Vec::with_capacity(order.len());
        let mut cold = Vec::with_capacity(order.len());
        for &index in order {
            let (triangle, material) = &triangles[index as usize];
            let anchor = anchors.get(triangle.mesh as usize).copied().unwrap_or(DVec3::ZERO);
            let [a, b, c] = triangle.vertices.map(|v| v - anchor);
            packed.push(PackedTriangle {
                offsets: [a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z].map(|v| v as f32),
                mesh: triangle.mesh,
            });
            cold.push(ColdData {
                face: triangle.face,
                material: *material,
            });
        }
        Self { packed, cold, anchors }
    }

    /// Number of triangles stored.
    pub fn len(&self) -> usize {
        self.packed.len()
    }

    /// Whether no triangle is stored.
    pub fn is_empty(&self) -> bool {
        self.packed.is_empty()
    }

    /// Bytes per triangle of leaf and hit data.
    pub const BYTES_PER_TRIANGLE: usize = std::mem::size_of::<PackedTriangle>() + std::mem::size_of::<ColdData>();

    /// Triangle `index` (in leaf order) in double precision: the stored vertices.
    pub fn get(&self, index: u32) -> Triangle {
        let packed = &self.packed[index as usize];
        let v = self.vertices(packed);
        Triangle {
            vertices: [
                DVec3::new(v[0], v[1], v[2]),
                DVec3::new(v[3], v[4], v[5]),
                DVec3::new(v[6], v[7], v[8]),
            ],
            mesh: packed.mesh,
            face: self.cold[index as usize].face,
        }
    }

    /// Which mesh, face and material triangle `index` (in leaf order) comes from.
    pub fn source(&self, index: u32) -> TriangleSource {
        let cold = self.cold[index as usize];
        TriangleSource {
            mesh: self.packed[index as usize].mesh,
            face: cold.face,
            material: cold.material,
        }
    }

    /// The nine stored coordinates: anchor + offset, in `f64`.
    #[inline(always)]
    fn vertices(&self, packed: &PackedTriangle) -> [f64; 9] {
        let anchor = self.anchors[packed.mesh as usize];
        let anchor = [anchor.x, anchor.y, anchor.z];
        std::array::from_fn(|k| anchor[k % 3] + f64::from(packed.offsets[k]))
    }

    /// The nearest hit in `(0, t_max)` among triangles `first .. first + count`.
    #[inline(always)]
    pub fn intersect_leaf(&self, ray: &TriangleRay, first: u32, count: u32, mut t_max: f64) -> Option<LeafHit> {
        let mut nearest = None;
        for index in first..first + count {
            if let Some(hit) = ray.intersect(&self.vertices(&self.packed[index as usize]), t_max) {
                t_max = hit.t;
                nearest = Some(LeafHit { index, hit });
            }
        }
        nearest
    }

    /// Whether any of triangles `first .. first + count` is hit in `(0, t_max)`.
    #[inline(always)]
    pub fn occludes_leaf(&self, ray: &TriangleRay, first: u32, count: u32, t_max: f64) -> bool {
        (first..first + count).any(|index| ray.intersect(&self.vertices(&self.packed[index as usize]), t_max).is_some())
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
