//! The denoiser's guide buffers: what the camera sees first through each
//! pixel (its albedo and its normal), from one primary ray per pixel through
//! the pixel's centre and the lens centre. A pass of its own, so the path
//! tracer stays as it is; it costs about one bounce of one sample per pixel.
//!
//! Edges in these buffers are edges of the scene (a wall meeting the floor,
//! a texture's pattern), not of noise, so the filter may stop at them.

use super::atrous::{GuidePlanes, Plane};
use crate::camera::Camera;
use crate::geometry::SurfaceHit;
use crate::material::{Material, ShadingPoint};
use crate::scene::Scene;
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use std::sync::OnceLock;

/// First-hit albedo and normal per pixel, row-major.
#[derive(Clone, Debug, Default)]
pub struct Guides {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Reflectance of the first surface hit; zero where the ray escapes or
    /// meets a light (nothing to demodulate there).
    pub albedo: Vec<[f32; 3]>,
    /// Unit shading normal of the first hit, turned towards the camera; zero
    /// where the ray escapes.
    pub normal: Vec<[f32; 3]>,
    /// The filter's padded copies, made on first use.
    planes: OnceLock<GuidePlanes>,
}

impl Guides {
    /// Guides from per-pixel albedo and normal (row-major, `width` × `height` each).
    pub fn new(width: u32, height: u32, albedo: Vec<[f32; 3]>, normal: Vec<[f32; 3]>) -> Self {
        Self {
            width,
            height,
            albedo,
            normal,
            planes: OnceLock::new(),
        }
    }

    /// The guides as the filter reads them (made once, then shared).
    pub(super) fn planes(&self) -> &GuidePlanes {
        self.planes.get_or_init(|| {
            let (width, height) = (self.width as usize, self.height as usize);
            let plane = |values: &[[f32; 3]], c: usize| Plane::from_fn(width, height, |i| values[i][c]);
            GuidePlanes {
                normal: [0, 1, 2].map(|c| plane(&self.normal, c)),
            }
        })
    }

    /// One primary ray per pixel (through its centre; lens centre, so the
    /// guides are sharp even with depth of field) on the current rayon pool.
    pub fn first_hit(scene: &Scene, camera: &Camera, width: u32, height: u32) -> Self {
        let (width, height) = (width.max(1), height.max(1));
        let aspect = width as f64 / height as f64;
        let texels: Vec<([f32; 3], [f32; 3])> = (0..width as usize * height as usize)
            .into_par_iter()
            .with_min_len(256)
            .map(|index| {
                let (x, y) = (index as u32 % width, index as u32 / width);
                let film = DVec2::new((x as f64 + 0.5) / width as f64, (y as f64 + 0.5) / height as f64);
                let ray = camera.generate_ray(film, aspect, DVec2::splat(0.5));
                match scene.intersect(&ray, f64::INFINITY) {
                    Some(hit) => {
                        let albedo = albedo(scene.material_of(hit.primitive), &hit.hit);
                        let normal = facing(hit.hit.shading_normal, ray.direction);
                        (to_f32(albedo), to_f32(normal))
                    }
                    None => ([0.0; 3], [0.0; 3]),
                }
            })
            .collect();
        let (albedo, normal) = texels.into_iter().unzip();
        Self::new(width, height, albedo, normal)
    }
}

/// The colour a surface reflects at a hit: the diffuse albedo or the
/// specular tint; zero for lights, which reflect nothing.
fn albedo(material: &Material, hit: &SurfaceHit) -> DVec3 {
    let at = ShadingPoint {
        uv: hit.uv,
        point: hit.point,
    };
    match material {
        Material::Diffuse { albedo } => albedo.evaluate(&at),
        Material::Glossy { tint, .. } | Material::Mirror { tint } => tint.evaluate(&at),
        Material::Glass { tint, .. } => *tint,
        Material::Emissive { .. } => DVec3::ZERO,
    }
}

/// The normal on the side the ray came from, so two-sided surfaces agree.
fn facing(normal: DVec3, direction: DVec3) -> DVec3 {
    if normal.dot(direction) > 0.0 { -normal } else { normal }
}

fn to_f32(v: DVec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{DEFAULT_SCENE, load_scene_str};
    use std::path::Path;

    #[test]
    fn the_cornell_box_guides_see_its_walls_and_light() {
        let loaded = load_scene_str(DEFAULT_SCENE, Path::new("cornell"), Path::new(".")).expect("default scene");
        let guides = Guides::first_hit(&loaded.scene, &loaded.camera, 32, 32);
        assert_eq!(guides.albedo.len(), 32 * 32);
        // Every normal is unit length or zero (escaped), and faces the camera.
        for n in &guides.normal {
            let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            assert!(length == 0.0 || (length - 1.0).abs() < 1e-4, "{n:?}");
        }
        // The left wall is red and the right wall green (cornell.toml): the
        // left edge's middle pixel reflects more red than green, the right's the opposite.
        let left = guides.albedo[16 * 32];
        let right = guides.albedo[16 * 32 + 31];
        assert!(left[0] > 2.0 * left[1], "left wall {left:?}");
        assert!(right[1] > 2.0 * right[0], "right wall {right:?}");
    }
}
