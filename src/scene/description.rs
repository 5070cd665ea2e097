//! The scene file as plain data: what the user wrote, with source spans, before
//! anything is validated or built. Documented key by key in docs/scene-format.md.

use crate::sampler::SamplerKind;
use crate::settings::IntegratorKind;
use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

mod texture;
pub use texture::{ColorDescription, MappingKind, Numbers, TextureDescription, WrapKind};

pub type Vector = [f64; 3];

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDescription {
    pub camera: CameraDescription,
    #[serde(default)]
    pub render: RenderDescription,
    /// Radiance of rays that escape the scene (linear RGB). Default black.
    #[serde(default)]
    pub background: Option<Spanned<Vector>>,
    #[serde(default)]
    pub materials: BTreeMap<String, Spanned<MaterialDescription>>,
    #[serde(default)]
    pub objects: Vec<Spanned<ObjectDescription>>,
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

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderDescription {
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub spp: Option<u32>,
    pub max_depth: Option<u32>,
    pub integrator: Option<IntegratorKind>,
    pub sampler: Option<SamplerKind>,
    pub seed: Option<u64>,
    pub photons_per_iteration: Option<u32>,
    pub initial_radius: Option<f64>,
    pub alpha: Option<f64>,
    /// Relative standard error at which a pixel stops taking samples.
    pub adaptive_threshold: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
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
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
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
        material: String,
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
    pub fn material(&self) -> &str {
        match self {
            ObjectDescription::Sphere { material, .. }
            | ObjectDescription::Box { material, .. }
            | ObjectDescription::Quad { material, .. }
            | ObjectDescription::Triangle { material, .. }
            | ObjectDescription::Mesh { material, .. }
            | ObjectDescription::Revolution { material, .. } => material,
        }
    }
}
