//! How cost grows with the problem: BVH build time and ray cost against
//! triangle count (generated spheres of 1k … 1M triangles), and render time
//! against resolution and thread count.
//!
//! Expectations: a binned SAH build sorts nothing but partitions each level
//! once, O(n) per level over O(log n) levels, so time / (n log₂ n) should stay
//! flat; a ray visits O(log n) nodes of a balanced tree, so ns per ray should
//! grow linearly in log₂ n (Wald 2007; pbrt-v4 §7.3).

use super::plot::{LinePlot, Series};
use super::{BenchError, Csv, format_number};
use crate::accel::{BuildPrimitive, Bvh};
use crate::camera::Camera;
use crate::geometry::Mesh;
use crate::math::Ray;
use crate::render::render_to_completion;
use crate::sampler::{Sampler, SamplerKind};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use glam::DVec3;
use std::f64::consts::PI;
use std::path::Path;
use std::time::Instant;

/// A closed, consistently outward-wound UV sphere with about `target_triangles`
/// faces, vertices shared between faces (so its edges are watertight).
pub fn sphere_mesh(target_triangles: u32, center: DVec3, radius: f64) -> Mesh {
    // `segments` around, `rings` = segments / 2 from pole to pole: two fans of
    // `segments` triangles plus 2·segments per inner band ≈ segments² faces.
    let segments = ((target_triangles as f64).sqrt().round() as u32 + 2).max(4);
    let rings = (segments / 2).max(2);
    let mut mesh = Mesh::default();
    let point =
        |theta: f64, phi: f64| center + radius * DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
    mesh.positions.push(center + DVec3::new(0.0, radius, 0.0));
    for ring in 1..rings {
        let theta = PI * ring as f64 / rings as f64;
        for segment in 0..segments {
            mesh.positions.push(point(theta, 2.0 * PI * segment as f64 / segments as f64));
        }
    }
    let south = mesh.positions.len() as u32;
    mesh.positions.push(center - DVec3::new(0.0, radius, 0.0));
    let vertex = |ring: u32, segment: u32| 1 + (ring - 1) * segments + segment % segments;
    for s in 0..segments {
        mesh.faces.push([0, vertex(1, s), vertex(1, s + 1)]);
        mesh.faces.push([south, vertex(rings - 1, s + 1), vertex(rings - 1, s)]);
        for ring in 1..rings - 1 {
            let (a, b, c, d) = (
                vertex(ring, s),
                vertex(ring, s + 1),
                vertex(ring + 1, s),
                vertex(ring + 1, s + 1),
            );
            mesh.faces.push([a, c, b]);
            mesh.faces.push([b, c, d]);
        }
    }
    orient_outward(&mut mesh, center);
    mesh
}

/// Flips faces whose normal points towards `inside` (a point the closed,
/// star-shaped mesh surrounds), so every face is wound outward.
pub fn orient_outward(mesh: &mut Mesh, inside: DVec3) {
    for face in &mut mesh.faces {
        let [a, b, c] = face.map(|i| mesh.positions[i as usize]);
        if (b - a).cross(c - a).dot((a + b + c) / 3.0 - inside) < 0.0 {
            face.swap(1, 2);
        }
    }
}

/// One row of the BVH measurement.
#[derive(Clone, Debug)]
pub struct BvhRow {
    /// Triangles in the tessellated sphere.
    pub triangles: usize,
    /// Eight-wide nodes of its BVH.
    pub nodes: usize,
    /// Mean of repeated single-threaded builds, in thread CPU time where
    /// known (else wall time), which other load barely disturbs.
    pub build_seconds: f64,
    /// Wall time of the same builds, mean per build.
    pub build_wall_seconds: f64,
    /// Probe rays traced.
    pub rays: u64,
    /// Single-threaded nearest-hit cost, CPU time where known.
    pub ns_per_ray: f64,
    /// As `ns_per_ray`, in wall time.
    pub wall_ns_per_ray: f64,
    /// Share of the probe rays that hit the sphere, 0 to 1 (about 0.78).
    pub hit_fraction: f64,
}

