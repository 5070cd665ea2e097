//! Numerical stress: scenes at the edges of floating-point range, rendered
//! and probed, counting what must never happen.
//!
//! - NaN or infinite samples: the film drops and counts them
//!   (`Integrator::rejected_samples`); must be 0.
//! - Self-intersections: a ray spawned from a hit point (either side, as
//!   reflection and refraction do) that hits the same primitive again within
//!   10⁻⁶ of that primitive's size. A correct offset (pbrt-v4 §6.8.6) leaves
//!   only legitimate re-hits, which lie at distances of the order of the
//!   primitive's size (the far side of a sphere); the chance that a
//!   cosine-distributed ray re-hits legitimately that close is ~10⁻⁶.
//! - Leaks: rays aimed exactly at the vertices and edge midpoints of a closed
//!   mesh (where a non-watertight triangle test misses both neighbours), from
//!   inside and from outside, that hit nothing.
//!
//! The scenes (`stress_scenes`) are files in `scenes/stress/`, each placed by
//! one or more similarities (`scene::Similarity`): the Cornell box scaled to
//! 10⁻⁴ and to 10⁵ units and moved 10⁵ from the origin; smallpt's room of
//! radius-10⁵ spheres; light grazing a floor; glass nested in glass with
//! nearly coincident surfaces; Bezier surfaces of revolution (glass and
//! diffuse vases) at unit scale, 10⁻⁴ and 10⁵ from the origin. Disagreements
//! of the revolution intersector with an independent reference are counted
//! by `tests/revolution_stress.rs`.

use super::scaling::sphere_mesh;
use super::{BenchError, Csv};
use crate::camera::Camera;
use crate::geometry::{Mesh, SurfaceHit, Transform};
use crate::math::{Frame as LocalFrame, Ray, warp};
use crate::render::render_to_completion;
use crate::sampler::{Sampler, SamplerKind};
use crate::scene::{LoadedScene, Scene, SceneError, Similarity, load_scene_str_placed};
use crate::settings::{IntegratorKind, RenderSettings, SppmSettings};
use glam::DVec3;
use std::path::{Path, PathBuf};

/// A re-hit of the same primitive nearer than this fraction of its size is a self-intersection.
pub const SELF_HIT_FRACTION: f64 = 1e-6;

/// How hard to push.
#[derive(Clone, Debug)]
pub struct StressOptions {
    /// Image width of the NaN/inf renders, in pixels.
    pub width: u32,
    /// Image height of the NaN/inf renders, in pixels.
    pub height: u32,
    /// Passes rendered per integrator.
    pub passes: u32,
    /// Probe rays per scene (self-intersections) and per mesh (leaks).
    pub rays: u64,
    /// A closed OBJ mesh to test for leaks as well (the shipped bunny).
    pub closed_mesh: Option<PathBuf>,
    /// SPPM photons per pass (once SPPM exists), kept small for fast runs.
    pub photons_per_iteration: u32,
}

/// One count: in `scene`, `failures` of `tested` did what must not happen.
#[derive(Clone, Debug, PartialEq)]
pub struct StressRow {
    /// The stress scene (or mesh) tested.
    pub scene: String,
    /// What was counted, e.g. `self-intersections`.
    pub check: String,
    /// Samples or probe rays tested.
    pub tested: u64,
    /// How many of them failed; anything but 0 is a defect.
    pub failures: u64,
}

/// The text of a scene file under `scenes/stress/`, with its path from the
/// crate root; compiled in, so `prism bench --stress` runs from anywhere.
macro_rules! stress_scene_file {
    ($name:literal) => {
        (
            concat!("scenes/stress/", $name),
            include_str!(concat!("../../scenes/stress/", $name)),
        )
    };
}

/// One extreme scene: a file under `scenes/stress/`, placed by a similarity
/// (every length scaled by `scale`, then everything moved by `offset` along
/// each axis).
#[derive(Clone, Copy, Debug)]
pub struct StressScene {
    /// Short name, for tables.
    pub name: &'static str,
    /// Path from the crate root; names the scene in errors.
    pub file: &'static str,
    text: &'static str,
    /// Factor applied to every length of the scene.
    pub scale: f64,
    /// Distance the scaled scene is moved along each axis.
    pub offset: f64,
}

