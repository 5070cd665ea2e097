//! BVH build time and incoherent-ray throughput on the Stanford bunny.
//! `cargo bench --bench bvh`; criterion reports rays/s as elements/s.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use prism::accel::BuildPrimitive;
use prism::geometry::{Mesh, Shape, Transform};
use prism::material::{Material, Texture};
use prism::math::{Aabb, Ray};
use prism::scene::{Primitive, Scene};
use rayon::prelude::*;
use std::hint::black_box;
use std::path::Path;

fn bunny() -> (Vec<Primitive>, Mesh) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny.obj");
    let mesh = match Mesh::load_obj(&path, &Transform::default()) {
        Ok(m) => m,
        Err(e) => panic!("{}: {e}", path.display()),
    };
    let primitives = mesh
        .triangles(0)
        .map(|t| Primitive {
            shape: Shape::Triangle(t),
            material: 0,
        })
        .collect();
    (primitives, mesh)
}

fn material() -> Vec<Material> {
    vec![Material::Diffuse {
        albedo: Texture::Constant(DVec3::ONE),
    }]
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
    let (primitives, mesh) = bunny();
    let bounds: Vec<BuildPrimitive> = primitives
        .iter()
        .map(|p| BuildPrimitive {
            bounds: p.shape.bounds(),
            kind: 0,
        })
        .collect();

    let mut group = c.benchmark_group("bvh_build_bunny");
    group.throughput(Throughput::Elements(bounds.len() as u64));
    group.bench_function("binned_sah", |b| {
        b.iter(|| black_box(prism::accel::Bvh::build(black_box(&bounds))))
    });
    group.finish();

    let scene = Scene::new(primitives, vec![mesh], material(), DVec3::ZERO);
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