/// Builds BVHs over spheres of each triangle count and traces `rays` camera-like
/// rays (about 78% hitting) through each, all on one worker thread.
pub fn measure_bvh(triangle_counts: &[u32], rays: u64, mut progress: impl FnMut(&BvhRow)) -> Result<Vec<BvhRow>, BenchError> {
    // One thread: the builder's rayon::join stays on it, so its CPU time is the build's.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let mut rows = Vec::new();
    for &target in triangle_counts {
        let scene = Scene::from_mesh(sphere_mesh(target, DVec3::ZERO, 1.0));
        let bounds: Vec<BuildPrimitive> = (0..scene.primitive_count() as u32)
            .map(|primitive| BuildPrimitive {
                bounds: scene.primitive_bounds(primitive),
                kind: 0,
            })
            .collect();
        // Repeat small builds so the total spans ~0.3 s or more: the CPU
        // clock advances in scheduler ticks (a few ms), too coarse for one build.
        let repetitions = (3_000_000 / bounds.len().max(1)).clamp(1, 3000);
        let (nodes, wall, cpu) = pool.install(|| {
            super::time_thread(|| {
                let mut nodes = 0;
                for _ in 0..repetitions {
                    nodes = Bvh::build(&bounds).0.node_count();
                }
                nodes
            })
        });
        let build_wall_seconds = wall / repetitions as f64;
        let build_seconds = cpu.map_or(build_wall_seconds, |c| c / repetitions as f64);
        let probes = probe_rays(rays);
        let (hits, wall, cpu) = pool.install(|| super::time_thread(|| count_hits(&scene, &probes)));
        let per_ray = 1e9 / rays.max(1) as f64;
        let row = BvhRow {
            triangles: bounds.len(),
            nodes,
            build_seconds,
            build_wall_seconds,
            rays,
            ns_per_ray: cpu.unwrap_or(wall) * per_ray,
            wall_ns_per_ray: wall * per_ray,
            hit_fraction: hits as f64 / rays.max(1) as f64,
        };
        progress(&row);
        rows.push(row);
    }
    Ok(rows)
}

/// Rays from a point 3 radii away towards a disk 1.2 radii wide around the
/// unit sphere's centre (made before timing, so only tracing is measured).
fn probe_rays(count: u64) -> Vec<Ray> {
    let origin = DVec3::new(0.0, 0.0, 3.0);
    (0..count)
        .map(|i| {
            let u = Sampler::new(SamplerKind::Random, i, 0, 7).next_2d();
            let disk = crate::math::warp::square_to_concentric_disk(u) * 1.2;
            Ray::new(origin, DVec3::new(disk.x, disk.y, 0.0) - origin)
        })
        .collect()
}

/// How many of `rays` hit something.
fn count_hits(scene: &Scene, rays: &[Ray]) -> u64 {
    rays.iter()
        .filter(|ray| scene.intersect(ray, f64::INFINITY).is_some())
        .count() as u64
}

