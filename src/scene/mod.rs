//! Scenes: the scene file parsed into a spanned TOML document (`document`),
//! read as plain data (`description`), then checked and turned into a frozen,
//! render-ready `Scene` (`load`) whose acceleration structure is built once
//! and shared read-only. Every error names file, line, column and field
//! (`error`). A description can be placed by a `similarity` (scaled and
//! moved) before it is built.

pub mod description;
pub mod document;
pub mod error;
pub mod load;
pub mod progress;
pub mod similarity;
pub mod specular_balls;
mod visitors;

pub use error::{Location, SceneError};
pub use load::{COORDINATE_LIMIT, LoadedScene, load_scene_bytes, load_scene_file, load_scene_str, load_scene_str_edited};
pub use progress::{LoadStage, load_scene_file_with_progress};
pub use similarity::{Similarity, load_scene_str_placed};
pub use specular_balls::{MAX_SPECULAR_BALLS, SpecularBall};

use crate::accel::{BuildPrimitive, Bvh, Dispatched, Kernel, Leaf, LeafKind, Traversal};
use crate::color::Color;
use crate::geometry::clipped_sphere::clip_emitters;
use crate::geometry::spheres::Spheres;
use crate::geometry::triangles::{TriangleSource, Triangles, store_mesh_positions, stored_position};
use crate::geometry::{Mesh, Shape, Sphere, SurfaceHit, Triangle};
use crate::light::{Emitter, EmitterSource, Light, Lights};
use crate::material::{Material, Texture};
use crate::math::{Aabb, Ray};
use visitors::{Nearest, NearestVisitor, OcclusionVisitor};

/// The TOML text of the scene compiled into the binary.
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/cornell.toml");

/// A shape with its material.
#[derive(Clone, Debug)]
pub struct Primitive {
    /// What it is and where.
    pub shape: Shape,
    /// Index into the scene's `materials`.
    pub material: u32,
}

/// What a ray spawned on a surface cannot hit again (see [`Scene::leaving`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Leaving {
    /// The ray may hit anything, the surface it left included.
    Nothing,
    /// The ray leaves this quad (a primitive id).
    Quad(u32),
}

impl Leaving {
    /// The shape index the leaf loops skip (`u32::MAX`, no shape, for nothing).
    #[inline(always)]
    fn shape_index(self) -> u32 {
        match self {
            Leaving::Nothing => u32::MAX,
            Leaving::Quad(primitive) => primitive,
        }
    }
}

/// A hit and which primitive it belongs to.
#[derive(Clone, Copy, Debug)]
pub struct Intersection {
    /// Where the ray met the surface.
    pub hit: SurfaceHit,
    /// The primitive it belongs to (numbering as in [`Scene`]).
    pub primitive: u32,
}

/// BVH leaf kinds: the scene's triangles, its spheres (both tested four
/// at a time), and its other shapes.
const TRIANGLE_LEAF: u8 = 0;
const SHAPE_LEAF: u8 = 1;
const SPHERE_LEAF: u8 = 2;
/// Cost of one leaf of up to four spheres, in traversal steps.
const SPHERE_BLOCK_COST: f32 = 4.0;
/// Fewest spheres in one leaf for sphere leaves to pay (two are tested one
/// at a time, see `geometry::spheres`).
const MIN_SPHERES_TOGETHER: usize = 3;

/// Everything a ray can meet; immutable once built.
///
/// Primitives are numbered shapes first (in BVH leaf order; spheres last,
/// in their own leaf order, when they have leaves of their own), then
/// triangles (in leaf order too).
#[derive(Debug)]
pub struct Scene {
    shapes: Vec<Primitive>,
    /// The spheres of `shapes` (its last `spheres.len()`), as their leaves read them.
    spheres: Spheres,
    /// Index in `shapes` of the first sphere.
    first_sphere: u32,
    /// Per shape: whether its material reads texture coordinates (so its
    /// hit record needs them; see [`Material::reads_uv`]).
    shape_reads_uv: Vec<bool>,
    triangles: Triangles,
    /// The meshes triangles come from (for shading normals and uv), with
    /// positions rounded to the stored form.
    pub meshes: Vec<Mesh>,
    /// Every material; primitives refer to them by index.
    pub materials: Vec<Material>,
    /// The emissive primitives and how to choose among them.
    pub lights: Lights,
    /// Radiance of rays that leave the scene.
    pub background: Color,
    bvh: Bvh,
    /// The spheres of smooth glass and mirror (see [`specular_balls`]).
    specular_balls: Vec<SpecularBall>,
}

