//! `prism bench --rays`: the ray core measured on its own, the way ray
//! tracing kernels are compared (Embree, tinybvh): the Stanford bunny, the
//! bunny subdivided twice (each triangle split in four at its edge
//! midpoints, ×16) and four times (×256); two sets of rays:
//!
//! - *primary*: a pinhole image of the mesh, 1024 × 1024 rays in scanline
//!   order (coherent: neighbours visit the same nodes);
//! - *incoherent*: origins uniform on the bounding sphere, aimed at uniform
//!   points inside the bounding box (every ray goes its own way);
//!
//! and three queries: *closest* (`Scene::intersect`, the nearest hit and
//! its hit record, as the renderer asks), *distance*
//! (`Scene::nearest_distance`, the nearest hit's distance and primitive
//! alone: the work of a kernel's closest-hit query such as Embree's
//! `rtcIntersect1`) on both sets, and *occlusion* (any hit) on the
//! incoherent rays.
//!
//! Rays are single-precision values (origins and directions rounded to
//! `f32`) so that a peer that takes `f32` rays traces exactly the same
//! ones; `--export-rays` writes meshes, rays and Prism's answers for such a
//! comparison (see `benches/peers/embree_rays.py`).

use super::plot::{LinePlot, Series};
use super::{BenchError, Csv, format_number};
use crate::accel::{BuildPrimitive, Bvh};
use crate::geometry::Mesh;
use crate::math::Ray;
use crate::sampler::{Sampler, SamplerKind};
use crate::scene::Scene;
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use std::collections::HashMap;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// Side of the primary-ray image.
const PRIMARY_SIDE: u32 = 1024;
/// Incoherent rays per mesh.
pub const INCOHERENT_RAYS: usize = 1 << 20;