impl StressScene {
    fn new(name: &'static str, (file, text): (&'static str, &'static str), scale: f64, offset: f64) -> Self {
        Self {
            name,
            file,
            text,
            scale,
            offset,
        }
    }

    /// The scene file, placed.
    pub fn load(&self) -> Result<LoadedScene, SceneError> {
        let placement = Similarity::new(self.scale, DVec3::splat(self.offset)).ok_or_else(|| {
            SceneError::new(
                self.file,
                None,
                None,
                format!(
                    "{}: scale {} and offset {} do not make a placement",
                    self.name, self.scale, self.offset
                ),
            )
        })?;
        load_scene_str_placed(self.text, Path::new(self.file), Path::new("."), &placement)
    }
}

/// The extreme scenes: the Cornell box (555 units across in its file) shrunk
/// to 10⁻⁴, grown to 10⁵ and, at unit size, moved 10⁵ from the origin;
/// smallpt's room of radius-10⁵ spheres; light grazing a floor; glass nested
/// in glass with nearly coincident surfaces; two Bezier vases (surfaces of
/// revolution, 7.5 units tall) at unit scale, shrunk 16·10⁴ times, and moved
/// 10⁵ from the origin.
pub fn stress_scenes() -> Vec<StressScene> {
    let cornell = stress_scene_file!("cornell.toml");
    let vase = stress_scene_file!("vase.toml");
    vec![
        StressScene::new("cornell-tiny-1e-4", cornell, 1e-4 / 555.0, 0.0),
        StressScene::new("cornell-huge-1e5", cornell, 1e5 / 555.0, 0.0),
        StressScene::new("cornell-far-1e5-from-origin", cornell, 1.0 / 555.0, 1e5),
        StressScene::new("smallpt-1e5-radius-walls", stress_scene_file!("smallpt.toml"), 1.0, 0.0),
        StressScene::new("grazing-light", stress_scene_file!("grazing.toml"), 1.0, 0.0),
        StressScene::new("nested-glass", stress_scene_file!("nested-glass.toml"), 1.0, 0.0),
        StressScene::new("vase-revolution", vase, 1.0, 0.0),
        StressScene::new("vase-revolution-tiny-1e-4", vase, 1e-4 / 16.0, 0.0),
        StressScene::new("vase-revolution-far-1e5-from-origin", vase, 1.0, 1e5),
    ]
}

/// Renders `passes` passes and returns (samples, rejected NaN/inf samples).
pub fn rejected_samples(loaded: &LoadedScene, kind: IntegratorKind, options: &StressOptions) -> (u64, u64) {
    let settings = RenderSettings {
        width: options.width,
        height: options.height,
        integrator: kind,
        samples_per_pixel: Some(options.passes),
        time_limit: None,
        adaptive_threshold: None,
        sppm: SppmSettings {
            photons_per_iteration: options.photons_per_iteration,
            ..loaded.settings.sppm
        },
        ..loaded.settings.clone()
    };
    let integrator = render_to_completion(&loaded.scene, &loaded.camera, &settings);
    (
        integrator.passes() as u64 * settings.pixel_count() as u64,
        integrator.rejected_samples(),
    )
}

/// Random walks from the camera (a primary ray through a uniform point of
/// the film, then four bounces cosine-weighted about either side of each
/// hit's geometric normal), each continuation made by `Ray::spawn`: returns
/// (spawned rays, self-intersections).
pub fn self_intersections(scene: &Scene, camera: &Camera, rays: u64) -> (u64, u64) {
    self_intersections_with(scene, camera, rays, |hit, direction| {
        Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, direction)
    })
}

