//! Intersects a fixed set of rays with the 5-point vase of `benches/revolution.rs`
//! on one thread, for instruction counting under `valgrind --tool=callgrind`:
//! `cargo build --release --example revolution_cost && valgrind --tool=callgrind
//! target/release/examples/revolution_cost 20000`.

use glam::{DAffine3, DVec2, DVec3};
use prism::geometry::revolution::Revolution;
use prism::math::Ray;
use std::hint::black_box;

const VASE: [DVec2; 5] = [
    DVec2::new(0.0, 0.0),
    DVec2::new(1.2, 0.1),
    DVec2::new(0.3, 0.9),
    DVec2::new(0.9, 1.4),
    DVec2::new(0.5, 2.0),
];

fn main() {
    let count: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(20_000);
    let shape = match Revolution::new(vec![VASE.to_vec()], false, DAffine3::IDENTITY) {
        Ok(shape) => shape,
        Err(e) => {
            eprintln!("vase: {e}");
            std::process::exit(1);
        }
    };
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut uniform = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut hits = 0;
    for _ in 0..count {
        let z = 2.0 * uniform() - 1.0;
        let phi = std::f64::consts::TAU * uniform();
        let r = (1.0 - z * z).max(0.0).sqrt();
        let origin = DVec3::new(0.0, 0.0, 1.0) + 6.0 * DVec3::new(r * phi.cos(), r * phi.sin(), z);
        let target = DVec3::new(2.4 * uniform() - 1.2, 2.4 * uniform() - 1.2, 2.0 * uniform());
        if black_box(shape.intersect(&Ray::new(origin, target - origin), f64::INFINITY)).is_some() {
            hits += 1;
        }
    }
    println!("{hits} of {count} rays hit");
}
