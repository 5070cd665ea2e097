//! A similarity `p ↦ s p + t` (uniform scale `s > 0`, then translation `t`)
//! applied to a whole scene description, so one scene file yields the same
//! scene at any size and position: the numerical stress test renders its
//! scenes shrunk, grown and moved far from the origin this way.
//!
//! Every point moves (`s p + t`), every vector and length scales (`s v`),
//! directions and angles stay: object positions, edges and radii; object
//! transforms, composed as `S ∘ T` (translation `s t_T + t`, scale `s k_T`,
//! the same rotation, since a uniform scale commutes with it); the camera's
//! position, target, aperture, focal distance and near clip; SPPM's initial
//! radius; and textures placed in world space (sphere-mapping centres,
//! planar-mapping parallelograms, gradient ranges, which shift by the
//! translation's component along the unit axis). Rendered images are the
//! same up to rounding: radiance does not depend on scale.

use super::description::{
    CameraDescription, ColorDescription, MaterialDescription, ObjectDescription, Scale, SceneDescription, TextureDescription,
    TransformDescription, Vector,
};
use super::error::SceneError;
use super::load::{LoadedScene, load_scene_str_edited};
use crate::settings::SettingsPatch;
use glam::DVec3;
use std::path::Path;

/// A uniform scale followed by a translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Similarity {
    scale: f64,
    translation: DVec3,
}

impl Similarity {
    /// The map that changes nothing.
    pub const IDENTITY: Similarity = Similarity {
        scale: 1.0,
        translation: DVec3::ZERO,
    };

    /// `p ↦ scale · p + translation`; `None` unless `scale` is positive and
    /// both are finite (a negative scale would mirror the scene and turn
    /// one-sided lights away from what they lit).
    pub fn new(scale: f64, translation: DVec3) -> Option<Self> {
        (scale.is_finite() && scale > 0.0 && translation.is_finite()).then_some(Self { scale, translation })
    }

    /// The uniform scale factor.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The translation, applied after the scale.
    pub fn translation(&self) -> DVec3 {
        self.translation
    }

    /// A point: `s p + t`.
    pub fn point(&self, p: Vector) -> Vector {
        (self.translation + self.scale * DVec3::from_array(p)).to_array()
    }

    /// A displacement (edge, offset): `s v`.
    pub fn vector(&self, v: Vector) -> Vector {
        (self.scale * DVec3::from_array(v)).to_array()
    }

    /// A length (radius, distance): `s l`.
    pub fn length(&self, length: f64) -> f64 {
        self.scale * length
    }

    /// Moves everything in `description` that has a position or a size.
    pub fn apply(&self, description: &mut SceneDescription) {
        self.apply_to_camera(&mut description.camera);
        self.apply_to_render(&mut description.render);
        for material in description.materials.values_mut() {
            self.apply_to_material(material);
        }
        for object in &mut description.objects {
            self.apply_to_object(object);
        }
    }

    fn apply_to_camera(&self, camera: &mut CameraDescription) {
        camera.position = self.point(camera.position);
        camera.look_at = self.point(camera.look_at);
        camera.aperture_radius = self.length(camera.aperture_radius);
        camera.focal_distance = camera.focal_distance.map(|d| self.length(d));
        camera.near_clip = self.length(camera.near_clip);
    }

    fn apply_to_render(&self, render: &mut SettingsPatch) {
        render.initial_radius = render.initial_radius.map(|r| self.length(r));
    }

    fn apply_to_material(&self, material: &mut MaterialDescription) {
        match material {
            MaterialDescription::Diffuse { albedo: color }
            | MaterialDescription::Mirror { tint: color }
            | MaterialDescription::Glossy { tint: color, .. } => self.apply_to_color(color),
            MaterialDescription::Glass { .. } | MaterialDescription::Emissive { .. } => {}
        }
    }

    fn apply_to_color(&self, color: &mut ColorDescription) {
        if let ColorDescription::Texture(texture) = color {
            self.apply_to_texture(texture);
        }
    }

