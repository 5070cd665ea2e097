//! Traces fixed ray sets at the bunny (optionally subdivided) on one
//! thread, for instruction and cache counting under
//! `valgrind --tool=callgrind` (repeatable on a loaded machine, unlike wall
//! time). The same rays as `prism bench --rays`:
//!
//! ```sh
//! cargo build --release --example ray_cost
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='ray_cost::measured_*' \
//!     target/release/examples/ray_cost 100000 2
//! callgrind_annotate --inclusive=yes callgrind.out.PID | grep measured_
//! ```
//!
//! traces 100,000 incoherent closest-hit and occlusion queries and every
//! fourth row of the 1024² primary image (262,144 rays, still in scanline
//! order) at the bunny subdivided twice (59k triangles), and builds its
//! BVH once more (on one thread), each in its own `measured_*` function,
//! so the collected instructions divided by the ray count are instructions
//! per ray.

use prism::accel::{BuildPrimitive, Bvh};
use prism::bench::rays::{incoherent_rays, primary_rays, subdivide};
use prism::geometry::{Mesh, Transform};
use prism::math::Ray;
use prism::scene::Scene;
use std::hint::black_box;
use std::path::Path;

#[inline(never)]
fn measured_closest(scene: &Scene, rays: &[Ray]) -> usize {
    rays.iter()
        .filter(|ray| scene.intersect(ray, f64::INFINITY).is_some())
        .count()
}

#[inline(never)]
fn measured_occlusion(scene: &Scene, rays: &[Ray]) -> usize {
    rays.iter().filter(|ray| scene.occluded(ray, f64::INFINITY)).count()
}

/// Not the same code as `measured_closest` (which the linker would merge
/// with it, mixing the two counts): the primitives hit are summed.
#[inline(never)]
fn measured_primary(scene: &Scene, rays: &[Ray]) -> usize {
    rays.iter()
        .filter_map(|ray| scene.intersect(ray, f64::INFINITY))
        .map(|hit| hit.primitive as usize)
        .sum()
}

#[inline(never)]
fn measured_build(primitives: &[BuildPrimitive]) -> usize {
    black_box(Bvh::build(primitives)).0.node_count()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let count: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(100_000);
    let subdivisions: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(0);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny.obj");
    let mut mesh = match Mesh::load_obj(&path, &Transform::default()) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("{}: {e}", path.display());
            std::process::exit(1);
        }
    };
    for _ in 0..subdivisions {
        mesh = subdivide(&mesh);
    }
    let scene = Scene::from_mesh(mesh);
    let incoherent = incoherent_rays(&scene, count);
    // Every fourth row of the image: coherent within rows, a quarter of the work.
    let primary: Vec<Ray> = primary_rays(&scene).chunks(1024).step_by(4).flatten().copied().collect();
    let build_primitives: Vec<BuildPrimitive> = (0..scene.primitive_count() as u32)
        .map(|primitive| BuildPrimitive {
            bounds: scene.primitive_bounds(primitive),
            kind: 0,
        })
        .collect();
    let hits = measured_closest(&scene, &incoherent);
    let shadowed = measured_occlusion(&scene, &incoherent);
    let primary_hits = measured_primary(&scene, &primary);
    // On a one-thread pool, so the build's parallel subtrees run on the
    // thread that entered `measured_build` (callgrind counts per thread).
    let nodes = match rayon::ThreadPoolBuilder::new().num_threads(1).build() {
        Ok(pool) => pool.install(|| measured_build(&build_primitives)),
        Err(e) => {
            eprintln!("thread pool: {e}");
            std::process::exit(1);
        }
    };
    println!(
        "{} triangles, {count} incoherent rays: {hits} closest hits, {shadowed} occluded; {} primary rays (hit primitives summing to {primary_hits}); \
         {nodes} nodes, {} leaves, depth {}, {:.1} bytes per triangle",
        scene.primitive_count(),
        primary.len(),
        scene.bvh().leaf_count(),
        scene.bvh().depth(),
        scene.acceleration_bytes() as f64 / scene.primitive_count() as f64
    );
}