/// [`self_intersections`] with continuation rays made by `spawn(hit, direction)`
/// (tests use a naive spawn to show the count can fail).
pub fn self_intersections_with(
    scene: &Scene,
    camera: &Camera,
    rays: u64,
    spawn: impl Fn(&SurfaceHit, DVec3) -> Ray,
) -> (u64, u64) {
    let (mut spawned, mut self_hits) = (0, 0);
    for i in 0..rays {
        let mut sampler = Sampler::new(SamplerKind::Random, i, 0, 11);
        let mut ray = camera.generate_ray(sampler.next_2d(), 1.0, sampler.next_2d());
        let Some(mut hit) = scene.intersect(&ray, f64::INFINITY) else {
            continue;
        };
        for _bounce in 0..4 {
            let side = if sampler.next_1d() < 0.5 { 1.0 } else { -1.0 };
            let normal = side * hit.hit.geometric_normal;
            let direction = LocalFrame::from_normal(normal).to_world(warp::square_to_cosine_hemisphere(sampler.next_2d()));
            ray = spawn(&hit.hit, direction);
            spawned += 1;
            let Some(next) = scene.intersect(&ray, f64::INFINITY) else {
                break;
            };
            let size = scene.primitive_bounds(hit.primitive).extent().length();
            if next.primitive == hit.primitive && next.hit.t < SELF_HIT_FRACTION * size {
                self_hits += 1;
            }
            hit = next;
        }
    }
    (spawned, self_hits)
}

/// Probe rays aimed exactly at a closed mesh's vertices and edge midpoints,
/// where a triangle test that is not watertight lets rays slip between
/// neighbours: from outside along the surface normal there (only where every
/// adjacent face faces that ray, so the ray must enter the surface: near the
/// silhouette a ray may legitimately graze past a vertex), and, when a point
/// `inside` is given, from there at the targets and in uniform directions
/// (everything leaving an interior point must hit). Returns (rays, leaks).
pub fn leaks(mesh: &Mesh, inside: Option<DVec3>, rays: u64) -> (u64, u64) {
    let targets = entry_targets(mesh);
    if targets.is_empty() {
        return (0, 0);
    }
    let extent = crate::math::Aabb::from_points(&mesh.positions).extent().length();
    let scene = Scene::from_mesh(mesh.clone());
    let (mut tested, mut leaked) = (0, 0);
    for i in 0..rays {
        let mut sampler = Sampler::new(SamplerKind::Random, i, 0, 13);
        let (target, normal) = targets[(sampler.next_1d() * targets.len() as f64) as usize % targets.len()];
        let (origin, direction) = match inside {
            Some(point) if i % 3 == 1 => (point, target - point),
            Some(point) if i % 3 == 2 => (point, warp::square_to_uniform_sphere(sampler.next_2d())),
            _ => (target + extent * normal, -normal),
        };
        if direction.length_squared() == 0.0 {
            continue;
        }
        tested += 1;
        if scene.intersect(&Ray::new(origin, direction), f64::INFINITY).is_none() {
            leaked += 1;
        }
    }
    (tested, leaked)
}

