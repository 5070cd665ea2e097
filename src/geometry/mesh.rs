//! Triangle meshes from Wavefront OBJ files (read with `tobj`), baked into
//! world space by their transform, with optional vertex normals and uv.

use super::transform::Transform;
use super::triangle::Triangle;
use crate::input_file::regular_file;
use glam::{DVec2, DVec3};
use std::path::Path;

/// Shared per-vertex attributes of a mesh; faces index into them.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Vertex positions, world space (the transform is already applied).
    pub positions: Vec<DVec3>,
    /// Unit vertex normals, world space; empty unless every vertex has one.
    pub normals: Vec<DVec3>,
    /// Vertex texture coordinates; empty unless every vertex has one.
    pub uvs: Vec<DVec2>,
    /// Per face: position indices; normals and uv use the same indices
    /// (tobj's single-index mode).
    pub faces: Vec<[u32; 3]>,
}

/// An OBJ file read whole: its mesh and, per face, the `.mtl` material its
/// group uses (`usemtl`).
#[derive(Clone, Debug)]
pub struct ObjFile {
    /// All the file's models merged into one mesh, in world space.
    pub mesh: Mesh,
    /// Per face of `mesh`: an index into `materials`, if its group named one.
    pub face_materials: Vec<Option<usize>>,
    /// The materials of the file's `mtllib` libraries, as `tobj` parsed them.
    pub materials: Vec<tobj::Material>,
    /// Why the material libraries could not be read, when they could not.
    pub material_error: Option<String>,
}

impl Mesh {
    /// Loads every model in an OBJ file into one mesh, triangulating polygons.
    pub fn load_obj(path: &Path, transform: &Transform) -> Result<Self, String> {
        Ok(Self::load_obj_file(path, transform)?.mesh)
    }