impl Scene {
    /// Builds the BVH over `primitives` (stored in its leaf order, triangles
    /// apart) and collects the emissive ones as lights. Mesh positions and
    /// triangle vertices are rounded to the form the BVH stores triangles
    /// in (single-precision offsets from an anchor per mesh, see
    /// `geometry::triangles`); triangles that this leaves without area are
    /// dropped, as they can never be hit.
    pub fn new(primitives: Vec<Primitive>, mut meshes: Vec<Mesh>, materials: Vec<Material>, background: Color) -> Self {
        let anchors: Vec<_> = meshes.iter_mut().map(store_mesh_positions).collect();
        let mut shapes = Vec::new();
        let mut spheres = Vec::new();
        let mut triangles: Vec<(Triangle, u32)> = Vec::new();
        for primitive in primitives {
            match primitive.shape {
                Shape::Triangle(mut triangle) => {
                    let anchor = anchors.get(triangle.mesh as usize).copied().unwrap_or_default();
                    triangle.vertices = triangle.vertices.map(|v| stored_position(anchor, v));
                    if triangle.area() > 0.0 {
                        triangles.push((triangle, primitive.material));
                    }
                }
                Shape::Sphere(_) => spheres.push(primitive),
                _ => shapes.push(primitive),
            }
        }
        // A leaf holds up to four triangles, one other shape (a box or
        // revolution test costs several box tests, which can cull it), and
        // up to four spheres tested together, a block the SAH counts as four
        // traversal steps (so it keeps apart spheres whose boxes overlap
        // little). Spheres get leaves of their own only where that puts
        // three or more together (smallpt's walls, whose boxes all hold the
        // room): elsewhere the third leaf kind costs more than it saves, so
        // the tree is built again with the spheres among the other shapes.
        // `spheres_only` builds over the spheres alone.
        let build = |sphere_leaves: bool, spheres_only: bool| {
            let sphere_kind = if sphere_leaves { SPHERE_LEAF } else { SHAPE_LEAF };
            let (triangles, shapes) = match spheres_only {
                true => (&triangles[..0], &shapes[..0]),
                false => (&triangles[..], &shapes[..]),
            };
            let build_primitives: Vec<BuildPrimitive> = triangles
                .iter()
                .map(|(triangle, _)| BuildPrimitive {
                    bounds: triangle.bounds(),
                    kind: TRIANGLE_LEAF,
                })
                .chain(shapes.iter().map(|p| BuildPrimitive {
                    bounds: p.shape.bounds(),
                    kind: SHAPE_LEAF,
                }))
                .chain(spheres.iter().map(|p| BuildPrimitive {
                    bounds: p.shape.bounds(),
                    kind: sphere_kind,
                }))
                .collect();
            let leaf_kinds = [
                LeafKind::sized(4),
                LeafKind::sized(1),
                LeafKind {
                    max_size: 4,
                    block_cost: SPHERE_BLOCK_COST,
                },
            ];
            Bvh::build_with_leaf_kinds(&build_primitives, leaf_kinds)
        };
        let together = |bvh: &Bvh| {
            bvh.leaves(SPHERE_LEAF)
                .iter()
                .any(|leaf| leaf.count as usize >= MIN_SPHERES_TOGETHER)
        };
        // Whether to try sphere leaves. Where the spheres are a minority (a
        // mesh and a few spheres), a tree of the spheres alone answers first,
        // at a cost that grows with the spheres only, so that the mesh's tree
        // is not built twice when they would not share a leaf anyway.
        let other_count = triangles.len() + shapes.len();
        let sphere_leaves =
            spheres.len() >= MIN_SPHERES_TOGETHER && (other_count <= spheres.len() || together(&build(true, true).0));
        let (mut bvh, mut orders) = build(sphere_leaves, false);
        if sphere_leaves && !together(&bvh) {
            (bvh, orders) = build(false, false);
        }
        let triangle_count = triangles.len() as u32;
        let triangles = Triangles::new(
            &triangles,
            &orders[TRIANGLE_LEAF as usize],
            &bvh.leaves(TRIANGLE_LEAF),
            anchors,
        );
        // Build indices run triangles, other shapes, spheres; the stored
        // order is other shapes, then spheres, each in its leaf order.
        let mut slots: Vec<Option<Primitive>> = shapes.into_iter().chain(spheres).map(Some).collect();
        let mut take = |kind: u8| -> Vec<Primitive> {
            orders[kind as usize]
                .iter()
                .filter_map(|&i| slots.get_mut((i - triangle_count) as usize)?.take())
                .collect()
        };
        let mut shapes = take(SHAPE_LEAF);
        let spheres = take(SPHERE_LEAF);
        let first_sphere = shapes.len() as u32;
        shapes.extend(spheres);
        let spheres = Spheres::new(
            shapes[first_sphere as usize..]
                .iter()
                .filter_map(|primitive| match &primitive.shape {
                    Shape::Sphere(sphere) => Some(sphere),
                    _ => None,
                }),
        );
        let shape_reads_uv = shapes
            .iter()
            .map(|shape| materials.get(shape.material as usize).is_some_and(Material::reads_uv))
            .collect();
        let mut scene = Self {
            shapes,
            spheres,
            first_sphere,
            shape_reads_uv,
            triangles,
            meshes,
            materials,
            lights: Lights::default(),
            background,
            bvh,
            specular_balls: Vec::new(),
        };
        let lights: Vec<Light> = (0..scene.primitive_count() as u32)
            .filter_map(|primitive| match scene.material_of(primitive) {
                Material::Emissive {
                    radiance,
                    two_sided,
                    spectrum,
                } if *radiance != Color::ZERO => Some(Light {
                    primitive,
                    radiance: *radiance,
                    spectrum: spectrum.clone(),
                    two_sided: *two_sided,
                    clipped: None,
                }),
                _ => None,
            })
            .collect();
        let lights = scene.clip_sphere_lights(lights);
        scene.lights = Lights::new(lights, &scene);
        scene.specular_balls = specular_balls::specular_balls(&scene);
        scene
    }

