//! The scene file as plain data: what the user wrote, before anything is
//! validated or built. Documented key by key in docs/scene-format.md. Where
//! each value was written is kept by the spanned document it was read from
//! (`scene::document`), not here.
//!
//! Objects and materials are read as serde's externally tagged enums: the
//! loader first rewrites each `type = "kind"` table into `{ kind = {...} }`
//! (`Document::retagged`), which keeps the spans an internally tagged enum
//! would lose.

use crate::settings::SettingsPatch;
use serde::Deserialize;
use std::collections::BTreeMap;

mod texture;
pub use texture::{ColorDescription, MappingKind, Numbers, TextureDescription, WrapKind};

/// A point, direction or linear RGB colour as written: `[x, y, z]`.
pub type Vector = [f64; 3];

/// A whole scene file. Keys are checked strictly (`deny_unknown_fields`):
/// a misspelt key is an error, not ignored.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDescription {
    /// The `[camera]` table.
    pub camera: CameraDescription,
    /// The `[render]` table: the same settings, checked the same way, as the
    /// command line's flags.
    #[serde(default)]
    pub render: SettingsPatch,
    /// Radiance of rays that escape the scene (linear RGB). Default black.
    #[serde(default)]
    pub background: Option<Vector>,
    /// The `[materials.NAME]` tables, by name; objects refer to them by name.
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialDescription>,
    /// The `[[objects]]` array, in file order.
    #[serde(default)]
    pub objects: Vec<ObjectDescription>,
}

/// The `[camera]` table; see [`crate::camera::Camera`] for the meaning of
/// each value. Lengths are in scene units.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDescription {
    /// Eye position.
    pub position: Vector,
    /// The point looked at (also the orbit centre in the viewer).
    pub look_at: Vector,
    /// Approximate up direction; default +y.
    #[serde(default = "default_up")]
    pub up: Vector,
    /// Vertical field of view in degrees; default 40.
    #[serde(default = "default_fov")]
    pub fov_y_degrees: f64,
    /// Lens radius; 0 (the default) is a pinhole.
    #[serde(default)]
    pub aperture_radius: f64,
    /// Distance to the plane in focus; default the distance to `look_at`.
    pub focal_distance: Option<f64>,
    /// Rays start this far along the view axis (default 0).
    #[serde(default)]
    pub near_clip: f64,
}

fn default_up() -> Vector {
    [0.0, 1.0, 0.0]
}

fn default_fov() -> f64 {
    40.0
}

/// A `[materials.NAME]` table, tagged by its `type`; see
/// [`crate::material::Material`] for each model.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum MaterialDescription {
    /// Lambertian reflection.
    Diffuse {
        /// Reflectance in [0, 1], a colour or texture.
        albedo: ColorDescription,
    },
    /// A perfect mirror.
    Mirror {
        /// Reflectance, a colour or texture; default white.
        #[serde(default = "white_texture")]
        tint: ColorDescription,
    },
    /// Smooth glass.
    Glass {
        /// Index of refraction inside over outside (positive); default 1.5,
        /// or the named glass's nd. With `abbe`, the index at the d line.
        ior: Option<f64>,
        /// A named dispersive glass: `BK7`, `fused-silica` or `SF11`.
        #[serde(default)]
        glass: Option<String>,
        /// Abbe number: makes the glass dispersive, n(λ) by Cauchy's law
        /// through `ior` (nd) and this.
        #[serde(default)]
        abbe: Option<f64>,
        /// Colour multiplying reflection and transmission; default white.
        #[serde(default = "white")]
        tint: Vector,
    },
    /// A rough conductor (GGX).
    Glossy {
        /// Reflectance at normal incidence, a colour or texture.
        tint: ColorDescription,
        /// GGX α in [0, 1].
        roughness: f64,
    },
    /// A light: an RGB `radiance`, or a spectrum (`spectrum` or
    /// `temperature`) scaled by `luminance`.
    Emissive {
        /// Emitted radiance, linear RGB.
        #[serde(default)]
        radiance: Option<Vector>,
        /// A named CIE standard illuminant: `D65` or `A`.
        #[serde(default)]
        spectrum: Option<String>,
        /// A blackbody's temperature, kelvin.
        #[serde(default)]
        temperature: Option<f64>,
        /// CIE Y of a `spectrum` or `temperature` emitter, relative to the
        /// film's white (that of `radiance = [1, 1, 1]`).
        #[serde(default)]
        luminance: Option<f64>,
        /// Emit from both faces; default false (front face only).
        #[serde(default)]
        two_sided: bool,
    },
}

