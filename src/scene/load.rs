//! Scene file → spanned document → description → frozen `Scene`, with every
//! error placed at its file, line and column and named by its full field
//! path (see `scene::document`).
//!
//! Besides each field's own range, every position, radius, edge and
//! transformed vertex must lie within [`COORDINATE_LIMIT`] of the origin.

use super::description::*;
use super::document::{Document, FieldPath};
use super::error::{Location, SceneError};
use super::progress::LoadStage;
use super::{Primitive, Scene};
use crate::accel::bvh::MAX_PRIMITIVES_PER_KIND;
use crate::camera::Camera;
use crate::color::Color;
use crate::geometry::{AxisBox, Mesh, Quad, Revolution, Shape, Sphere, Transform};
use crate::material::Material;
use crate::material::texture::ImageCache;
use crate::math::Aabb;
use crate::settings::validate::available_memory;
use crate::settings::{RenderSettings, Setting, SettingError};
use crate::spectrum::dispersion::Dispersion;
use emission::EmissiveKeys;
use glam::{DAffine3, DVec2, DVec3};
use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

mod emission;
mod mesh;
mod texture;

/// Largest magnitude of any coordinate, radius or edge component a scene may
/// use, in scene units. Triangles are stored in single precision (f32) for
/// intersection, and the watertight ray-triangle test multiplies up to three
/// coordinates taken relative to the ray origin (up to 2·10¹² apart): 8·10³⁶
/// stays well below f32's largest value, 3.4·10³⁸. Spheres and the f64 error
/// bounds of ray origins (pbrt's γₙ bounds, which assume no overflow) square
/// coordinates: 10²⁴ is far from f64's limit. See docs/scene-format.md,
/// "Coordinates".
pub const COORDINATE_LIMIT: f64 = 1e12;
/// A glass's index when the file gives neither `ior` nor a named `glass`.
const DEFAULT_IOR: f64 = 1.5;

/// A scene ready to render, with the camera and settings its file asked for.
#[derive(Debug)]
pub struct LoadedScene {
    /// The built scene, ready to render.
    pub scene: Scene,
    /// The camera of the file's `[camera]` table.
    pub camera: Camera,
    /// Default settings with the file's `[render]` table applied.
    pub settings: RenderSettings,
    /// The file it came from; `None` for the embedded default scene.
    pub path: Option<PathBuf>,
    /// Things the file asked for that Prism cannot show (e.g. `.mtl` keys
    /// without a Prism equivalent), one line each.
    pub warnings: Vec<String>,
}

/// Reads and builds a scene file; relative paths inside resolve against its folder.
pub fn load_scene_file(path: &Path) -> Result<LoadedScene, SceneError> {
    load_scene_file_reporting(path, &|_| {})
}

/// `load_scene_file`, telling `progress` which stage it is in (see `scene::progress`).
pub(super) fn load_scene_file_reporting(path: &Path, progress: &dyn Fn(LoadStage)) -> Result<LoadedScene, SceneError> {
    progress(LoadStage::Parsing);
    let cannot_read = |message: String| SceneError::new(path, None, None, message);
    // The error names the scene file already.
    if let Some(reason) = crate::input_file::not_a_regular_file(path) {
        return Err(cannot_read(reason));
    }
    let bytes = std::fs::read(path).map_err(|e| cannot_read(format!("cannot read scene file: {e}")))?;
    let base = path.parent().unwrap_or(Path::new("."));
    let mut loaded = load_scene_bytes_reporting(&bytes, path, base, progress)?;
    loaded.path = Some(path.to_path_buf());
    Ok(loaded)
}

/// Builds a scene from the bytes of a scene file, which must be UTF-8 (an
/// error names the line and column of the first bad byte).
pub fn load_scene_bytes(bytes: &[u8], file: &Path, base: &Path) -> Result<LoadedScene, SceneError> {
    load_scene_bytes_reporting(bytes, file, base, &|_| {})
}

fn load_scene_bytes_reporting(
    bytes: &[u8],
    file: &Path,
    base: &Path,
    progress: &dyn Fn(LoadStage),
) -> Result<LoadedScene, SceneError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        // Everything before the first bad byte is valid text to count in.
        let valid = std::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or_default();
        SceneError::new(
            file,
            Some(Location::of_offset(valid, valid.len())),
            None,
            format!("the file is not valid UTF-8 (byte 0x{:02x})", bytes[e.valid_up_to()]),
        )
    })?;
    load_scene_str_edited_reporting(text, file, base, |_| {}, progress)
}