    /// World-space texture placements; keys left out stay out, so the
    /// loader's defaults and its checks of which keys go together still apply.
    fn apply_to_texture(&self, texture: &mut TextureDescription) {
        texture.center = texture.center.map(|c| self.point(c));
        texture.origin = texture.origin.map(|o| self.point(o));
        texture.edge_u = texture.edge_u.map(|e| self.vector(e));
        texture.edge_v = texture.edge_v.map(|e| self.vector(e));
        if texture.gradient.is_some() {
            // The ramp reads p·â: (s p + t)·â = s (p·â) + t·â. The loader's
            // defaults are axis +y, from 0, to 1.
            let axis = DVec3::from_array(texture.axis.unwrap_or([0.0, 1.0, 0.0])).normalize_or_zero();
            let shift = self.translation.dot(axis);
            texture.from = Some(self.length(texture.from.unwrap_or(0.0)) + shift);
            texture.to = Some(self.length(texture.to.unwrap_or(1.0)) + shift);
        }
    }

    fn apply_to_object(&self, object: &mut ObjectDescription) {
        match object {
            ObjectDescription::Sphere { center, radius, .. } => {
                *center = self.point(*center);
                *radius = self.length(*radius);
            }
            ObjectDescription::Box { min, max, .. } => {
                *min = self.point(*min);
                *max = self.point(*max);
            }
            ObjectDescription::Quad {
                corner, edge_u, edge_v, ..
            } => {
                *corner = self.point(*corner);
                *edge_u = self.vector(*edge_u);
                *edge_v = self.vector(*edge_v);
            }
            ObjectDescription::Triangle { vertices, .. } => {
                *vertices = vertices.map(|v| self.point(v));
            }
            ObjectDescription::Mesh { transform, .. } | ObjectDescription::Revolution { transform, .. } => {
                self.apply_to_transform(transform);
            }
        }
    }

    /// `S ∘ T` for `T = translate ∘ rotate ∘ scale`.
    fn apply_to_transform(&self, transform: &mut TransformDescription) {
        transform.translate = Some(self.point(transform.translate.unwrap_or([0.0; 3])));
        transform.scale = Some(match transform.scale {
            None => Scale::Uniform(self.scale),
            Some(Scale::Uniform(k)) => Scale::Uniform(self.length(k)),
            Some(Scale::PerAxis(k)) => Scale::PerAxis(self.vector(k)),
        });
    }
}

