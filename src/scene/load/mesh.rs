//! Mesh objects: the OBJ file checked and placed, and its `.mtl` materials
//! mapped onto Prism's when the scene names no material for it.
//!
//! The mapping (documented in docs/scene-format.md, "OBJ materials") picks
//! one Prism material per `.mtl` material, first match wins:
//! 1. `Ke` (emission) above zero → emissive with radiance `Ke`.
//! 2. `d` (dissolve) below 1, or a transparent `illum` model (4, 6, 7, 9) →
//!    glass with index `Ni` (default 1.5) and tint `Tf` (default white).
//! 3. `Ks` brighter than `Kd` (by luminance) → glossy with tint `Ks` and GGX
//!    roughness α = √(2 / (Ns + 2)), the Phong-exponent match of Walter et al.
//!    2007 (eq. 4 there maps Beckmann; GGX's lobe is close enough at the
//!    exponents exporters write). `Ns` defaults to 0 (α = 1).
//! 4. Otherwise diffuse: `map_Kd` as an image texture on the mesh's uv, or
//!    `Kd` (default 0.5 grey; components above 1 are clamped, as an albedo
//!    above 1 would create energy).
//!
//! Every given key the chosen material cannot use is named in a warning.

use super::{Builder, COORDINATE_LIMIT, SceneParts, out_of_range};
use crate::color::{Color, luminance};
use crate::geometry::mesh::ObjFile;
use crate::geometry::{Mesh, Shape};
use crate::input_file::regular_file;
use crate::material::Material;
use crate::material::texture::{Mapping, Projection, Texture, Wrap};
use crate::scene::Primitive;
use crate::scene::description::TransformDescription;
use crate::scene::document::FieldPath;
use crate::scene::error::SceneError;
use glam::{DVec2, DVec3};
use std::path::Path;

/// Dissolve below this counts as transparent (exporters write `d 1.0` or
/// `d 0.999999` for opaque materials).
const OPAQUE_DISSOLVE: f32 = 0.999;
/// MTL illumination models that mean refraction or transparency.
const TRANSPARENT_ILLUMINATION: [u8; 4] = [4, 6, 7, 9];
/// `Kd` when the material gives none.
const DEFAULT_DIFFUSE: f64 = 0.5;

