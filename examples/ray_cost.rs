//! Traces a fixed set of incoherent rays at the bunny (optionally
//! subdivided) on one thread, for instruction and cache counting under
//! `valgrind --tool=callgrind` (repeatable on a loaded machine, unlike wall
//! time): `cargo build --profile profiling --example ray_cost &&
//! valgrind --tool=callgrind target/profiling/examples/ray_cost 200000 2`
//! traces 200,000 closest-hit and 200,000 occlusion queries at the bunny
//! subdivided twice (59k triangles). The same rays as `prism bench --rays`.

use prism::bench::rays::{incoherent_rays, subdivide};
use prism::geometry::{Mesh, Transform};
use prism::scene::Scene;
use std::path::Path;

fn main() {
    let mut args = std::env::args().skip(1);
    let count: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(200_000);
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
    let rays = incoherent_rays(&scene, count);
    let hits = rays
        .iter()
        .filter(|ray| scene.intersect(ray, f64::INFINITY).is_some())
        .count();
    let shadowed = rays.iter().filter(|ray| scene.occluded(ray, f64::INFINITY)).count();
    println!(
        "{} triangles, {count} rays: {hits} closest hits, {shadowed} occluded; {} nodes, {} leaves, depth {}",
        scene.primitive_count(),
        scene.bvh().node_count(),
        scene.bvh().leaf_count(),
        scene.bvh().depth()
    );
}