    /// The spheres of smooth, non-dispersive glass and of mirror of one
    /// colour, if there are at most [`specular_balls::MAX_SPECULAR_BALLS`];
    /// none otherwise.
    pub fn specular_balls(&self) -> &[SpecularBall] {
        &self.specular_balls
    }

    /// Gives each spherical light the opaque spheres whose surfaces cross
    /// its own (see `geometry::clipped_sphere`), so it samples only what a
    /// shading point might see: smallpt's light pokes through the ceiling
    /// and only a small cap of it shows in the room.
    fn clip_sphere_lights(&self, mut lights: Vec<Light>) -> Vec<Light> {
        let sphere_of = |primitive: &Primitive| match primitive.shape {
            Shape::Sphere(sphere) => Some(sphere),
            _ => None,
        };
        let spherical: Vec<(usize, Sphere)> = lights
            .iter()
            .enumerate()
            .filter_map(|(index, light)| {
                let primitive = self.shapes.get(light.primitive as usize)?;
                sphere_of(primitive).map(|sphere| (index, sphere))
            })
            .collect();
        if spherical.is_empty() {
            return lights;
        }
        let opaque: Vec<Sphere> = self
            .shapes
            .iter()
            .filter(|primitive| self.materials[primitive.material as usize].is_opaque())
            .filter_map(sphere_of)
            .collect();
        let emitters: Vec<Sphere> = spherical.iter().map(|&(_, sphere)| sphere).collect();
        for ((index, _), clipped) in spherical.iter().zip(clip_emitters(&emitters, &opaque)) {
            lights[*index].clipped = clipped.map(Box::new);
        }
        lights
    }

    /// A scene of one mesh, each triangle a primitive of one grey diffuse
    /// material, with no lights and a black background: for intersection
    /// tests and benchmarks.
    pub fn from_mesh(mesh: Mesh) -> Self {
        let primitives: Vec<Primitive> = mesh
            .triangles(0)
            .map(|t| Primitive {
                shape: Shape::Triangle(t),
                material: 0,
            })
            .collect();
        let materials = vec![Material::Diffuse {
            albedo: Texture::Constant(Color::splat(0.5)),
        }];
        Self::new(primitives, vec![mesh], materials, Color::ZERO)
    }

    /// Bounds of everything in the scene (rounded outward to `f32`).
    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    /// Shapes plus triangles.
    pub fn primitive_count(&self) -> usize {
        self.shapes.len() + self.triangles.len()
    }

    /// The scene's triangles, in leaf order.
    pub fn triangles(&self) -> &Triangles {
        &self.triangles
    }

    /// Index into `materials` of a primitive's material.
    pub fn material_index(&self, primitive: u32) -> u32 {
        match self.triangle_index(primitive) {
            Some(triangle) => self.triangles.source(triangle).material,
            None => self.shapes[primitive as usize].material,
        }
    }