/// Builds a scene from TOML text; `file` names it in errors, `base` resolves paths.
pub fn load_scene_str(text: &str, file: &Path, base: &Path) -> Result<LoadedScene, SceneError> {
    load_scene_str_edited(text, file, base, |_| {})
}

/// Parses TOML text into a description, lets `edit` change it (as
/// `scene::Similarity` does), then builds it; errors still point into `text`.
pub fn load_scene_str_edited(
    text: &str,
    file: &Path,
    base: &Path,
    edit: impl FnOnce(&mut SceneDescription),
) -> Result<LoadedScene, SceneError> {
    load_scene_str_edited_reporting(text, file, base, edit, &|_| {})
}

fn load_scene_str_edited_reporting(
    text: &str,
    file: &Path,
    base: &Path,
    edit: impl FnOnce(&mut SceneDescription),
    progress: &dyn Fn(LoadStage),
) -> Result<LoadedScene, SceneError> {
    let document = Document::parse(text, file)?;
    let retagged = document.retagged(&["objects"], &["materials"])?;
    let mut description: SceneDescription = document.deserialize(retagged)?;
    edit(&mut description);
    let builder = Builder {
        document: &document,
        base,
        warnings: RefCell::default(),
        progress,
    };
    builder.build(description)
}

struct Builder<'a> {
    document: &'a Document<'a>,
    base: &'a Path,
    warnings: RefCell<Vec<String>>,
    progress: &'a dyn Fn(LoadStage),
}

