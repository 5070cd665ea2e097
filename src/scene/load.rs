//! Scene file → validated description → frozen `Scene`, with every error
//! located at its file, line and field.

use super::description::*;
use super::error::{SceneError, line_of};
use super::{Primitive, Scene};
use crate::camera::Camera;
use crate::color::Color;
use crate::geometry::{AxisBox, Mesh, Quad, Revolution, Shape, Sphere, Transform};
use crate::material::Material;
use crate::material::texture::ImageCache;
use crate::math::Aabb;
use crate::settings::RenderSettings;
use glam::{DAffine3, DVec2, DVec3};
use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

mod texture;

/// A scene ready to render, with the camera and settings its file asked for.
#[derive(Debug)]
pub struct LoadedScene {
    pub scene: Scene,
    pub camera: Camera,
    pub settings: RenderSettings,
    /// The file it came from; `None` for the embedded default scene.
    pub path: Option<PathBuf>,
}

/// Reads and builds a scene file; relative paths inside resolve against its folder.
pub fn load_scene_file(path: &Path) -> Result<LoadedScene, SceneError> {
    let text =
        std::fs::read_to_string(path).map_err(|e| SceneError::new(path, None, None, format!("cannot read scene file: {e}")))?;
    let base = path.parent().unwrap_or(Path::new("."));
    let mut loaded = load_scene_str(&text, path, base)?;
    loaded.path = Some(path.to_path_buf());
    Ok(loaded)
}

/// Builds a scene from TOML text; `file` names it in errors, `base` resolves paths.
pub fn load_scene_str(text: &str, file: &Path, base: &Path) -> Result<LoadedScene, SceneError> {
    build_scene(parse_scene_str(text, file)?, text, file, base)
}

/// Parses TOML text into a description without building anything, so it can
/// be edited first (as `scene::Similarity` does); `file` names it in errors.
pub fn parse_scene_str(text: &str, file: &Path) -> Result<SceneDescription, SceneError> {
    toml::from_str(text).map_err(|e| {
        let message = e.message().to_string();
        // Tagged tables report errors at their start; point at the offending
        // key itself when the message names it.
        let key = message
            .strip_prefix("unknown field `")
            .and_then(|rest| rest.split('`').next());
        let line = e.span().map(|span| key_line(text, span, key));
        SceneError::new(file, line, None, message)
    })
}

/// Builds a description parsed from `text` by [`parse_scene_str`] (values may
/// have been edited since; `text` still locates errors by line).
pub fn build_scene(description: SceneDescription, text: &str, file: &Path, base: &Path) -> Result<LoadedScene, SceneError> {
    Builder { text, file, base }.build(description)
}

struct Builder<'a> {
    text: &'a str,
    file: &'a Path,
    base: &'a Path,
}

