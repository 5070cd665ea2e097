//! The leaf tests of the scene's two ray queries, as the BVH's traversal
//! calls them ([`LeafVisitor`]): the nearest hit, which records the nearest
//! candidate and builds its hit record only after the traversal, and
//! occlusion, which stops at the first hit. Their methods are always
//! inlined, so each compiled copy of the traversal (baseline x86-64, AVX2:
//! `accel::kernel`) carries its own copy of the tests.

use super::{Intersection, SPHERE_LEAF, Scene, TRIANGLE_LEAF};
use crate::accel::{Avx2, Leaf, LeafVisitor};
use crate::geometry::triangle::TriangleRay;
use crate::geometry::triangles::LeafHit;
use crate::geometry::{Shape, ShapeHit};
use crate::math::Ray;

/// The nearest hit so far. Candidates are compared by distance
/// alone; the hit record (normal, uv, error bounds) is built once,
/// for the nearest, except for surfaces of revolution, whose root
/// finding depends on the bound and so keeps the record it found.
pub(super) enum Nearest {
    Nothing,
    Triangle(LeafHit),
    Shape(u32, ShapeHit),
    Record(Intersection),
}

/// The nearest-hit query's leaf test: lowers `t_max` and records each
/// nearer hit; shape `skipped` is passed over when `SKIP`.
pub(super) struct NearestVisitor<'a, const SKIP: bool> {
    pub(super) scene: &'a Scene,
    pub(super) ray: &'a Ray,
    pub(super) skipped: u32,
    /// The triangle test's per-ray constants, made when a triangle leaf is first reached.
    pub(super) triangle_ray: Option<TriangleRay>,
    pub(super) nearest: Nearest,
}

impl<const SKIP: bool> LeafVisitor for NearestVisitor<'_, SKIP> {
    #[inline(always)]
    fn visit(&mut self, leaf: Leaf, t_max: &mut f64, avx2: Option<Avx2>) -> bool {
        if leaf.kind == TRIANGLE_LEAF {
            let triangle_ray = self.triangle_ray.get_or_insert_with(|| TriangleRay::new(self.ray));
            if let Some(found) = self
                .scene
                .triangles
                .intersect_leaf(avx2, triangle_ray, leaf.first, leaf.count, *t_max)
            {
                *t_max = found.hit.t;
                self.nearest = Nearest::Triangle(found);
            }
        } else if leaf.kind == SPHERE_LEAF {
            if let Some(found) = self
                .scene
                .spheres
                .intersect_leaf(avx2, self.ray, leaf.first, leaf.count, *t_max)
            {
                *t_max = found.t;
                self.nearest = Nearest::Shape(self.scene.first_sphere + found.index, ShapeHit::Sphere(found.t));
            }
        } else {
            for index in leaf.first..leaf.first + leaf.count {
                if SKIP && index == self.skipped {
                    continue;
                }
                let shape = &self.scene.shapes[index as usize].shape;
                if let Shape::Revolution(revolution) = shape {
                    if let Some(hit) = revolution.intersect(self.ray, *t_max) {
                        *t_max = hit.t;
                        self.nearest = Nearest::Record(Intersection { hit, primitive: index });
                    }
                } else if let Some(hit) = shape.nearest_hit(self.ray, *t_max) {
                    *t_max = hit.t();
                    self.nearest = Nearest::Shape(index, hit);
                }
            }
        }
        false
    }

    #[inline(always)]
    fn prefetch(&self, leaf: Leaf) {
        self.scene.prefetch_leaf(leaf);
    }
}

/// The any-hit query's leaf test: whether anything in a leaf but shapes
/// `skipped` (when `SKIP`) lies on the ray before `t_max`.
pub(super) struct OcclusionVisitor<'a, const SKIP: bool> {
    pub(super) scene: &'a Scene,
    pub(super) ray: &'a Ray,
    pub(super) skipped: (u32, u32),
    pub(super) triangle_ray: Option<TriangleRay>,
    pub(super) found: bool,
}

impl<const SKIP: bool> LeafVisitor for OcclusionVisitor<'_, SKIP> {
    #[inline(always)]
    fn visit(&mut self, leaf: Leaf, t_max: &mut f64, avx2: Option<Avx2>) -> bool {
        self.found = if leaf.kind == TRIANGLE_LEAF {
            let triangle_ray = self.triangle_ray.get_or_insert_with(|| TriangleRay::new(self.ray));
            self.scene
                .triangles
                .occludes_leaf(avx2, triangle_ray, leaf.first, leaf.count, *t_max)
        } else if leaf.kind == SPHERE_LEAF {
            self.scene
                .spheres
                .occludes_leaf(avx2, self.ray, leaf.first, leaf.count, *t_max)
        } else {
            // A plain loop, not `any`: its closure stayed out of line.
            let mut found = false;
            for index in leaf.first..leaf.first + leaf.count {
                if !(SKIP && (index == self.skipped.0 || index == self.skipped.1))
                    && self.scene.shapes[index as usize]
                        .shape
                        .hit_distance(self.ray, *t_max)
                        .is_some()
                {
                    found = true;
                    break;
                }
            }
            found
        };
        self.found
    }

    #[inline(always)]
    fn prefetch(&self, leaf: Leaf) {
        self.scene.prefetch_leaf(leaf);
    }
}