    /// Whether any material's scattering depends on wavelength (dispersive
    /// glass): such a scene is rendered spectrally.
    pub fn has_dispersion(&self) -> bool {
        self.materials.iter().any(Material::is_dispersive)
    }

    /// The material of primitive `primitive`.
    pub fn material_of(&self, primitive: u32) -> &Material {
        &self.materials[self.material_index(primitive) as usize]
    }

    /// Bounds of one primitive.
    pub fn primitive_bounds(&self, primitive: u32) -> Aabb {
        match self.triangle_index(primitive) {
            Some(triangle) => self.triangles.get(triangle).bounds(),
            None => self.shapes[primitive as usize].shape.bounds(),
        }
    }

    /// The sphere itself if a primitive is one (centre, radius); `None` for
    /// every other kind.
    pub fn primitive_sphere(&self, primitive: u32) -> Option<(glam::DVec3, f64)> {
        match self.triangle_index(primitive) {
            Some(_) => None,
            None => match &self.shapes[primitive as usize].shape {
                Shape::Sphere(sphere) => Some((sphere.center, sphere.radius)),
                _ => None,
            },
        }
    }

    /// Which mesh face (and material) a triangle primitive is; `None` for shapes.
    pub fn triangle_source(&self, primitive: u32) -> Option<TriangleSource> {
        self.triangle_index(primitive).map(|triangle| self.triangles.source(triangle))
    }

    /// The position of a triangle primitive among the triangles.
    fn triangle_index(&self, primitive: u32) -> Option<u32> {
        primitive.checked_sub(self.shapes.len() as u32)
    }

    /// What a ray spawned on `primitive` may skip: the primitive itself if
    /// it is a quad, which a ray leaving it cannot meet again (it is flat,
    /// and the spawned origin lies off its plane on the side the ray leaves
    /// by), else [`Leaving::Nothing`]. The same holds for a shadow ray
    /// aimed at a point on a quad light, stopping short of it
    /// ([`Scene::occluded_between`]). A ray leaving a wall enters the
    /// wall's own box first (the conservative `f32` box test brackets the
    /// origin to within an `f32` ulp, far more than its offset from the
    /// wall), so without this every bounce off a quad tests that quad
    /// again, and the rejection is a mispredicted branch.
    pub fn leaving(&self, primitive: u32) -> Leaving {
        match self.shapes.get(primitive as usize) {
            Some(Primitive {
                shape: Shape::Quad(_), ..
            }) => Leaving::Quad(primitive),
            _ => Leaving::Nothing,
        }
    }