fn white() -> Vector {
    [1.0; 3]
}

fn white_texture() -> ColorDescription {
    ColorDescription::Rgb(white())
}

/// Placement of a mesh: scale, then rotate (degrees about x, y, z), then translate.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransformDescription {
    /// Translation; default none.
    #[serde(default)]
    pub translate: Option<Vector>,
    /// Euler angles in degrees, applied about x, then y, then z; default
    /// none.
    #[serde(default)]
    pub rotate_degrees: Option<Vector>,
    /// Scale factor(s), non-zero; default 1.
    #[serde(default)]
    pub scale: Option<Scale>,
}

/// A `scale` value: one factor, or one per axis.
#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(untagged)]
pub enum Scale {
    /// The same factor on every axis.
    Uniform(f64),
    /// Factors for x, y and z.
    PerAxis(Vector),
}

/// One `[[objects]]` entry, tagged by its `type`. Coordinates are world
/// space, except a mesh's and a revolution's, which their `transform`
/// places.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum ObjectDescription {
    /// A sphere.
    Sphere {
        /// Centre.
        center: Vector,
        /// Radius, positive.
        radius: f64,
        /// The material's name.
        material: String,
    },
    /// A solid axis-aligned box.
    Box {
        /// The corner of least coordinates.
        min: Vector,
        /// The opposite corner; greater than `min` on every axis.
        max: Vector,
        /// The material's name.
        material: String,
    },
    /// A parallelogram `corner + a·edge_u + b·edge_v`, a, b in [0, 1]; its
    /// normal (the side a one-sided light emits to) is `edge_u × edge_v`.
    Quad {
        /// The corner where a = b = 0.
        corner: Vector,
        /// One side; u runs along it.
        edge_u: Vector,
        /// The other side; v runs along it. Not parallel to `edge_u`.
        edge_v: Vector,
        /// The material's name.
        material: String,
    },
    /// A single triangle.
    Triangle {
        /// Its corners; counter-clockwise seen from the front.
        vertices: [Vector; 3],
        /// The material's name.
        material: String,
    },
    /// A triangle mesh from a Wavefront OBJ file.
    Mesh {
        /// The OBJ file, relative to the scene file's folder.
        file: String,
        /// The scene's material for every face; if omitted, the faces take
        /// the materials of the OBJ file's `.mtl` library.
        #[serde(default)]
        material: Option<String>,
        /// Placement of the mesh (applied to its vertices when loaded).
        #[serde(default)]
        transform: TransformDescription,
    },
    /// A Bezier profile swept about the object's vertical (y) axis: each
    /// control point is [distance from the axis, height].
    Revolution {
        /// One Bezier segment's control points `[[x, y], ...]`, or use `segments`.
        #[serde(default)]
        profile: Option<Vec<[f64; 2]>>,
        /// A chain of segments, each its own control points.
        #[serde(default)]
        segments: Option<Vec<Vec<[f64; 2]>>>,
        /// Close the ends with flat discs.
        #[serde(default)]
        caps: bool,
        /// The material's name.
        material: String,
        /// Placement of the swept surface.
        #[serde(default)]
        transform: TransformDescription,
    },
}

impl ObjectDescription {
    /// The scene material the object names; `None` for a mesh that takes
    /// its materials from its `.mtl` library.
    pub fn material(&self) -> Option<&str> {
        match self {
            ObjectDescription::Sphere { material, .. }
            | ObjectDescription::Box { material, .. }
            | ObjectDescription::Quad { material, .. }
            | ObjectDescription::Triangle { material, .. }
            | ObjectDescription::Revolution { material, .. } => Some(material),
            ObjectDescription::Mesh { material, .. } => material.as_deref(),
        }
    }
}
