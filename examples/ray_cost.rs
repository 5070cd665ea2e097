//! Traces a fixed set of incoherent rays at the bunny on one thread, for
//! instruction counting under `valgrind --tool=callgrind` (repeatable on a
//! loaded machine, unlike wall time): `cargo run --release --example ray_cost -- 200000`.

use glam::DVec3;
use prism::geometry::{Mesh, Transform};
use prism::math::Ray;
use prism::scene::Scene;
use std::path::Path;

fn main() {
    let count: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(200_000);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny.obj");
    let mesh = match Mesh::load_obj(&path, &Transform::default()) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("{}: {e}", path.display());
            std::process::exit(1);
        }
    };
    let scene = Scene::from_mesh(mesh);
    let bounds = scene.bounds();
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let (center, radius) = (bounds.centroid(), bounds.extent().length());
    let mut hits = 0;
    let mut shadowed = 0;
    for _ in 0..count {
        let z = 2.0 * next() - 1.0;
        let phi = std::f64::consts::TAU * next();
        let r = (1.0 - z * z).sqrt();
        let origin = center + radius * DVec3::new(r * phi.cos(), r * phi.sin(), z);
        let target = bounds.min + bounds.extent() * DVec3::new(next(), next(), next());
        let ray = Ray::new(origin, target - origin);
        hits += scene.intersect(&ray, f64::INFINITY).is_some() as usize;
        shadowed += scene.occluded(&ray, f64::INFINITY) as usize;
    }
    println!("{count} rays: {hits} closest hits, {shadowed} occluded");
}