impl Builder<'_> {
    /// An error about `field` of the table spanning `span`, at the line where
    /// that key is written (or where the table starts).
    fn error(&self, span: Option<Range<usize>>, path: &str, field: &str, message: impl Into<String>) -> SceneError {
        let line = span.map(|span| key_line(self.text, span, Some(field)));
        let full = if path.is_empty() {
            field.to_string()
        } else {
            format!("{path}.{field}")
        };
        SceneError::new(self.file, line, Some(full), message)
    }

    fn finite(&self, span: &Option<Range<usize>>, path: &str, field: &str, values: &[f64]) -> Result<(), SceneError> {
        if values.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(self.error(span.clone(), path, field, "must be a finite number (found NaN or infinity)"))
        }
    }

    fn color(&self, span: &Option<Range<usize>>, path: &str, field: &str, v: Vector) -> Result<Color, SceneError> {
        self.finite(span, path, field, &v)?;
        if v.iter().any(|&c| c < 0.0) {
            return Err(self.error(span.clone(), path, field, "colour components must not be negative"));
        }
        Ok(DVec3::from_array(v))
    }

    fn build(&self, description: SceneDescription) -> Result<LoadedScene, SceneError> {
        let camera = self.camera(&description.camera)?;
        let settings = self.settings(&description.render)?;

        // Materials, by name.
        let mut material_index = HashMap::new();
        let mut materials = Vec::new();
        // Each image file is decoded once, however many materials use it.
        let mut images = ImageCache::default();
        for (name, spanned) in &description.materials {
            let span = Some(spanned.span());
            let path = format!("materials.{name}");
            materials.push(self.material(&span, &path, spanned.get_ref(), &mut images)?);
            material_index.insert(name.as_str(), (materials.len() - 1) as u32);
        }

        // Objects.
        let mut primitives = Vec::new();
        let mut meshes = Vec::new();
        for (i, spanned) in description.objects.iter().enumerate() {
            let span = Some(spanned.span());
            let path = format!("objects[{i}]");
            let object = spanned.get_ref();
            let material = *material_index.get(object.material()).ok_or_else(|| {
                let known: Vec<&str> = material_index.keys().copied().collect();
                self.error(
                    span.clone(),
                    &path,
                    "material",
                    format!("unknown material \"{}\" (defined: {})", object.material(), known.join(", ")),
                )
            })?;
            self.object(&span, &path, object, material, &mut primitives, &mut meshes)?;
        }

        let background = match &description.background {
            Some(b) => self.color(&Some(b.span()), "", "background", *b.get_ref())?,
            None => Color::ZERO,
        };
        let scene = Scene::new(primitives, meshes, materials, background);
        Ok(LoadedScene {
            scene,
            camera,
            settings,
            path: None,
        })
    }

    fn camera(&self, c: &CameraDescription) -> Result<Camera, SceneError> {
        let span = find_table(self.text, "camera");
        let p = "camera";
        self.finite(&span, p, "position", &c.position)?;
        self.finite(&span, p, "look_at", &c.look_at)?;
        self.finite(&span, p, "up", &c.up)?;
        self.finite(&span, p, "fov_y_degrees", &[c.fov_y_degrees])?;
        self.finite(&span, p, "aperture_radius", &[c.aperture_radius])?;
        let position = DVec3::from_array(c.position);
        let look_at = DVec3::from_array(c.look_at);
        let up = DVec3::from_array(c.up);
        if (look_at - position).length() == 0.0 {
            return Err(self.error(span, p, "look_at", "must differ from position"));
        }
        if (look_at - position).cross(up).length() == 0.0 {
            return Err(self.error(span, p, "up", "must not be parallel to the view direction"));
        }
        if !(c.fov_y_degrees > 0.0 && c.fov_y_degrees < 180.0) {
            return Err(self.error(span, p, "fov_y_degrees", "must be between 0 and 180 degrees"));
        }
        if c.aperture_radius < 0.0 {
            return Err(self.error(span, p, "aperture_radius", "must not be negative"));
        }
        let focal_distance = match c.focal_distance {
            Some(f) if !(f.is_finite() && f > 0.0) => {
                return Err(self.error(span, p, "focal_distance", "must be a positive finite number"));
            }
            Some(f) => f,
            None => (look_at - position).length(),
        };
        self.finite(&span, p, "near_clip", &[c.near_clip])?;
        if c.near_clip < 0.0 {
            return Err(self.error(span, p, "near_clip", "must not be negative"));
        }
        let mut camera = Camera::new(position, look_at, up, c.fov_y_degrees, c.aperture_radius, focal_distance);
        camera.near_clip = c.near_clip;
        Ok(camera)
    }

    fn settings(&self, r: &RenderDescription) -> Result<RenderSettings, SceneError> {
        let span = find_table(self.text, "render");
        let p = "render";
        let mut s = RenderSettings::default();
        let positive = |value: Option<u32>, field: &str| match value {
            Some(0) => Err(self.error(span.clone(), p, field, "must be at least 1")),
            _ => Ok(value),
        };
        if let Some(w) = positive(r.width, "width")? {
            s.width = w;
        }
        if let Some(h) = positive(r.height, "height")? {
            s.height = h;
        }
        if let Some(spp) = positive(r.spp, "spp")? {
            s.samples_per_pixel = Some(spp);
        }
        if let Some(d) = positive(r.max_depth, "max_depth")? {
            s.max_depth = d;
        }
        if let Some(photons) = positive(r.photons_per_iteration, "photons_per_iteration")? {
            s.sppm.photons_per_iteration = photons;
        }
        if let Some(radius) = r.initial_radius {
            if !(radius.is_finite() && radius > 0.0) {
                return Err(self.error(span, p, "initial_radius", "must be a positive finite number"));
            }
            s.sppm.initial_radius = Some(radius);
        }
        if let Some(alpha) = r.alpha {
            if !(alpha > 0.0 && alpha < 1.0) {
                return Err(self.error(span, p, "alpha", "must be strictly between 0 and 1"));
            }
            s.sppm.alpha = alpha;
        }
        if let Some(threshold) = r.adaptive_threshold {
            if !(threshold.is_finite() && threshold > 0.0) {
                return Err(self.error(span, p, "adaptive_threshold", "must be a positive finite number"));
            }
            s.adaptive_threshold = Some(threshold);
        }
        s.integrator = r.integrator.unwrap_or(s.integrator);
        s.sampler = r.sampler.unwrap_or(s.sampler);
        s.seed = r.seed.unwrap_or(s.seed);
        Ok(s)
    }

    fn material(
        &self,
        span: &Option<Range<usize>>,
        path: &str,
        m: &MaterialDescription,
        images: &mut ImageCache,
    ) -> Result<Material, SceneError> {
        Ok(match m {
            MaterialDescription::Diffuse { albedo } => Material::Diffuse {
                albedo: self.texture(span, path, "albedo", albedo, true, images)?,
            },
            MaterialDescription::Mirror { tint } => Material::Mirror {
                tint: self.texture(span, path, "tint", tint, false, images)?,
            },
            MaterialDescription::Glass { ior, tint } => {
                self.finite(span, path, "ior", &[*ior])?;
                if *ior <= 0.0 {
                    return Err(self.error(span.clone(), path, "ior", "must be positive"));
                }
                Material::Glass {
                    ior: *ior,
                    tint: self.color(span, path, "tint", *tint)?,
                }
            }
            MaterialDescription::Glossy { tint, roughness } => {
                self.finite(span, path, "roughness", &[*roughness])?;
                if !(0.0..=1.0).contains(roughness) {
                    return Err(self.error(span.clone(), path, "roughness", "must be between 0 and 1"));
                }
                Material::Glossy {
                    tint: self.texture(span, path, "tint", tint, false, images)?,
                    roughness: *roughness,
                }
            }
            MaterialDescription::Emissive { radiance, two_sided } => Material::Emissive {
                radiance: self.color(span, path, "radiance", *radiance)?,
                two_sided: *two_sided,
            },
        })
    }

    fn object(
        &self,
        span: &Option<Range<usize>>,
        path: &str,
        object: &ObjectDescription,
        material: u32,
        primitives: &mut Vec<Primitive>,
        meshes: &mut Vec<Mesh>,
    ) -> Result<(), SceneError> {
        let mut push = |shape: Shape| primitives.push(Primitive { shape, material });
        match object {
            ObjectDescription::Sphere { center, radius, .. } => {
                self.finite(span, path, "center", center)?;
                self.finite(span, path, "radius", &[*radius])?;
                if *radius <= 0.0 {
                    return Err(self.error(span.clone(), path, "radius", format!("must be positive (found {radius})")));
                }
                push(Shape::Sphere(Sphere {
                    center: DVec3::from_array(*center),
                    radius: *radius,
                }));
            }
            ObjectDescription::Box { min, max, .. } => {
                self.finite(span, path, "min", min)?;
                self.finite(span, path, "max", max)?;
                let (lo, hi) = (DVec3::from_array(*min), DVec3::from_array(*max));
                if lo.cmpge(hi).any() {
                    return Err(self.error(span.clone(), path, "max", "must exceed min on every axis"));
                }
                push(Shape::AxisBox(AxisBox {
                    bounds: Aabb::new(lo, hi),
                }));
            }
            ObjectDescription::Quad {
                corner, edge_u, edge_v, ..
            } => {
                self.finite(span, path, "corner", corner)?;
                self.finite(span, path, "edge_u", edge_u)?;
                self.finite(span, path, "edge_v", edge_v)?;
                let (u, v) = (DVec3::from_array(*edge_u), DVec3::from_array(*edge_v));
                if u.cross(v).length() == 0.0 {
                    return Err(self.error(span.clone(), path, "edge_v", "edges must not be parallel or zero"));
                }
                push(Shape::Quad(Quad::new(DVec3::from_array(*corner), u, v)));
            }
            ObjectDescription::Triangle { vertices, .. } => {
                self.finite(span, path, "vertices", &vertices.concat())?;
                let mesh = Mesh::from_triangles(&[vertices.map(DVec3::from_array)]);
                let before = primitives.len();
                primitives.extend(mesh.triangles(meshes.len() as u32).map(|t| Primitive {
                    shape: Shape::Triangle(t),
                    material,
                }));
                if primitives.len() == before {
                    return Err(self.error(span.clone(), path, "vertices", "the triangle has zero area"));
                }
                meshes.push(mesh);
            }
            ObjectDescription::Mesh { file, transform, .. } => {
                let transform = self.transform(span, path, transform)?;
                let mesh_path = self.base.join(file);
                if !mesh_path.is_file() {
                    return Err(self.error(
                        span.clone(),
                        path,
                        "file",
                        format!("mesh file not found: {}", mesh_path.display()),
                    ));
                }
                let mesh = Mesh::load_obj(&mesh_path, &transform)
                    .map_err(|e| self.error(span.clone(), path, "file", format!("{}: {e}", mesh_path.display())))?;
                primitives.extend(mesh.triangles(meshes.len() as u32).map(|t| Primitive {
                    shape: Shape::Triangle(t),
                    material,
                }));
                meshes.push(mesh);
            }
            ObjectDescription::Revolution {
                profile,
                segments,
                caps,
                transform,
                ..
            } => {
                let segments: Vec<Vec<DVec2>> = match (profile, segments) {
                    (Some(points), None) => vec![points.iter().map(|p| DVec2::from_array(*p)).collect()],
                    (None, Some(chain)) => chain
                        .iter()
                        .map(|s| s.iter().map(|p| DVec2::from_array(*p)).collect())
                        .collect(),
                    _ => return Err(self.error(span.clone(), path, "profile", "give exactly one of `profile` or `segments`")),
                };
                let field = if profile.is_some() { "profile" } else { "segments" };
                let flat: Vec<f64> = segments.iter().flatten().flat_map(|p| [p.x, p.y]).collect();
                self.finite(span, path, field, &flat)?;
                let transform = self.transform(span, path, transform)?;
                // The profile lies in the local (x, z) half-plane rotated about z;
                // scene files are y-up, so local z maps to world y.
                let y_up = DAffine3::from_cols(DVec3::X, -DVec3::Z, DVec3::Y, DVec3::ZERO);
                let revolution = Revolution::new(segments, *caps, transform.to_world * y_up)
                    .map_err(|e| self.error(span.clone(), path, field, e))?;
                push(Shape::Revolution(Box::new(revolution)));
            }
        }
        Ok(())
    }

    fn transform(&self, span: &Option<Range<usize>>, path: &str, t: &TransformDescription) -> Result<Transform, SceneError> {
        let translate = t.translate.unwrap_or([0.0; 3]);
        let rotate = t.rotate_degrees.unwrap_or([0.0; 3]);
        let scale = match t.scale {
            None => [1.0; 3],
            Some(Scale::Uniform(s)) => [s; 3],
            Some(Scale::PerAxis(v)) => v,
        };
        self.finite(span, path, "transform", &[translate, rotate, scale].concat())?;
        if scale.contains(&0.0) {
            return Err(self.error(span.clone(), path, "scale", "must not be zero"));
        }
        Ok(Transform::new(
            DVec3::from_array(translate),
            DVec3::from_array(rotate),
            DVec3::from_array(scale),
        ))
    }
}

