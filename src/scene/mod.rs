//! Scenes: the scene file parsed into a spanned TOML document (`document`),
//! read as plain data (`description`), then checked and turned into a frozen,
//! render-ready `Scene` (`load`) whose acceleration structure is built once
//! and shared read-only. Every error names file, line, column and field
//! (`error`).

pub mod description;
pub mod document;
pub mod error;
pub mod load;

pub use error::{Location, SceneError};
pub use load::{COORDINATE_LIMIT, LoadedScene, load_scene_bytes, load_scene_file, load_scene_str};

use crate::accel::Bvh;
use crate::color::Color;
use crate::geometry::{Mesh, Shape, SurfaceHit};
use crate::light::{AsShape, Light, Lights};
use crate::material::Material;
use crate::math::{Aabb, Ray};

/// The TOML text of the scene compiled into the binary.
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/cornell.toml");

/// A shape with its material.
#[derive(Clone, Debug)]
pub struct Primitive {
    pub shape: Shape,
    pub material: u32,
}

impl AsShape for Primitive {
    fn shape(&self) -> &Shape {
        &self.shape
    }
}

/// A hit and which primitive it belongs to.
#[derive(Clone, Copy, Debug)]
pub struct Intersection {
    pub hit: SurfaceHit,
    pub primitive: u32,
}

/// Everything a ray can meet; immutable once built.
#[derive(Debug)]
pub struct Scene {
    pub primitives: Vec<Primitive>,
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    pub lights: Lights,
    /// Radiance of rays that leave the scene.
    pub background: Color,
    bvh: Bvh,
}

impl Scene {
    /// Builds the BVH over `primitives` (reordered to match it) and collects
    /// the emissive ones as lights.
    pub fn new(primitives: Vec<Primitive>, meshes: Vec<Mesh>, materials: Vec<Material>, background: Color) -> Self {
        let bounds: Vec<Aabb> = primitives.iter().map(|p| p.shape.bounds()).collect();
        let (bvh, order) = Bvh::build(&bounds);
        let mut slots: Vec<Option<Primitive>> = primitives.into_iter().map(Some).collect();
        let primitives: Vec<Primitive> = order.iter().filter_map(|&i| slots[i as usize].take()).collect();
        let lights = primitives
            .iter()
            .enumerate()
            .filter_map(|(i, p)| match &materials[p.material as usize] {
                Material::Emissive { radiance, two_sided } if *radiance != Color::ZERO => Some(Light {
                    primitive: i as u32,
                    radiance: *radiance,
                    two_sided: *two_sided,
                }),
                _ => None,
            })
            .collect();
        let lights = Lights::new(lights, &primitives);
        Self {
            primitives,
            meshes,
            materials,
            lights,
            background,
            bvh,
        }
    }

    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    pub fn material_of(&self, primitive: u32) -> &Material {
        &self.materials[self.primitives[primitive as usize].material as usize]
    }

    /// Nearest hit in `(0, t_max)`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<Intersection> {
        let mut best: Option<Intersection> = None;
        self.bvh.intersect(ray, t_max, |index, t_max| {
            let hit = self.primitives[index].shape.intersect(ray, t_max, &self.meshes)?;
            best = Some(Intersection {
                hit,
                primitive: index as u32,
            });
            Some(hit.t)
        });
        best
    }

    /// Whether anything lies on the ray before `t_max` (shadow rays).
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f64) -> bool {
        self.bvh.occluded(ray, t_max, |index, t_max| {
            self.primitives[index].shape.hit_distance(ray, t_max).is_some()
        })
    }

    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }
}