/// One row of the render-time measurement.
#[derive(Clone, Debug)]
pub struct RenderRow {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels (from the width and the scene's aspect).
    pub height: u32,
    /// Worker threads.
    pub threads: usize,
    /// Passes rendered (samples per pixel).
    pub passes: u32,
    /// Wall time of the whole render, in seconds.
    pub seconds: f64,
    /// Wall nanoseconds per pixel sample: `seconds / (passes · pixels)`.
    pub ns_per_sample: f64,
}

/// Renders `passes` passes at each width (height by the settings' aspect)
/// with each thread count.
pub fn measure_render(
    scene: &Scene,
    camera: &Camera,
    settings: &RenderSettings,
    widths: &[u32],
    threads: &[usize],
    passes: u32,
    mut progress: impl FnMut(&RenderRow),
) -> Result<Vec<RenderRow>, BenchError> {
    let mut rows = Vec::new();
    for &thread_count in threads {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(thread_count).build()?;
        for &width in widths {
            let height = ((width as f64 / settings.aspect()).round() as u32).max(1);
            let settings = RenderSettings {
                width,
                height,
                samples_per_pixel: Some(passes),
                time_limit: None,
                ..settings.clone()
            };
            let start = Instant::now();
            pool.install(|| render_to_completion(scene, camera, &settings));
            let seconds = start.elapsed().as_secs_f64();
            let row = RenderRow {
                width,
                height,
                threads: thread_count,
                passes,
                seconds,
                ns_per_sample: seconds * 1e9 / (passes as f64 * settings.pixel_count() as f64),
            };
            progress(&row);
            rows.push(row);
        }
    }
    Ok(rows)
}

/// Largest triangle count in the O(log n) fit of ray cost.
const FIT_TRIANGLES: usize = 70_000;

/// Least-squares fit of y = a + b·x.
fn fit_line(points: &[(f64, f64)]) -> (f64, f64) {
    let n = points.len() as f64;
    let (sx, sy) = points.iter().fold((0.0, 0.0), |(sx, sy), &(x, y)| (sx + x, sy + y));
    let (mx, my) = (sx / n, sy / n);
    let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(a, b), &(x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    (my - slope * mx, slope)
}

/// Writes `bvh_scaling.csv` and `bvh_build.png`, `ray_cost.png` into `directory`.
pub fn write_bvh_results(rows: &[BvhRow], machine: &str, directory: &Path) -> Result<(), BenchError> {
    let mut csv = Csv::new(vec![
        "triangles",
        "nodes",
        "build_seconds",
        "build_ns_per_n_log2_n",
        "build_wall_seconds",
        "rays",
        "ns_per_ray",
        "wall_ns_per_ray",
        "hit_fraction",
    ]);
    csv.comments.push(
        "prism bench --scaling: BVH build (mean of repeated builds) and nearest-hit ray cost on UV spheres, one thread".into(),
    );
    csv.comments.push(format!(
        "build_seconds and ns_per_ray are thread CPU time ({}); the wall_ columns include time lost to other load",
        if super::thread_cpu_seconds().is_some() {
            "from /proc/thread-self/schedstat"
        } else {
            "unavailable here: wall time"
        }
    ));
    csv.comments.push(machine.to_string());
    for r in rows {
        let n = r.triangles as f64;
        csv.rows.push(vec![
            r.triangles.to_string(),
            r.nodes.to_string(),
            format_number(r.build_seconds),
            format_number(r.build_seconds * 1e9 / (n * n.log2().max(1.0))),
            format_number(r.build_wall_seconds),
            r.rays.to_string(),
            format_number(r.ns_per_ray),
            format_number(r.wall_ns_per_ray),
            format!("{:.4}", r.hit_fraction),
        ]);
    }
    csv.write(&directory.join("bvh_scaling.csv"))?;

    // Guide: c · n log₂ n through the largest measurement.
    let guide = rows.last().map(|last| {
        let n = last.triangles as f64;
        let c = last.build_seconds / (n * n.log2());
        Series {
            name: "c·n·log2(n)".into(),
            points: rows
                .iter()
                .map(|r| (r.triangles as f64, c * r.triangles as f64 * (r.triangles as f64).log2()))
                .collect(),
            guide: true,
        }
    });
    let mut build = LinePlot {
        title: "BVH build time against triangle count".into(),
        x_label: "triangles".into(),
        y_label: "build time [s], 1 thread, CPU time".into(),
        log_x: true,
        log_y: true,
        series: vec![Series {
            name: "binned SAH build".into(),
            points: rows.iter().map(|r| (r.triangles as f64, r.build_seconds)).collect(),
            guide: false,
        }],
    };
    build.series.extend(guide);
    build.write_png(&directory.join("bvh_build.png"))?;

    // Fit a + b·log2(n) where the tree and triangles still fit in the caches
    // (≤ 2^16 triangles ≈ 10 MB); beyond, memory latency adds to every node.
    let log_points: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.triangles <= FIT_TRIANGLES)
        .map(|r| ((r.triangles as f64).log2(), r.ns_per_ray))
        .collect();
    let (a, b) = fit_line(&log_points);
    let rays = LinePlot {
        title: "Cost per ray against triangle count".into(),
        x_label: "triangles".into(),
        y_label: "ns per ray (1 thread, CPU time)".into(),
        log_x: true,
        log_y: false,
        series: vec![
            Series {
                name: "nearest hit".into(),
                points: rows.iter().map(|r| (r.triangles as f64, r.ns_per_ray)).collect(),
                guide: false,
            },
            Series {
                name: format!("{a:.0} + {b:.1}·log2(n) ns, fit for n ≤ 70k"),
                points: rows
                    .iter()
                    .map(|r| (r.triangles as f64, a + b * (r.triangles as f64).log2()))
                    .collect(),
                guide: true,
            },
        ],
    };
    rays.write_png(&directory.join("ray_cost.png"))
}

/// Writes `render_scaling.csv` and `render_scaling.png` into `directory`.
pub fn write_render_results(rows: &[RenderRow], scene_name: &str, machine: &str, directory: &Path) -> Result<(), BenchError> {
    let mut csv = Csv::new(vec![
        "scene",
        "width",
        "height",
        "threads",
        "passes",
        "seconds",
        "ns_per_sample",
    ]);
    csv.comments
        .push("prism bench --scaling: render time of a fixed number of passes against resolution and thread count".into());
    csv.comments.push(machine.to_string());
    for r in rows {
        csv.rows.push(vec![
            scene_name.to_string(),
            r.width.to_string(),
            r.height.to_string(),
            r.threads.to_string(),
            r.passes.to_string(),
            format_number(r.seconds),
            format_number(r.ns_per_sample),
        ]);
    }
    csv.write(&directory.join("render_scaling.csv"))?;
    let mut threads: Vec<usize> = rows.iter().map(|r| r.threads).collect();
    threads.dedup();
    let plot = LinePlot {
        title: format!("Render time against resolution ({scene_name})"),
        x_label: "pixels".into(),
        y_label: "seconds per pass".into(),
        log_x: true,
        log_y: true,
        series: threads
            .iter()
            .map(|&t| Series {
                name: format!("{t} thread{}", if t == 1 { "" } else { "s" }),
                points: rows
                    .iter()
                    .filter(|r| r.threads == t)
                    .map(|r| ((r.width * r.height) as f64, r.seconds / r.passes.max(1) as f64))
                    .collect(),
                guide: false,
            })
            .collect(),
    };
    plot.write_png(&directory.join("render_scaling.png"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_mesh_is_closed_and_outward() {
        let mesh = sphere_mesh(400, DVec3::new(1.0, 2.0, 3.0), 2.0);
        // Closed: every edge is shared by exactly two faces, in opposite directions.
        let mut edges = std::collections::HashMap::new();
        for f in &mesh.faces {
            for k in 0..3 {
                *edges.entry((f[k], f[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &count) in &edges {
            assert_eq!(count, 1, "edge {a}-{b} used twice in one direction");
            assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a}-{b} has no opposite");
        }
        // Signed volume (divergence theorem) positive and near 4/3 π r³
        // within 5%: a 400-face sphere underestimates the volume by ~2%.
        let volume: f64 = mesh
            .faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| mesh.positions[i as usize] - DVec3::new(1.0, 2.0, 3.0));
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        let exact = 4.0 / 3.0 * PI * 8.0;
        assert!((volume / exact - 1.0).abs() < 0.05, "volume {volume} vs {exact}");
    }

    #[test]
    fn line_fit_recovers_a_line() {
        let (a, b) = fit_line(&[(1.0, 5.0), (2.0, 7.0), (3.0, 9.0)]);
        assert!((a - 3.0).abs() < 1e-12 && (b - 2.0).abs() < 1e-12);
    }
}