    /// Nearest hit in `(0, t_max)`. Triangles report only distance and
    /// barycentrics during traversal, other shapes what their test found
    /// ([`crate::geometry::ShapeHit`]); the hit record (normals, uv, error bounds) is built
    /// once, for the final hit, from those results.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<Intersection> {
        self.intersect_skipping::<false>(Dispatched, ray, t_max, u32::MAX)
    }

    /// [`Scene::intersect`] for a ray spawned on a surface, which skips
    /// what [`Scene::leaving`] says it cannot hit again.
    #[inline]
    pub fn intersect_leaving(&self, ray: &Ray, t_max: f64, leaving: Leaving) -> Option<Intersection> {
        self.intersect_skipping::<true>(Dispatched, ray, t_max, leaving.shape_index())
    }

    /// [`Scene::intersect_leaving`] compiled into its caller. The hit record
    /// then reaches the caller's code without a return through memory. That
    /// pays in a path tracer whose loop is small (scenes without specular
    /// balls), not in the larger loop with the balls' connections
    /// (docs/performance.md, "The traversal inlined into the path loop").
    /// `traversal`: [`crate::accel::Portable`], or [`crate::accel::Avx2`] in
    /// a loop compiled for AVX2 ([`crate::accel::Avx2::run`]).
    #[inline(always)]
    pub fn intersect_leaving_inlined(
        &self,
        traversal: impl Traversal,
        ray: &Ray,
        t_max: f64,
        leaving: Leaving,
    ) -> Option<Intersection> {
        self.intersect_skipping::<true>(traversal, ray, t_max, leaving.shape_index())
    }

    /// The nearest hit, skipping shape `skipped` when `SKIP` (compiled
    /// twice, so rays that skip nothing pay no comparison per shape).
    #[inline(always)]
    fn intersect_skipping<const SKIP: bool>(
        &self,
        traversal: impl Traversal,
        ray: &Ray,
        t_max: f64,
        skipped: u32,
    ) -> Option<Intersection> {
        let (nearest, _) = self.nearest::<SKIP>(traversal, ray, t_max, skipped);
        self.hit_record(ray, nearest)
    }

    /// The nearest hit's distance along the ray and its primitive, in
    /// `(0, t_max)`, without the hit record: for queries that need only
    /// where the ray stops (the viewer's depth under the pointer). It is
    /// the work of a ray-tracing kernel's closest-hit query, such as
    /// Embree's `rtcIntersect1` (whose distance, barycentrics and primitive
    /// the leaf tests find here too; Embree also returns an unnormalised
    /// geometric normal), so that `prism bench --rays` can time the same
    /// work as Embree's.
    #[inline]
    pub fn nearest_distance(&self, ray: &Ray, t_max: f64) -> Option<(f64, u32)> {
        let (nearest, t) = self.nearest::<false>(Dispatched, ray, t_max, u32::MAX);
        match nearest {
            Nearest::Nothing => None,
            Nearest::Triangle(found) => Some((t, self.shapes.len() as u32 + found.index)),
            Nearest::Shape(index, _) => Some((t, index)),
            Nearest::Record(found) => Some((t, found.primitive)),
        }
    }

    /// What the traversal found nearest, and its distance (each leaf test
    /// lowers the bound to the nearest hit it finds, so the final bound is
    /// the distance when something was found).
    #[inline(always)]
    fn nearest<const SKIP: bool>(&self, traversal: impl Traversal, ray: &Ray, t_max: f64, skipped: u32) -> (Nearest, f64) {
        let mut visitor = NearestVisitor::<SKIP> {
            scene: self,
            ray,
            skipped,
            triangle_ray: None,
            nearest: Nearest::Nothing,
        };
        let mut t = t_max;
        traversal.nearest(&self.bvh, ray, &mut t, &mut visitor);
        (visitor.nearest, t)
    }

    /// The hit record of what a nearest-hit query found.
    #[inline(always)]
    fn hit_record(&self, ray: &Ray, nearest: Nearest) -> Option<Intersection> {
        match nearest {
            Nearest::Nothing => None,
            Nearest::Triangle(found) => {
                let triangle = self.triangles.get(found.index);
                let mesh = &self.meshes[triangle.mesh as usize];
                Some(Intersection {
                    hit: triangle.surface_hit(&found.hit, mesh),
                    primitive: self.shapes.len() as u32 + found.index,
                })
            }
            Nearest::Shape(index, found) => {
                let with_uv = self.shape_reads_uv[index as usize];
                let hit = self.shapes[index as usize]
                    .shape
                    .surface_hit(ray, found, &self.meshes, with_uv)?;
                Some(Intersection { hit, primitive: index })
            }
            Nearest::Record(found) => Some(found),
        }
    }

    /// Whether anything lies on the ray before `t_max` (shadow rays); stops
    /// at the first hit found.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f64) -> bool {
        self.occluded_skipping::<false>(Dispatched, ray, t_max, u32::MAX, u32::MAX)
    }

    /// [`Scene::occluded`] for a shadow ray from one surface to a point on
    /// another (a light), which skips what [`Scene::leaving`] says of each:
    /// the ray cannot hit the quad it leaves, nor, before `t_max`, the quad
    /// it is aimed at (a segment meets a plane once, and it ends there).
    #[inline]
    pub fn occluded_between(&self, ray: &Ray, t_max: f64, from: Leaving, to: Leaving) -> bool {
        self.occluded_skipping::<true>(Dispatched, ray, t_max, from.shape_index(), to.shape_index())
    }

    /// [`Scene::occluded_between`] compiled into its caller, as
    /// [`Scene::intersect_leaving_inlined`] is and for the same loop: the
    /// shadow ray reaches the traversal in registers, not through memory.
    #[inline(always)]
    pub fn occluded_between_inlined(&self, traversal: impl Traversal, ray: &Ray, t_max: f64, from: Leaving, to: Leaving) -> bool {
        self.occluded_skipping::<true>(traversal, ray, t_max, from.shape_index(), to.shape_index())
    }

    /// Whether anything but shapes `skipped` and `target` (when `SKIP`)
    /// lies on the ray before `t_max`.
    #[inline(always)]
    fn occluded_skipping<const SKIP: bool>(
        &self,
        traversal: impl Traversal,
        ray: &Ray,
        t_max: f64,
        skipped: u32,
        target: u32,
    ) -> bool {
        let mut visitor = OcclusionVisitor::<SKIP> {
            scene: self,
            ray,
            skipped: (skipped, target),
            triangle_ray: None,
            found: false,
        };
        let mut t = t_max;
        traversal.any(&self.bvh, ray, &mut t, &mut visitor);
        visitor.found
    }

    /// Starts loading the primitives of a leaf the traversal deferred (in
    /// a tree larger than the caches): a triangle leaf's vertex block. The
    /// other kinds belong to small scenes, whose data stays cached.
    #[inline(always)]
    fn prefetch_leaf(&self, leaf: Leaf) {
        if leaf.kind == TRIANGLE_LEAF {
            self.triangles.prefetch_leaf(leaf.first);
        }
    }

    /// The acceleration structure, for statistics and benchmarks.
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// Runs this scene's ray queries (and the path tracer's loop, which
    /// follows the BVH's choice) with `kernel` where the CPU has it: to
    /// compare the kernels, which must give the same answers.
    pub fn set_kernel(&mut self, kernel: Kernel) {
        self.bvh.set_kernel(kernel);
    }

    /// Bytes of the BVH nodes plus the triangles' leaf data.
    pub fn acceleration_bytes(&self) -> usize {
        self.bvh.memory_bytes() + self.triangles.len() * Triangles::BYTES_PER_TRIANGLE
    }
}