impl Builder<'_> {
    /// An error about the field at `path`, placed where it is written.
    fn error(&self, path: &FieldPath, message: impl Into<String>) -> SceneError {
        self.document.error(path, message)
    }

    fn warn(&self, message: String) {
        self.warnings.borrow_mut().push(message);
    }

    fn finite(&self, path: &FieldPath, values: &[f64]) -> Result<(), SceneError> {
        if values.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(self.error(path, "must be a finite number (found NaN or infinity)"))
        }
    }

    /// Finite and within ±[`COORDINATE_LIMIT`]: positions, radii, edges. An
    /// error names the component (`center[1]`) when `values` has several.
    fn coordinates(&self, path: &FieldPath, values: &[f64]) -> Result<(), SceneError> {
        let Some(i) = values.iter().position(|v| !(v.is_finite() && v.abs() <= COORDINATE_LIMIT)) else {
            return Ok(());
        };
        let at = if values.len() > 1 { path.index(i) } else { path.clone() };
        if values[i].is_finite() {
            Err(self.error(&at, out_of_range(values[i])))
        } else {
            Err(self.error(&at, "must be a finite number (found NaN or infinity)"))
        }
    }

    fn color(&self, path: &FieldPath, v: Vector) -> Result<Color, SceneError> {
        self.finite(path, &v)?;
        if v.iter().any(|&c| c < 0.0) {
            return Err(self.error(path, "colour components must not be negative"));
        }
        Ok(DVec3::from_array(v))
    }

    fn build(&self, description: SceneDescription) -> Result<LoadedScene, SceneError> {
        let camera = self.camera(&description.camera)?;
        let settings = self.settings(&description.render)?;
        let root = FieldPath::root();

        // Materials, by name.
        let mut material_index = HashMap::new();
        let mut materials = Vec::new();
        // Each image file is decoded once, however many materials use it.
        let mut images = ImageCache::default();
        for (name, material) in &description.materials {
            let path = root.key("materials").key(name);
            materials.push(self.material(&path, material, &mut images)?);
            material_index.insert(name.as_str(), (materials.len() - 1) as u32);
        }

        // Objects.
        let mut primitives = Vec::new();
        let mut meshes = Vec::new();
        for (i, object) in description.objects.iter().enumerate() {
            (self.progress)(LoadStage::Objects {
                done: i,
                total: description.objects.len(),
            });
            let path = root.key("objects").index(i);
            let material = match object.material() {
                None => None,
                Some(name) => Some(*material_index.get(name).ok_or_else(|| {
                    let known: Vec<&str> = material_index.keys().copied().collect();
                    self.error(
                        &path.key("material"),
                        format!("unknown material \"{name}\" (defined: {})", known.join(", ")),
                    )
                })?),
            };
            let mut scene = SceneParts {
                primitives: &mut primitives,
                meshes: &mut meshes,
                materials: &mut materials,
                images: &mut images,
            };
            self.object(&path, object, material, &mut scene)?;
            if primitives.len() > MAX_PRIMITIVES_PER_KIND {
                return Err(self.error(
                    &path,
                    format!(
                        "the objects up to this one hold {} primitives (a mesh counts its triangles); \
                         the BVH indexes at most {MAX_PRIMITIVES_PER_KIND}",
                        primitives.len()
                    ),
                ));
            }
        }

        let background = match description.background {
            Some(b) => self.color(&root.key("background"), b)?,
            None => Color::ZERO,
        };
        (self.progress)(LoadStage::Bvh {
            primitives: primitives.len(),
        });
        let scene = Scene::new(primitives, meshes, materials, background);
        Ok(LoadedScene {
            scene,
            camera,
            settings,
            path: None,
            warnings: self.warnings.take(),
        })
    }

    fn camera(&self, c: &CameraDescription) -> Result<Camera, SceneError> {
        let p = FieldPath::root().key("camera");
        self.coordinates(&p.key("position"), &c.position)?;
        self.coordinates(&p.key("look_at"), &c.look_at)?;
        self.coordinates(&p.key("up"), &c.up)?;
        self.finite(&p.key("fov_y_degrees"), &[c.fov_y_degrees])?;
        self.coordinates(&p.key("aperture_radius"), &[c.aperture_radius])?;
        let position = DVec3::from_array(c.position);
        let look_at = DVec3::from_array(c.look_at);
        let up = DVec3::from_array(c.up);
        if (look_at - position).length() == 0.0 {
            return Err(self.error(&p.key("look_at"), "must differ from position"));
        }
        if (look_at - position).cross(up).length() == 0.0 {
            return Err(self.error(&p.key("up"), "must not be parallel to the view direction"));
        }
        if !(c.fov_y_degrees > 0.0 && c.fov_y_degrees < 180.0) {
            return Err(self.error(&p.key("fov_y_degrees"), "must be between 0 and 180 degrees"));
        }
        if c.aperture_radius < 0.0 {
            return Err(self.error(&p.key("aperture_radius"), "must not be negative"));
        }
        let focal_distance = match c.focal_distance {
            Some(f) => {
                self.coordinates(&p.key("focal_distance"), &[f])?;
                if f <= 0.0 {
                    return Err(self.error(&p.key("focal_distance"), "must be a positive finite number"));
                }
                f
            }
            None => (look_at - position).length(),
        };
        self.coordinates(&p.key("near_clip"), &[c.near_clip])?;
        if c.near_clip < 0.0 {
            return Err(self.error(&p.key("near_clip"), "must not be negative"));
        }
        let mut camera = Camera::new(position, look_at, up, c.fov_y_degrees, c.aperture_radius, focal_distance);
        camera.near_clip = c.near_clip;
        Ok(camera)
    }

    /// The `[render]` table through the same validation as the command line's
    /// flags, then the image's memory estimate against what the system has.
    fn settings(&self, patch: &crate::settings::SettingsPatch) -> Result<RenderSettings, SceneError> {
        let render = FieldPath::root().key("render");
        let located = |error: SettingError| {
            let key = match error.setting.key() {
                Some(key) => render.key(key),
                None => render.clone(),
            };
            self.error(&key, error.message)
        };
        let mut settings = RenderSettings::default();
        patch.apply_to(&mut settings).map_err(located)?;
        settings.check_memory(available_memory()).map_err(|mut error| {
            // The size is the product: name the side the file set.
            if patch.width.is_none() && patch.height.is_some() {
                error.setting = Setting::Height;
            }
            located(error)
        })?;
        Ok(settings)
    }

    fn material(&self, path: &FieldPath, m: &MaterialDescription, images: &mut ImageCache) -> Result<Material, SceneError> {
        Ok(match m {
            MaterialDescription::Diffuse { albedo } => Material::Diffuse {
                albedo: self.texture(&path.key("albedo"), albedo, true, images)?,
            },
            MaterialDescription::Mirror { tint } => Material::Mirror {
                tint: self.texture(&path.key("tint"), tint, false, images)?,
            },
            MaterialDescription::Glass { ior, glass, abbe, tint } => {
                let dispersion = match (glass, abbe) {
                    (Some(_), Some(_)) => {
                        return Err(self.error(
                            &path.key("abbe"),
                            "a named glass has its own dispersion: give `glass` or `abbe`, not both",
                        ));
                    }
                    (Some(name), None) => {
                        if ior.is_some() {
                            return Err(self.error(
                                &path.key("ior"),
                                format!("the glass {name} has its own index: give `glass` or `ior`, not both"),
                            ));
                        }
                        let names: Vec<&str> = Dispersion::NAMED.iter().map(|(n, _)| *n).collect();
                        let found = Dispersion::named(name);
                        Some(found.ok_or_else(|| {
                            self.error(
                                &path.key("glass"),
                                format!("unknown glass {name:?} (known: {})", names.join(", ")),
                            )
                        })?)
                    }
                    (None, Some(abbe)) => {
                        self.finite(&path.key("abbe"), &[*abbe])?;
                        if *abbe <= 0.0 {
                            return Err(self.error(&path.key("abbe"), format!("must be positive (found {abbe})")));
                        }
                        Some(Dispersion::from_abbe(ior.unwrap_or(DEFAULT_IOR), *abbe))
                    }
                    (None, None) => None,
                };
                let ior = match (ior, dispersion) {
                    (Some(ior), _) => *ior,
                    (None, Some(dispersion)) => dispersion.nd(),
                    (None, None) => DEFAULT_IOR,
                };
                self.finite(&path.key("ior"), &[ior])?;
                if ior <= 1.0 && dispersion.is_some() {
                    return Err(self.error(&path.key("ior"), format!("a dispersive glass needs nd above 1 (found {ior})")));
                }
                if ior <= 0.0 {
                    return Err(self.error(&path.key("ior"), format!("must be positive (found {ior})")));
                }
                Material::Glass {
                    ior,
                    tint: self.color(&path.key("tint"), *tint)?,
                    dispersion,
                }
            }
            MaterialDescription::Glossy { tint, roughness } => {
                self.finite(&path.key("roughness"), &[*roughness])?;
                if !(0.0..=1.0).contains(roughness) {
                    return Err(self.error(&path.key("roughness"), format!("must be between 0 and 1 (found {roughness})")));
                }
                Material::Glossy {
                    tint: self.texture(&path.key("tint"), tint, false, images)?,
                    roughness: *roughness,
                }
            }
            MaterialDescription::Emissive {
                radiance,
                spectrum,
                temperature,
                luminance,
                two_sided,
            } => self.emissive(
                path,
                EmissiveKeys {
                    radiance: *radiance,
                    spectrum: spectrum.as_deref(),
                    temperature: *temperature,
                    luminance: *luminance,
                },
                *two_sided,
            )?,
        })
    }

    /// Checks and builds one object; `material` is the scene material it
    /// names (only a mesh may name none, taking its `.mtl` materials).
    fn object(
        &self,
        path: &FieldPath,
        object: &ObjectDescription,
        material: Option<u32>,
        scene: &mut SceneParts,
    ) -> Result<(), SceneError> {
        let material = match (object, material) {
            (ObjectDescription::Mesh { file, transform, .. }, material) => {
                return self.mesh(path, file, transform, material, scene);
            }
            (_, Some(material)) => material,
            // The description requires `material` for every other kind.
            (_, None) => return Err(self.error(&path.key("material"), "missing field `material`")),
        };
        let mut push = |shape: Shape| scene.primitives.push(Primitive { shape, material });
        match object {
            ObjectDescription::Sphere { center, radius, .. } => {
                self.coordinates(&path.key("center"), center)?;
                self.coordinates(&path.key("radius"), &[*radius])?;
                if *radius <= 0.0 {
                    return Err(self.error(&path.key("radius"), format!("must be positive (found {radius})")));
                }
                push(Shape::Sphere(Sphere {
                    center: DVec3::from_array(*center),
                    radius: *radius,
                }));
            }
            ObjectDescription::Box { min, max, .. } => {
                self.coordinates(&path.key("min"), min)?;
                self.coordinates(&path.key("max"), max)?;
                let (lo, hi) = (DVec3::from_array(*min), DVec3::from_array(*max));
                if lo.cmpge(hi).any() {
                    return Err(self.error(&path.key("max"), "must exceed min on every axis"));
                }
                push(Shape::AxisBox(AxisBox {
                    bounds: Aabb::new(lo, hi),
                }));
            }
            ObjectDescription::Quad {
                corner, edge_u, edge_v, ..
            } => {
                self.coordinates(&path.key("corner"), corner)?;
                self.coordinates(&path.key("edge_u"), edge_u)?;
                self.coordinates(&path.key("edge_v"), edge_v)?;
                let (u, v) = (DVec3::from_array(*edge_u), DVec3::from_array(*edge_v));
                if u.cross(v).length() == 0.0 {
                    return Err(self.error(&path.key("edge_v"), "edges must not be parallel or zero"));
                }
                let far = DVec3::from_array(*corner) + u + v;
                self.coordinates(&path.key("edge_v"), &far.to_array())?;
                push(Shape::Quad(Quad::new(DVec3::from_array(*corner), u, v)));
            }
            ObjectDescription::Triangle { vertices, .. } => {
                for (k, vertex) in vertices.iter().enumerate() {
                    self.coordinates(&path.key("vertices").index(k), vertex)?;
                }
                let mesh = Mesh::from_triangles(&[vertices.map(DVec3::from_array)]);
                let before = scene.primitives.len();
                scene
                    .primitives
                    .extend(mesh.triangles(scene.meshes.len() as u32).map(|t| Primitive {
                        shape: Shape::Triangle(t),
                        material,
                    }));
                if scene.primitives.len() == before {
                    return Err(self.error(&path.key("vertices"), "the triangle has zero area"));
                }
                scene.meshes.push(mesh);
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
                    (Some(_), Some(_)) => {
                        return Err(self.error(&path.key("segments"), "give exactly one of `profile` or `segments`"));
                    }
                    (None, None) => return Err(self.error(&path.key("profile"), "missing field `profile` (or `segments`)")),
                };
                let field = path.key(if profile.is_some() { "profile" } else { "segments" });
                let flat: Vec<f64> = segments.iter().flatten().flat_map(|p| [p.x, p.y]).collect();
                self.coordinates(&field, &flat)?;
                let transform = self.transform(path, transform)?;
                // The profile lies in the local (x, z) half-plane rotated about z;
                // scene files are y-up, so local z maps to world y.
                let y_up = DAffine3::from_cols(DVec3::X, -DVec3::Z, DVec3::Y, DVec3::ZERO);
                let revolution =
                    Revolution::new(segments, *caps, transform.to_world * y_up).map_err(|e| self.error(&field, e))?;
                let bounds = revolution.bounds();
                self.coordinates(
                    &path.key("transform"),
                    &[bounds.min.to_array(), bounds.max.to_array()].concat(),
                )
                .map_err(|e| SceneError {
                    message: format!("the transformed surface {}", e.message),
                    ..e
                })?;
                push(Shape::Revolution(Box::new(revolution)));
            }
            ObjectDescription::Mesh { .. } => {}
        }
        Ok(())
    }

    /// An object's `transform` table: finite, with non-zero scales, and a
    /// translation within the coordinate range.
    fn transform(&self, path: &FieldPath, t: &TransformDescription) -> Result<Transform, SceneError> {
        let path = path.key("transform");
        let translate = t.translate.unwrap_or([0.0; 3]);
        let rotate = t.rotate_degrees.unwrap_or([0.0; 3]);
        let scale = match t.scale {
            None => [1.0; 3],
            Some(Scale::Uniform(s)) => [s; 3],
            Some(Scale::PerAxis(v)) => v,
        };
        self.coordinates(&path.key("translate"), &translate)?;
        self.finite(&path.key("rotate_degrees"), &rotate)?;
        self.coordinates(&path.key("scale"), &scale)?;
        if scale.contains(&0.0) {
            return Err(self.error(&path.key("scale"), "must not be zero"));
        }
        Ok(Transform::new(
            DVec3::from_array(translate),
            DVec3::from_array(rotate),
            DVec3::from_array(scale),
        ))
    }
}

/// What the objects add to the scene as they are built.
struct SceneParts<'a> {
    primitives: &'a mut Vec<Primitive>,
    meshes: &'a mut Vec<Mesh>,
    materials: &'a mut Vec<Material>,
    images: &'a mut ImageCache,
}

/// The message for a value beyond [`COORDINATE_LIMIT`].
fn out_of_range(value: f64) -> String {
    format!("must lie within ±{COORDINATE_LIMIT:e} scene units (found {value:e}; see \"Coordinates\" in docs/scene-format.md)")
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
    fn errors_name_line_column_and_field() {
        let text = "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n\n[materials.white]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = -1\nmaterial = \"white\"\n";
        let error = load_scene_str(text, Path::new("s.toml"), Path::new(".")).err();
        let message = error.map(|e| e.to_string()).unwrap_or_default();
        assert_eq!(message, "s.toml:12:10: objects[0].radius: must be positive (found -1)");
    }
}