/// Splits every triangle into four at its edge midpoints, each midpoint
/// shared by the two faces of its edge (so a closed mesh stays closed).
pub fn subdivide(mesh: &Mesh) -> Mesh {
    let mut out = Mesh {
        positions: mesh.positions.clone(),
        ..Mesh::default()
    };
    let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
    let mut midpoint = |a: u32, b: u32, positions: &mut Vec<DVec3>| -> u32 {
        let key = (a.min(b), a.max(b));
        *midpoints.entry(key).or_insert_with(|| {
            positions.push(0.5 * (positions[a as usize] + positions[b as usize]));
            (positions.len() - 1) as u32
        })
    };
    for &[a, b, c] in &mesh.faces {
        let ab = midpoint(a, b, &mut out.positions);
        let bc = midpoint(b, c, &mut out.positions);
        let ca = midpoint(c, a, &mut out.positions);
        out.faces
            .extend_from_slice(&[[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    out
}

/// The three meshes of the benchmark: `bunny` and its subdivisions.
pub fn benchmark_meshes(bunny: Mesh) -> Vec<(String, Mesh)> {
    let twice = subdivide(&subdivide(&bunny));
    let four_times = subdivide(&subdivide(&twice));
    vec![
        ("bunny".to_string(), bunny),
        ("bunny-x16".to_string(), twice),
        ("bunny-x256".to_string(), four_times),
    ]
}

/// A ray whose origin and direction are `f32` values.
fn single_precision_ray(origin: DVec3, direction: DVec3) -> Ray {
    Ray {
        origin: origin.as_vec3().as_dvec3(),
        direction: direction.normalize().as_vec3().as_dvec3(),
    }
}

/// A pinhole image of a scene's bounds: the camera looks at the centre from
/// 2.5 bounding radii away along +z, with a field of view that frames the
/// bounding sphere; rays in scanline order.
pub fn primary_rays(scene: &Scene) -> Vec<Ray> {
    let bounds = scene.bounds();
    let (center, radius) = (bounds.centroid(), 0.5 * bounds.extent().length());
    let eye = center + DVec3::new(0.0, 0.0, 2.5 * radius);
    let half_width = (radius / (2.5 * radius)).tan().max(1e-6) * 1.1;
    let side = PRIMARY_SIDE as f64;
    (0..PRIMARY_SIDE * PRIMARY_SIDE)
        .map(|i| {
            let (x, y) = ((i % PRIMARY_SIDE) as f64 + 0.5, (i / PRIMARY_SIDE) as f64 + 0.5);
            let film = DVec2::new(2.0 * x / side - 1.0, 1.0 - 2.0 * y / side) * half_width;
            single_precision_ray(eye, DVec3::new(film.x, film.y, -1.0))
        })
        .collect()
}

/// Origins uniform on the bounding sphere, aimed at uniform points in the
/// bounding box (a fixed stream of independent samples).
pub fn incoherent_rays(scene: &Scene, count: usize) -> Vec<Ray> {
    let bounds = scene.bounds();
    let (center, radius) = (bounds.centroid(), 0.5 * bounds.extent().length());
    (0..count as u64)
        .map(|i| {
            let mut sampler = Sampler::new(SamplerKind::Random, i, 0, 0x5eed_4a75);
            let on_sphere = crate::math::warp::square_to_uniform_sphere(sampler.next_2d());
            let u = sampler.next_2d();
            let target = bounds.min + bounds.extent() * DVec3::new(u.x, u.y, sampler.next_1d());
            let origin = center + radius * on_sphere;
            single_precision_ray(origin, target - origin)
        })
        .collect()
}

/// One measured combination.
#[derive(Clone, Debug)]
pub struct RayRow {
    /// Mesh name (`bunny`, `bunny-x16`, `bunny-x256`).
    pub mesh: String,
    /// Triangles in the mesh.
    pub triangles: usize,
    /// Which ray set: `primary` or `incoherent`.
    pub rays: String,
    /// `closest` (nearest hit) or `occlusion` (any hit).
    pub query: &'static str,
    /// Worker threads (1 or 2).
    pub threads: usize,
    /// Millions of rays per second of wall time, best of the repetitions.
    pub mrays_per_second: f64,
    /// Share of the rays that hit something, 0 to 1.
    pub hit_fraction: f64,
}

/// Build cost and size of one mesh's acceleration structure.
#[derive(Clone, Debug)]
pub struct BuildRow {
    /// Mesh name.
    pub mesh: String,
    /// Triangles in the mesh.
    pub triangles: usize,
    /// Best of a few single-threaded builds of the BVH over the triangles' boxes.
    pub build_ms_one_thread: f64,
    /// As `build_ms_one_thread`, on two threads.
    pub build_ms_two_threads: f64,
    /// Eight-wide nodes of the BVH.
    pub nodes: usize,
    /// Leaves of the BVH.
    pub leaves: usize,
    /// Nodes plus the triangles' leaf data, per triangle.
    pub bytes_per_triangle: f64,
}

/// Times `query` over `rays` on `pool`: the best of `repetitions` runs
/// (the machine is shared; the best run is the least disturbed).
fn time_rays(pool: &rayon::ThreadPool, rays: &[Ray], repetitions: usize, query: impl Fn(&Ray) -> bool + Sync) -> (f64, f64) {
    let mut best = f64::INFINITY;
    let mut hits = 0;
    for _ in 0..repetitions {
        let start = Instant::now();
        hits = pool.install(|| {
            // One chunk per job, as benches/peers/embree_rays.py deals them
            // to its threads (see `integrator::pass` for rayon's default).
            rays.par_chunks(4096)
                .with_max_len(1)
                .map(|chunk| chunk.iter().filter(|r| query(r)).count())
                .sum::<usize>()
        });
        best = best.min(start.elapsed().as_secs_f64());
    }
    (rays.len() as f64 / best / 1e6, hits as f64 / rays.len().max(1) as f64)
}

/// Measures every mesh: build (1 and 2 threads), then closest-hit (with and
/// without the hit record) on the primary and incoherent rays and occlusion
/// on the incoherent ones, on 1 and 2 threads.
pub fn measure(
    meshes: &[(String, Mesh)],
    repetitions: usize,
    mut progress: impl FnMut(&str),
) -> Result<(Vec<BuildRow>, Vec<RayRow>), BenchError> {
    let pools = [
        rayon::ThreadPoolBuilder::new().num_threads(1).build()?,
        rayon::ThreadPoolBuilder::new().num_threads(2).build()?,
    ];
    let mut builds = Vec::new();
    let mut rows = Vec::new();
    for (name, mesh) in meshes {
        let scene = Scene::from_mesh(mesh.clone());
        let triangles = scene.primitive_count();
        let build_primitives: Vec<BuildPrimitive> = (0..triangles as u32)
            .map(|primitive| BuildPrimitive {
                bounds: scene.primitive_bounds(primitive),
                kind: 0,
            })
            .collect();
        let build_ms = |pool: &rayon::ThreadPool| {
            (0..repetitions.max(3))
                .map(|_| {
                    let start = Instant::now();
                    let bvh = pool.install(|| Bvh::build(&build_primitives));
                    std::hint::black_box(bvh);
                    start.elapsed().as_secs_f64() * 1e3
                })
                .fold(f64::INFINITY, f64::min)
        };
        let build = BuildRow {
            mesh: name.clone(),
            triangles,
            build_ms_one_thread: build_ms(&pools[0]),
            build_ms_two_threads: build_ms(&pools[1]),
            nodes: scene.bvh().node_count(),
            leaves: scene.bvh().leaf_count(),
            bytes_per_triangle: scene.acceleration_bytes() as f64 / triangles.max(1) as f64,
        };
        progress(&format!(
            "{name}: {triangles} triangles, build {:.1} ms (1 thread) / {:.1} ms (2 threads), {:.1} bytes per triangle",
            build.build_ms_one_thread, build.build_ms_two_threads, build.bytes_per_triangle
        ));
        builds.push(build);

        let primary = primary_rays(&scene);
        let incoherent = incoherent_rays(&scene, INCOHERENT_RAYS);
        let cases: [(&str, &[Ray], &'static str); 5] = [
            ("primary", &primary, "closest"),
            ("primary", &primary, "distance"),
            ("incoherent", &incoherent, "closest"),
            ("incoherent", &incoherent, "distance"),
            ("incoherent", &incoherent, "occlusion"),
        ];
        for (set, rays, query) in cases {
            for (pool, threads) in pools.iter().zip([1, 2]) {
                let (mrays_per_second, hit_fraction) = match query {
                    "closest" => time_rays(pool, rays, repetitions, |r| scene.intersect(r, f64::INFINITY).is_some()),
                    "distance" => time_rays(pool, rays, repetitions, |r| {
                        scene.nearest_distance(r, f64::INFINITY).is_some()
                    }),
                    _ => time_rays(pool, rays, repetitions, |r| scene.occluded(r, f64::INFINITY)),
                };
                progress(&format!(
                    "  {set:<10} {query:<9} {threads} thread(s): {mrays_per_second:6.2} Mrays/s ({:.0}% hit)",
                    100.0 * hit_fraction
                ));
                rows.push(RayRow {
                    mesh: name.clone(),
                    triangles,
                    rays: set.to_string(),
                    query,
                    threads,
                    mrays_per_second,
                    hit_fraction,
                });
            }
        }
    }
    Ok((builds, rows))
}

/// Writes `rays.csv`, `rays_build.csv` and `rays.png` into `directory`.
pub fn write_results(builds: &[BuildRow], rows: &[RayRow], machine: &str, directory: &Path) -> Result<(), BenchError> {
    let mut csv = Csv::new(vec![
        "mesh",
        "triangles",
        "rays",
        "query",
        "threads",
        "mrays_per_second",
        "hit_fraction",
    ]);
    csv.comments
        .push("prism bench --rays: best of repeated runs, wall time".into());
    csv.comments.push(machine.to_string());
    for r in rows {
        csv.rows.push(vec![
            r.mesh.clone(),
            r.triangles.to_string(),
            r.rays.clone(),
            r.query.to_string(),
            r.threads.to_string(),
            format_number(r.mrays_per_second),
            format!("{:.4}", r.hit_fraction),
        ]);
    }
    csv.write(&directory.join("rays.csv"))?;

    let mut build_csv = Csv::new(vec![
        "mesh",
        "triangles",
        "build_ms_1_thread",
        "build_ms_2_threads",
        "nodes",
        "leaves",
        "bytes_per_triangle",
    ]);
    build_csv
        .comments
        .push("prism bench --rays: BVH build (best of repeated builds) and size".into());
    build_csv.comments.push(machine.to_string());
    for b in builds {
        build_csv.rows.push(vec![
            b.mesh.clone(),
            b.triangles.to_string(),
            format!("{:.3}", b.build_ms_one_thread),
            format!("{:.3}", b.build_ms_two_threads),
            b.nodes.to_string(),
            b.leaves.to_string(),
            format!("{:.1}", b.bytes_per_triangle),
        ]);
    }
    build_csv.write(&directory.join("rays_build.csv"))?;

    let mut series = Vec::new();
    for (set, query) in [("primary", "closest"), ("incoherent", "closest"), ("incoherent", "occlusion")] {
        for threads in [1, 2] {
            series.push(Series {
                name: format!("{set} {query}, {threads} thread(s)"),
                points: rows
                    .iter()
                    .filter(|r| r.rays == set && r.query == query && r.threads == threads)
                    .map(|r| (r.triangles as f64, r.mrays_per_second))
                    .collect(),
                guide: false,
            });
        }
    }
    LinePlot {
        title: "Ray queries against triangle count (bunny, subdivided)".into(),
        x_label: "triangles".into(),
        y_label: "Mrays/s".into(),
        log_x: true,
        log_y: true,
        series,
    }
    .write_png(&directory.join("rays.png"))
}

/// Writes each mesh (`NAME.vertices.f32`: x y z per vertex, as stored;
/// `NAME.faces.u32`), each ray set (`NAME-SET.rays.f32`: origin and
/// direction per ray), Prism's closest-hit answers (`NAME-SET.prism.f64`:
/// face index, or −1, and distance per ray) and its occlusion answers
/// (`NAME-SET.prism-occluded.u8`: 1 where `occluded` finds a hit), all
/// little-endian, for a peer to trace and compare.
///
/// The stored vertices are an `f64` anchor plus `f32` offsets
/// (`geometry::triangles`); written as `f32`, each moves by at most half an
/// `f32` step of its coordinate, so a peer's distances agree to about 10⁻⁷
/// relative and only rays within that of an edge may hit differently.
pub fn export(meshes: &[(String, Mesh)], directory: &Path) -> Result<(), BenchError> {
    let io = |path: &Path| {
        let path = path.display().to_string();
        move |source| BenchError::Io { path, source }
    };
    std::fs::create_dir_all(directory).map_err(io(directory))?;
    let write = |path: &Path, bytes: Vec<u8>| -> Result<(), BenchError> {
        let mut file = std::fs::File::create(path).map_err(io(path))?;
        file.write_all(&bytes).map_err(io(path))
    };
    for (name, mesh) in meshes {
        let scene = Scene::from_mesh(mesh.clone());
        let stored = &scene.meshes[0];
        let vertices: Vec<u8> = stored
            .positions
            .iter()
            .flat_map(|p| p.as_vec3().to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        write(&directory.join(format!("{name}.vertices.f32")), vertices)?;
        let faces: Vec<u8> = stored.faces.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
        write(&directory.join(format!("{name}.faces.u32")), faces)?;
        for (set, rays) in [
            ("primary", primary_rays(&scene)),
            ("incoherent", incoherent_rays(&scene, INCOHERENT_RAYS)),
        ] {
            let ray_bytes: Vec<u8> = rays
                .iter()
                .flat_map(|r| [r.origin.as_vec3().to_array(), r.direction.as_vec3().to_array()])
                .flatten()
                .flat_map(f32::to_le_bytes)
                .collect();
            write(&directory.join(format!("{name}-{set}.rays.f32")), ray_bytes)?;
            let answers: Vec<u8> = rays
                .par_iter()
                .map(|ray| match scene.intersect(ray, f64::INFINITY) {
                    Some(hit) => {
                        let face = scene.triangle_source(hit.primitive).map_or(-1.0, |s| s.face as f64);
                        [face, hit.hit.t]
                    }
                    None => [-1.0, f64::INFINITY],
                })
                .collect::<Vec<_>>()
                .into_iter()
                .flatten()
                .flat_map(f64::to_le_bytes)
                .collect();
            write(&directory.join(format!("{name}-{set}.prism.f64")), answers)?;
            let occluded: Vec<u8> = rays
                .par_iter()
                .map(|ray| u8::from(scene.occluded(ray, f64::INFINITY)))
                .collect();
            write(&directory.join(format!("{name}-{set}.prism-occluded.u8")), occluded)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One level of subdivision keeps the surface: four faces per face,
    /// the same total area, and every edge still shared by two faces.
    #[test]
    fn subdivision_quadruples_faces_and_keeps_area_and_closure() {
        let sphere = super::super::scaling::sphere_mesh(200, DVec3::ZERO, 1.0);
        let finer = subdivide(&sphere);
        assert_eq!(finer.faces.len(), 4 * sphere.faces.len());
        let area = |m: &Mesh| {
            m.faces
                .iter()
                .map(|f| {
                    let [a, b, c] = f.map(|i| m.positions[i as usize]);
                    0.5 * (b - a).cross(c - a).length()
                })
                .sum::<f64>()
        };
        assert!((area(&finer) - area(&sphere)).abs() < 1e-9 * area(&sphere));
        let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
        for f in &finer.faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        assert!(edges.values().all(|&n| n == 2));
    }
}