/// Vertices and edge midpoints with the unit normal a ray must come along to
/// enter there: the sum of the adjacent faces' normals, kept only where each
/// adjacent face has a normal within ~84° of it (the fan seen along it is not folded).
fn entry_targets(mesh: &Mesh) -> Vec<(DVec3, DVec3)> {
    let face_normal = |f: &[u32; 3]| {
        let [a, b, c] = f.map(|i| mesh.positions[i as usize]);
        (b - a).cross(c - a).normalize_or_zero()
    };
    let mut vertex_faces: Vec<Vec<DVec3>> = vec![Vec::new(); mesh.positions.len()];
    let mut edge_faces: std::collections::HashMap<(u32, u32), Vec<DVec3>> = std::collections::HashMap::new();
    for face in &mesh.faces {
        let n = face_normal(face);
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            vertex_faces[a as usize].push(n);
            edge_faces.entry((a.min(b), a.max(b))).or_default().push(n);
        }
    }
    let unfolded = |normals: &[DVec3]| {
        let sum: DVec3 = normals.iter().sum();
        let n = sum.normalize_or_zero();
        (n != DVec3::ZERO && normals.iter().all(|m| m.dot(n) > 0.1)).then_some(n)
    };
    let mut targets = Vec::new();
    for (v, normals) in vertex_faces.iter().enumerate() {
        if let Some(n) = unfolded(normals) {
            targets.push((mesh.positions[v], n));
        }
    }
    for (&(a, b), normals) in &edge_faces {
        if let Some(n) = unfolded(normals) {
            targets.push(((mesh.positions[a as usize] + mesh.positions[b as usize]) * 0.5, n));
        }
    }
    // HashMap order is random: sort so runs are reproducible.
    targets.sort_by(|x, y| {
        x.0.to_array()
            .partial_cmp(&y.0.to_array())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    targets
}

/// The closed meshes the leak test uses: spheres at the same extremes as the
/// scenes, and `closed_mesh` (an OBJ) when given. Each with a point inside, if known.
fn closed_meshes(options: &StressOptions) -> Result<Vec<(String, Mesh, Option<DVec3>)>, BenchError> {
    let mut meshes = Vec::new();
    for (name, center, radius) in [
        ("sphere-mesh-radius-1e-4", DVec3::ZERO, 1e-4),
        ("sphere-mesh-radius-1e5", DVec3::ZERO, 1e5),
        ("sphere-mesh-1e5-from-origin", DVec3::splat(1e5), 1.0),
        ("tiny-sphere-mesh-1e5-from-origin", DVec3::splat(1e5), 1e-4),
    ] {
        meshes.push((name.to_string(), sphere_mesh(2000, center, radius), Some(center)));
    }
    if let Some(path) = &options.closed_mesh {
        // Leaks do not depend on winding or normals: the file is used as is.
        let mesh = Mesh::load_obj(path, &Transform::default()).map_err(BenchError::Reference)?;
        let name = path.file_stem().map_or("mesh".into(), |s| s.to_string_lossy().to_string());
        meshes.push((format!("{name}-obj"), mesh, None));
    }
    Ok(meshes)
}

/// Runs every check on every scene, calling `progress` per row.
pub fn run(options: &StressOptions, mut progress: impl FnMut(&StressRow)) -> Result<Vec<StressRow>, BenchError> {
    let mut rows = Vec::new();
    let mut push = |row: StressRow, rows: &mut Vec<StressRow>| {
        progress(&row);
        rows.push(row);
    };
    for stress_scene in stress_scenes() {
        let name = stress_scene.name;
        let loaded = stress_scene.load()?;
        for kind in IntegratorKind::ALL {
            let (samples, rejected) = rejected_samples(&loaded, kind, options);
            let row = StressRow {
                scene: name.into(),
                check: format!("NaN/inf samples ({kind})"),
                tested: samples,
                failures: rejected,
            };
            push(row, &mut rows);
        }
        let (spawned, self_hits) = self_intersections(&loaded.scene, &loaded.camera, options.rays);
        push(
            StressRow {
                scene: name.into(),
                check: "self-intersections".into(),
                tested: spawned,
                failures: self_hits,
            },
            &mut rows,
        );
    }
    for (name, mesh, inside) in closed_meshes(options)? {
        let (tested, leaked) = leaks(&mesh, inside, options.rays);
        push(
            StressRow {
                scene: name,
                check: "leaks through closed mesh".into(),
                tested,
                failures: leaked,
            },
            &mut rows,
        );
    }
    Ok(rows)
}

/// Writes the counts as CSV.
pub fn write_results(rows: &[StressRow], options: &StressOptions, machine: &str, path: &Path) -> Result<(), BenchError> {
    let mut csv = Csv::new(vec!["scene", "check", "tested", "failures"]);
    csv.comments.push(format!(
        "prism bench --stress: {}x{} pixels, {} passes per integrator, {} probe rays per scene or mesh",
        options.width, options.height, options.passes, options.rays
    ));
    csv.comments
        .push("Bezier intersection disagreements: counted by tests/revolution_stress.rs, not here".into());
    csv.comments.push(machine.to_string());
    for r in rows {
        csv.rows.push(vec![
            r.scene.clone(),
            r.check.clone(),
            r.tested.to_string(),
            r.failures.to_string(),
        ]);
    }
    csv.write(path)
}