impl Builder<'_> {
    /// Loads a mesh object's OBJ file, checks its transformed vertices, and
    /// adds its triangles with `material` or, without one, the `.mtl` materials.
    pub(super) fn mesh(
        &self,
        path: &FieldPath,
        file: &str,
        transform: &TransformDescription,
        material: Option<u32>,
        scene: &mut SceneParts,
    ) -> Result<(), SceneError> {
        let transform = self.transform(path, transform)?;
        let file_field = path.key("file");
        let mesh_path = self.base.join(file);
        regular_file(&mesh_path).map_err(|e| self.error(&file_field, format!("mesh file {e}")))?;
        let obj = Mesh::load_obj_file(&mesh_path, &transform)
            .map_err(|e| self.error(&file_field, format!("{}: {e}", mesh_path.display())))?;
        if let Some(far) = obj.mesh.positions.iter().find(|p| p.abs().max_element() > COORDINATE_LIMIT) {
            let value = far
                .to_array()
                .into_iter()
                .fold(0.0, |a: f64, c| if c.abs() > a.abs() { c } else { a });
            let field = if transform.is_identity() {
                file_field.clone()
            } else {
                path.key("transform")
            };
            return Err(self.error(
                &field,
                format!(
                    "a vertex of {} after the transform {}",
                    mesh_path.display(),
                    out_of_range(value)
                ),
            ));
        }
        let face_material = self.face_materials(path, &mesh_path, &obj, material, scene)?;
        let mesh_index = scene.meshes.len() as u32;
        scene.primitives.extend(obj.mesh.triangles(mesh_index).map(|t| Primitive {
            material: face_material[t.face as usize],
            shape: Shape::Triangle(t),
        }));
        scene.meshes.push(obj.mesh);
        Ok(())
    }

    /// The scene material of every face: `material` for all of them, or the
    /// Prism material made from each face's `.mtl` material.
    fn face_materials(
        &self,
        path: &FieldPath,
        mesh_path: &Path,
        obj: &ObjFile,
        material: Option<u32>,
        scene: &mut SceneParts,
    ) -> Result<Vec<u32>, SceneError> {
        let faces = obj.face_materials.len();
        if let Some(material) = material {
            if !obj.materials.is_empty() {
                let names: Vec<&str> = obj.materials.iter().map(|m| m.name.as_str()).collect();
                self.warn(format!(
                    "{}: the scene's material replaces the .mtl materials of {} ({})",
                    path,
                    mesh_path.display(),
                    names.join(", ")
                ));
            }
            return Ok(vec![material; faces]);
        }
        let known = |m: &Option<usize>| m.is_some_and(|m| m < obj.materials.len());
        let unassigned = obj.face_materials.iter().filter(|m| !known(m)).count();
        if unassigned > 0 || obj.materials.is_empty() {
            let why = match &obj.material_error {
                Some(reason) => format!("its material library could not be read ({reason})"),
                None if obj.materials.is_empty() => "it has no .mtl materials".to_string(),
                None => format!("{unassigned} of its {faces} faces use no .mtl material"),
            };
            return Err(self.error(
                &path.key("material"),
                format!("{} needs a scene material: {why}", mesh_path.display()),
            ));
        }
        let folder = mesh_path.parent().unwrap_or(Path::new("."));
        let first = scene.materials.len() as u32;
        for mtl in &obj.materials {
            let (material, ignored) = self.mtl_material(path, folder, mtl, scene)?;
            if !ignored.is_empty() {
                self.warn(format!(
                    "{}: .mtl material \"{}\" of {}: ignored {}",
                    path,
                    mtl.name,
                    mesh_path.display(),
                    ignored.join(", ")
                ));
            }
            scene.materials.push(material);
        }
        Ok(obj
            .face_materials
            .iter()
            .map(|m| first + m.unwrap_or_default() as u32)
            .collect())
    }

    /// One `.mtl` material as a Prism material, with the keys it ignores.
    fn mtl_material(
        &self,
        path: &FieldPath,
        folder: &Path,
        mtl: &tobj::Material,
        scene: &mut SceneParts,
    ) -> Result<(Material, Vec<String>), SceneError> {
        let rgb = |v: [f32; 3]| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
        let invalid =
            |key: &str, what: &str| self.error(&path.key("file"), format!(".mtl material \"{}\": {key} {what}", mtl.name));
        let color = |key: &str, value: Option<[f32; 3]>| -> Result<Option<Color>, SceneError> {
            match value.map(rgb) {
                Some(c) if !c.is_finite() || c.min_element() < 0.0 => Err(invalid(key, "must be finite and not negative")),
                c => Ok(c),
            }
        };
        let emission = color("Ke", mtl.emissive)?;
        let diffuse = color("Kd", mtl.diffuse)?;
        let specular = color("Ks", mtl.specular)?;
        let ambient = color("Ka", mtl.ambient)?;
        let filter = match mtl.unknown_param.get("Tf") {
            None => None,
            Some(text) => {
                let values: Vec<f32> = text.split_whitespace().filter_map(|w| w.parse().ok()).collect();
                match values.as_slice() {
                    [r, g, b] => color("Tf", Some([*r, *g, *b]))?,
                    [v] => color("Tf", Some([*v; 3]))?,
                    _ => return Err(invalid("Tf", "must be one or three numbers")),
                }
            }
        };
        for (key, value) in [("Ns", mtl.shininess), ("Ni", mtl.optical_density), ("d", mtl.dissolve)] {
            if value.is_some_and(|v| !v.is_finite() || v < 0.0) {
                return Err(invalid(key, "must be finite and not negative"));
            }
        }
        if mtl.optical_density == Some(0.0) {
            return Err(invalid("Ni", "must be positive"));
        }

        let nonzero = |c: Option<Color>| c.is_some_and(|c| c.max_element() > 0.0);
        let transparent = mtl.dissolve.is_some_and(|d| d < OPAQUE_DISSOLVE)
            || mtl.illumination_model.is_some_and(|i| TRANSPARENT_ILLUMINATION.contains(&i));
        let glossy = specular.is_some_and(|s| luminance(s) > luminance(diffuse.unwrap_or(Color::splat(DEFAULT_DIFFUSE))));

        // Which keys the chosen material reads; every other given key is ignored.
        let mut used: Vec<&str> = Vec::new();
        let material = if nonzero(emission) {
            used.push("Ke");
            Material::Emissive {
                radiance: emission.unwrap_or_default(),
                two_sided: false,
                spectrum: None,
            }
        } else if transparent {
            used.extend(["d", "Ni", "Tf"]);
            Material::Glass {
                ior: mtl.optical_density.map_or(1.5, f64::from),
                tint: filter.unwrap_or(Color::ONE),
                dispersion: None,
            }
        } else if glossy {
            used.extend(["Ks", "Ns"]);
            let exponent = mtl.shininess.map_or(0.0, f64::from);
            Material::Glossy {
                tint: Texture::Constant(specular.unwrap_or_default().min(Color::ONE)),
                roughness: (2.0 / (exponent + 2.0)).sqrt(),
            }
        } else {
            let albedo = match &mtl.diffuse_texture {
                Some(name) if !name.starts_with('-') => {
                    used.push("map_Kd");
                    let file = folder.join(name);
                    regular_file(&file).map_err(|e| invalid("map_Kd", &e))?;
                    let image = scene.images.load(&file).map_err(|e| invalid("map_Kd", &e.to_string()))?;
                    Texture::Image {
                        image,
                        mapping: Mapping {
                            projection: Projection::Uv,
                            scale: DVec2::ONE,
                        },
                        wrap: [Wrap::Repeat; 2],
                    }
                }
                _ => {
                    used.push("Kd");
                    let kd = diffuse.unwrap_or(Color::splat(DEFAULT_DIFFUSE));
                    if kd.max_element() > 1.0 {
                        self.warn(format!(
                            "{path}: .mtl material \"{}\": Kd {kd} clamped to 1 (an albedo above 1 would create energy)",
                            mtl.name
                        ));
                    }
                    Texture::Constant(kd.min(Color::ONE))
                }
            };
            Material::Diffuse { albedo }
        };

        let given = [
            ("Ke", nonzero(emission)),
            ("Kd", diffuse.is_some()),
            ("Ks", nonzero(specular)),
            ("Ka", nonzero(ambient)),
            ("Ns", mtl.shininess.is_some() && nonzero(specular)),
            ("Ni", mtl.optical_density.is_some() && transparent),
            ("d", transparent),
            ("Tf", filter.is_some()),
            ("map_Kd", mtl.diffuse_texture.is_some()),
            ("map_Ka", mtl.ambient_texture.is_some()),
            ("map_Ks", mtl.specular_texture.is_some()),
            ("map_Bump", mtl.normal_texture.is_some()),
            ("map_Ns", mtl.shininess_texture.is_some()),
            ("map_d", mtl.dissolve_texture.is_some()),
        ];
        let mut ignored: Vec<String> = given
            .iter()
            .filter(|(key, present)| *present && !used.contains(key))
            .map(|(key, _)| key.to_string())
            .collect();
        if mtl.diffuse_texture.as_deref().is_some_and(|n| n.starts_with('-')) {
            ignored.push("map_Kd (texture options are not supported)".into());
        }
        let mut unknown: Vec<&String> = mtl.unknown_param.keys().filter(|k| k.as_str() != "Tf").collect();
        unknown.sort();
        ignored.extend(unknown.into_iter().cloned());
        Ok((material, ignored))
    }
}
