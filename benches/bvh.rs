//! BVH build time and incoherent-ray throughput on the Stanford bunny.
//! `cargo bench --bench bvh`; criterion reports rays/s as elements/s.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use prism::accel::BuildPrimitive;
use prism::geometry::{Mesh, Transform};
use prism::math::{Aabb, Ray};
use prism::scene::Scene;
use rayon::prelude::*;
use std::hint::black_box;
use std::path::Path;

fn bunny() -> Mesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny.obj");
    match Mesh::load_obj(&path, &Transform::default()) {
        Ok(m) => m,
        Err(e) => panic!("{}: {e}", path.display()),
    }
}

/// Rays from random points on a sphere around the bunny towards random points
/// in its bounding box: incoherent, about half of them hit.
fn incoherent_rays(bounds: Aabb, count: usize) -> Vec<Ray> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let center = bounds.centroid();
    let radius = bounds.extent().length();
    (0..count)
        .map(|_| {
            let z = 2.0 * next() - 1.0;
            let phi = std::f64::consts::TAU * next();
            let r = (1.0 - z * z).sqrt();
            let origin = center + radius * DVec3::new(r * phi.cos(), r * phi.sin(), z);
            let target = bounds.min + bounds.extent() * DVec3::new(next(), next(), next());
            Ray::new(origin, target - origin)
        })
        .collect()
}

fn benchmarks(c: &mut Criterion) {
    let mesh = bunny();
    // In file order, as the scene loader hands triangles to the builder.
    let bounds: Vec<BuildPrimitive> = mesh
        .triangles(0)
        .map(|t| BuildPrimitive {
            bounds: t.bounds(),
            kind: 0,
        })
        .collect();

    let mut group = c.benchmark_group("bvh_build_bunny");
    group.throughput(Throughput::Elements(bounds.len() as u64));
    group.bench_function("binned_sah", |b| {
        b.iter(|| black_box(prism::accel::Bvh::build(black_box(&bounds))))
    });
    group.finish();

    let scene = Scene::from_mesh(mesh);
    let rays = incoherent_rays(scene.bounds(), 100_000);
    let hits = rays.iter().filter(|r| scene.intersect(r, f64::INFINITY).is_some()).count();
    eprintln!("incoherent rays: {} of {} hit the bunny", hits, rays.len());

    let mut group = c.benchmark_group("incoherent_rays_bunny");
    group.throughput(Throughput::Elements(rays.len() as u64));
    for threads in [1, 2] {
        let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
            Ok(p) => p,
            Err(e) => panic!("{e}"),
        };
        group.bench_function(format!("closest_hit_{threads}_threads"), |b| {
            b.iter(|| {
                pool.install(|| {
                    rays.par_chunks(1024)
                        .map(|chunk| chunk.iter().filter(|r| scene.intersect(r, f64::INFINITY).is_some()).count())
                        .sum::<usize>()
                })
            })
        });
        group.bench_function(format!("shadow_ray_{threads}_threads"), |b| {
            b.iter(|| {
                pool.install(|| {
                    rays.par_chunks(1024)
                        .map(|chunk| chunk.iter().filter(|r| scene.occluded(r, f64::INFINITY)).count())
                        .sum::<usize>()
                })
            })
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(4));
    targets = benchmarks
}
criterion_main!(benches);