/// Loads a scene from TOML text placed by `similarity`; `file` names it in
/// errors (which point at the lines of the unplaced text), `base` resolves
/// paths.
pub fn load_scene_str_placed(text: &str, file: &Path, base: &Path, similarity: &Similarity) -> Result<LoadedScene, SceneError> {
    load_scene_str_edited(text, file, base, |description| similarity.apply(description))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{Material, ShadingPoint};
    use crate::scene::load_scene_str;
    use glam::DVec2;

    /// One object of every kind, with world-space textures of every kind
    /// and every camera length set.
    const SCENE: &str = r#"
[camera]
position = [0, 2, 9]
look_at = [0, 1, 0]
fov_y_degrees = 50
aperture_radius = 0.05
focal_distance = 8
near_clip = 0.5

[render]
initial_radius = 0.2

[materials.ramp]
type = "diffuse"
albedo = { gradient = [[0.1, 0.2, 0.3], [0.9, 0.8, 0.7]], axis = [1, 2, 0], from = -1, to = 2 }
[materials.tiles]
type = "diffuse"
albedo = { checker = [[0.2, 0.2, 0.2], [0.8, 0.8, 0.8]], mapping = "planar", origin = [-4, 0, -4], edge_u = [8, 0, 0], edge_v = [0, 0, 8], scale = 4 }
[materials.globe]
type = "glossy"
tint = { checker = [[0.3, 0.1, 0.1], [0.1, 0.3, 0.1]], mapping = "sphere", center = [2, 1, 0], scale = 8 }
roughness = 0.3

[[objects]]
type = "quad"
corner = [-20, 0, -20]
edge_u = [0, 0, 40]
edge_v = [40, 0, 0]
material = "tiles"
[[objects]]
type = "quad"
corner = [-20, 0, -6]
edge_u = [40, 0, 0]
edge_v = [0, 20, 0]
material = "ramp"
[[objects]]
type = "sphere"
center = [-2, 1, 0]
radius = 1
material = "ramp"
[[objects]]
type = "box"
min = [1.2, 0, -0.8]
max = [2.8, 1.6, 0.8]
material = "globe"
[[objects]]
type = "triangle"
vertices = [[-3, 0, -3], [3, 0, -3], [0, 3, -3]]
material = "ramp"
[[objects]]
type = "revolution"
profile = [[0.0, 0.0], [1.2, 0.1], [0.3, 0.9], [0.9, 1.4], [0.5, 2.0]]
material = "ramp"
transform = { translate = [0, 0, 2], rotate_degrees = [10, 0, 5], scale = 0.8 }
"#;

    fn albedo(material: &Material, at: &ShadingPoint) -> DVec3 {
        match material {
            Material::Diffuse { albedo } => albedo.evaluate(at),
            Material::Glossy { tint, .. } => tint.evaluate(at),
            other => panic!("unexpected material {other:?}"),
        }
    }

    #[test]
    fn rejects_mirrors_collapses_and_non_finite_maps() {
        assert!(Similarity::new(0.0, DVec3::ZERO).is_none());
        assert!(Similarity::new(-1.0, DVec3::ZERO).is_none());
        assert!(Similarity::new(f64::NAN, DVec3::ZERO).is_none());
        assert!(Similarity::new(1.0, DVec3::new(0.0, f64::INFINITY, 0.0)).is_none());
        assert_eq!(Similarity::new(1.0, DVec3::ZERO), Some(Similarity::IDENTITY));
    }

    /// The same camera rays (film and lens points) in the original and the
    /// placed scene must meet the same material at `s` times the distance,
    /// with the same normal and the same texture colour. Tolerance: the
    /// placed scene lies 1e3 from the origin at size ≈ 1e-2, so its
    /// coordinates round at ≈ 1e3 · 2⁻⁵³ ≈ 1e-13, 1e-11 of its size; 1e-8
    /// relative leaves three orders of magnitude for the error bounds of
    /// hits, while a wrongly placed object or camera length is off by O(1).
    #[test]
    fn placed_scenes_meet_the_same_surfaces_at_scaled_distances() {
        let original = load_scene_str(SCENE, Path::new("similarity.toml"), Path::new(".")).expect("test scene loads");
        let similarity = Similarity::new(1e-3, DVec3::new(1234.5678, -2345.678, 5.4321)).expect("valid");
        let placed =
            load_scene_str_placed(SCENE, Path::new("similarity.toml"), Path::new("."), &similarity).expect("placed scene loads");
        assert_eq!(placed.settings.sppm.initial_radius, Some(0.2 * 1e-3));
        let mut hits = 0;
        for i in 0..24 {
            for j in 0..24 {
                let film = DVec2::new((i as f64 + 0.5) / 24.0, (j as f64 + 0.5) / 24.0);
                let lens = DVec2::new(((i * 7 + j * 3) % 24) as f64 / 24.0, ((i * 5 + j * 11) % 24) as f64 / 24.0);
                let ray = original.camera.generate_ray(film, 1.5, lens);
                let placed_ray = placed.camera.generate_ray(film, 1.5, lens);
                let origin_error = (placed_ray.origin - DVec3::from_array(similarity.point(ray.origin.to_array()))).length();
                assert!(origin_error < 1e-8 * 1e-2, "ray origin off by {origin_error}");
                let expected = original.scene.intersect(&ray, f64::INFINITY);
                let found = placed.scene.intersect(&placed_ray, f64::INFINITY);
                let (Some(expected), Some(found)) = (expected, found) else {
                    assert!(expected.is_none() && found.is_none(), "hit in one scene only at film {film}");
                    continue;
                };
                hits += 1;
                let material = original.scene.material_of(expected.primitive);
                let placed_material = placed.scene.material_of(found.primitive);
                // Distances along unnormalised directions that scale alike.
                let ratio = (found.hit.t * placed_ray.direction.length()) / (expected.hit.t * ray.direction.length());
                assert!((ratio / 1e-3 - 1.0).abs() < 1e-8, "distance ratio {ratio} at film {film}");
                let normal_error = (found.hit.geometric_normal - expected.hit.geometric_normal).length();
                assert!(normal_error < 1e-8, "normal off by {normal_error} at film {film}");
                let at = |hit: &crate::geometry::SurfaceHit| ShadingPoint {
                    uv: hit.uv,
                    point: hit.point,
                };
                let colour_error = (albedo(placed_material, &at(&found.hit)) - albedo(material, &at(&expected.hit))).length();
                assert!(colour_error < 1e-6, "texture colour off by {colour_error} at film {film}");
            }
        }
        assert!(hits > 500, "{hits} of 576 rays hit: the view does not test enough");
    }
}
