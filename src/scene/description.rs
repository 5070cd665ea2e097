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

pub type Vector = [f64; 3];

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDescription {
    pub camera: CameraDescription,
    /// The `[render]` table: the same settings, checked the same way, as the
    /// command line's flags.
    #[serde(default)]
    pub render: SettingsPatch,
    /// Radiance of rays that escape the scene (linear RGB). Default black.
    #[serde(default)]
    pub background: Option<Vector>,
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialDescription>,
    #[serde(default)]
    pub objects: Vec<ObjectDescription>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDescription {
    pub position: Vector,
    pub look_at: Vector,
    #[serde(default = "default_up")]
    pub up: Vector,
    #[serde(default = "default_fov")]
    pub fov_y_degrees: f64,
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

#[derive(Debug, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum MaterialDescription {
    Diffuse {
        albedo: ColorDescription,
    },
    Mirror {
        #[serde(default = "white_texture")]
        tint: ColorDescription,
    },
    Glass {
        #[serde(default = "default_ior")]
        ior: f64,
        #[serde(default = "white")]
        tint: Vector,
    },
    Glossy {
        tint: ColorDescription,
        roughness: f64,
    },
    Emissive {
        radiance: Vector,
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

fn default_ior() -> f64 {
    1.5
}

/// Placement of a mesh: scale, then rotate (degrees about x, y, z), then translate.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransformDescription {
    #[serde(default)]
    pub translate: Option<Vector>,
    #[serde(default)]
    pub rotate_degrees: Option<Vector>,
    #[serde(default)]
    pub scale: Option<Scale>,
}

#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(untagged)]
pub enum Scale {
    Uniform(f64),
    PerAxis(Vector),
}

#[derive(Debug, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum ObjectDescription {
    Sphere {
        center: Vector,
        radius: f64,
        material: String,
    },
    Box {
        min: Vector,
        max: Vector,
        material: String,
    },
    Quad {
        corner: Vector,
        edge_u: Vector,
        edge_v: Vector,
        material: String,
    },
    Triangle {
        vertices: [Vector; 3],
        material: String,
    },
    Mesh {
        file: String,
        /// The scene's material for every face; if omitted, the faces take
        /// the materials of the OBJ file's `.mtl` library.
        #[serde(default)]
        material: Option<String>,
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
        material: String,
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