impl EmitterSource for Scene {
    fn emitter(&self, primitive: u32) -> Emitter<'_> {
        match self.triangle_index(primitive) {
            Some(triangle) => Emitter::Triangle(self.triangles.get(triangle)),
            None => Emitter::Shape(&self.shapes[primitive as usize].shape),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A floor of `side`² × 2 small triangles around the origin, then `spheres`.
    fn floor_and_spheres(side: usize, spheres: &[Sphere]) -> Scene {
        let mut primitives = Vec::new();
        for i in 0..side {
            for j in 0..side {
                let corner = |di: usize, dj: usize| DVec3::new((i + di) as f64, 0.0, (j + dj) as f64);
                for (face, vertices) in [
                    [corner(0, 0), corner(1, 0), corner(1, 1)],
                    [corner(0, 0), corner(1, 1), corner(0, 1)],
                ]
                .into_iter()
                .enumerate()
                {
                    let triangle = Triangle {
                        vertices,
                        mesh: 0,
                        face: face as u32,
                    };
                    primitives.push(Primitive {
                        shape: Shape::Triangle(triangle),
                        material: 0,
                    });
                }
            }
        }
        primitives.extend(spheres.iter().map(|&sphere| Primitive {
            shape: Shape::Sphere(sphere),
            material: 0,
        }));
        let materials = vec![Material::Diffuse {
            albedo: Texture::Constant(Color::splat(0.5)),
        }];
        Scene::new(primitives, Vec::new(), materials, Color::ZERO)
    }

    /// Spheres among many triangles get leaves of their own where three or
    /// more share one (walls of radius 10⁵ whose boxes all hold the floor,
    /// as in smallpt), and not where none would (three small spheres far
    /// apart, which the tree of the spheres alone already keeps apart).
    #[test]
    fn spheres_among_triangles_share_leaves_only_where_three_overlap() {
        // A room 32 wide around the floor, walled by spheres as in smallpt.
        let wall = |axis: usize, side: f64| {
            let mut center = DVec3::splat(15.0);
            center[axis] = 15.0 + side * (1e5 + 16.0);
            Sphere { center, radius: 1e5 }
        };
        let walls = [0, 1, 2].map(|axis| [wall(axis, -1.0), wall(axis, 1.0)]).concat();
        let scene = floor_and_spheres(4, &walls);
        assert!(scene.triangles.len() > walls.len());
        let leaves = scene.bvh.leaves(SPHERE_LEAF);
        assert_eq!(leaves.iter().map(|leaf| leaf.count).sum::<u32>(), 6, "{leaves:?}");

        let apart = [-20.0, 5.0, 30.0].map(|x| Sphere {
            center: DVec3::new(x, 3.0, x),
            radius: 0.5,
        });
        let scene = floor_and_spheres(30, &apart);
        assert!(scene.bvh.leaves(SPHERE_LEAF).is_empty());
        assert_eq!(scene.bvh.leaves(SHAPE_LEAF).len(), 3);

        // Either way the spheres are found where they are.
        let ray = Ray::new(DVec3::new(5.0, 10.0, 5.0), DVec3::NEG_Y);
        let hit = scene.intersect(&ray, f64::INFINITY).map(|found| found.hit.t);
        assert_eq!(hit, Some(6.5));
    }
}