    /// Loads an OBJ file with the `.mtl` materials its faces use. Vertex
    /// positions and normals must be finite. `mtllib` paths resolve against
    /// the OBJ file's folder and must be regular files too.
    pub fn load_obj_file(path: &Path, transform: &Transform) -> Result<ObjFile, String> {
        regular_file(path)?;
        let options = tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ignore_points: true,
            ignore_lines: true,
        };
        let folder = path.parent().unwrap_or(Path::new("."));
        let library_errors = std::cell::RefCell::new(Vec::new());
        let load_library = |library: &Path| {
            let full = folder.join(library);
            if let Err(e) = regular_file(&full) {
                library_errors.borrow_mut().push(e);
                return Err(tobj::LoadError::OpenFileFailed);
            }
            tobj::load_mtl(&full).inspect_err(|e| library_errors.borrow_mut().push(format!("{}: {e}", full.display())))
        };
        let file = std::fs::File::open(path).map_err(|e| format!("cannot open: {e}"))?;
        let mut reader = std::io::BufReader::new(file);
        let (models, materials) =
            tobj::load_obj_buf(&mut reader, &options, load_library).map_err(|e| format!("cannot read OBJ: {e}"))?;
        let (materials, material_error) = match materials {
            Ok(materials) => (materials, None),
            Err(e) => {
                let reasons = library_errors.into_inner();
                let reason = if reasons.is_empty() {
                    e.to_string()
                } else {
                    reasons.join("; ")
                };
                (Vec::new(), Some(reason))
            }
        };
        let mut mesh = Mesh::default();
        let mut face_materials = Vec::new();
        for model in &models {
            let m = &model.mesh;
            let base = mesh.positions.len() as u32;
            let vertex_count = m.positions.len() / 3;
            mesh.positions.extend(
                m.positions
                    .chunks_exact(3)
                    .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)),
            );
            let has_normals = m.normals.len() == m.positions.len();
            let has_uvs = m.texcoords.len() / 2 == vertex_count;
            if has_normals {
                mesh.normals.extend(
                    m.normals
                        .chunks_exact(3)
                        .map(|n| DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64)),
                );
            }
            if has_uvs {
                mesh.uvs
                    .extend(m.texcoords.chunks_exact(2).map(|t| DVec2::new(t[0] as f64, t[1] as f64)));
            }
            for face in m.indices.chunks_exact(3) {
                let f = [face[0] + base, face[1] + base, face[2] + base];
                if f.iter().any(|&i| i as usize >= mesh.positions.len()) {
                    return Err("a face refers to a vertex that does not exist".into());
                }
                mesh.faces.push(f);
                face_materials.push(m.material_id);
            }
        }
        // Attributes are kept only if every model supplied them.
        if mesh.normals.len() != mesh.positions.len() {
            mesh.normals.clear();
        }
        if mesh.uvs.len() != mesh.positions.len() {
            mesh.uvs.clear();
        }
        if mesh.faces.is_empty() {
            return Err("the OBJ file has no triangles".into());
        }
        if let Some(p) = mesh.positions.iter().find(|p| !p.is_finite()) {
            return Err(format!("a vertex position (v) is not finite: {p}"));
        }
        // Normals are read even when the mesh would be flat-shaded without
        // them; a NaN one would turn every shading frame it touches to NaN.
        let all_normals = models.iter().flat_map(|m| m.mesh.normals.chunks_exact(3));
        if let Some(n) = all_normals.into_iter().find(|n| n.iter().any(|c| !c.is_finite())) {
            return Err(format!("a vertex normal (vn) is not finite: [{}, {}, {}]", n[0], n[1], n[2]));
        }
        mesh.apply(transform);
        Ok(ObjFile {
            mesh,
            face_materials,
            materials,
            material_error,
        })
    }

    /// Moves the mesh into world space.
    pub fn apply(&mut self, transform: &Transform) {
        if transform.is_identity() {
            return;
        }
        for p in &mut self.positions {
            *p = transform.point(*p);
        }
        let normal_matrix = transform.normal_matrix();
        for n in &mut self.normals {
            *n = (normal_matrix * *n).normalize_or_zero();
        }
    }

    /// The mesh's triangles as primitives, tagged with `mesh_index`.
    /// Degenerate (zero-area) faces are dropped: they can never be hit.
    pub fn triangles(&self, mesh_index: u32) -> impl Iterator<Item = Triangle> + '_ {
        self.faces.iter().enumerate().filter_map(move |(face, f)| {
            let triangle = Triangle {
                vertices: f.map(|i| self.positions[i as usize]),
                mesh: mesh_index,
                face: face as u32,
            };
            (triangle.area() > 0.0).then_some(triangle)
        })
    }

    /// Interpolated shading normal (if the mesh has normals) and uv (the
    /// barycentric coordinates when it has none) at a point of a face.
    pub fn shading(&self, face: usize, barycentric: [f64; 3]) -> (Option<DVec3>, DVec2) {
        let barycentric_uv = DVec2::new(barycentric[1], barycentric[2]);
        if self.normals.is_empty() && self.uvs.is_empty() {
            // Neither needs the face's vertex indices, whose read costs
            // the hit a cache miss on a mesh larger than the caches.
            return (None, barycentric_uv);
        }
        let f = self.faces[face];
        let normal = (!self.normals.is_empty())
            .then(|| {
                let n = (0..3).map(|k| barycentric[k] * self.normals[f[k] as usize]).sum::<DVec3>();
                n.try_normalize()
            })
            .flatten();
        let uv = if self.uvs.is_empty() {
            barycentric_uv
        } else {
            (0..3).map(|k| barycentric[k] * self.uvs[f[k] as usize]).sum()
        };
        (normal, uv)
    }

    /// A mesh of explicit triangles (the scene file's `triangle` objects).
    pub fn from_triangles(triangles: &[[DVec3; 3]]) -> Self {
        let mut mesh = Mesh::default();
        for (i, t) in triangles.iter().enumerate() {
            mesh.positions.extend_from_slice(t);
            let base = 3 * i as u32;
            mesh.faces.push([base, base + 1, base + 2]);
        }
        mesh
    }
}