/// 1-based line of `key` inside the table spanning `span`, or of the table's
/// start when the key is not found. A `[[table]]`'s span may cover only its
/// header, so the search runs on to the next header as well.
fn key_line(text: &str, span: Range<usize>, key: Option<&str>) -> usize {
    let start = span.start.min(text.len());
    let next_header = text[start..].find("\n[").map_or(text.len(), |i| start + i);
    let end = span.end.min(text.len()).max(next_header);
    let offset = key.and_then(|k| find_key(&text[start..end], k)).unwrap_or(0);
    line_of(text, start + offset)
}

/// Byte offset of `key =` (at a line start or after `{`/`,`) within `body`.
fn find_key(body: &str, key: &str) -> Option<usize> {
    let mut search = 0;
    while let Some(found) = body[search..].find(key) {
        let at = search + found;
        let before = body[..at].trim_end_matches([' ', '\t']);
        let after = body[at + key.len()..].trim_start_matches([' ', '\t']);
        let starts_key = before.is_empty() || before.ends_with(['\n', '{', ',']);
        if starts_key && after.starts_with('=') {
            return Some(at);
        }
        search = at + key.len();
    }
    None
}

/// Span of a top-level `[name]` table's body.
fn find_table(text: &str, name: &str) -> Option<Range<usize>> {
    let header = format!("[{name}]");
    let start = text.lines().scan(0, |offset, line| {
        let here = *offset;
        *offset += line.len() + 1;
        Some((here, line))
    });
    for (offset, line) in start {
        if line.trim() == header {
            let body_start = offset;
            let rest = &text[body_start + line.len()..];
            let end = rest.find("\n[").map_or(text.len(), |e| body_start + line.len() + e);
            return Some(body_start..end);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_scene_loads() {
        let loaded = load_scene_str(super::super::DEFAULT_SCENE, Path::new("default"), Path::new("."));
        assert!(loaded.is_ok(), "{:?}", loaded.err());
    }

    #[test]
    fn errors_name_line_and_field() {
        let text = "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n\n[materials.white]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = -1\nmaterial = \"white\"\n";
        let error = load_scene_str(text, Path::new("s.toml"), Path::new(".")).err();
        let message = error.map(|e| e.to_string()).unwrap_or_default();
        assert_eq!(message, "s.toml:12: objects[0].radius: must be positive (found -1)");
    }
}
