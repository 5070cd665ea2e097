//! Cost per ray of `Revolution::intersect` on a 5-point vase, for rays that
//! hit and rays that miss (inside the bounding box), against a baseline that
//! reimplements the original method of issue #4: Newton iteration on the same
//! implicit equation `(D_x(y − O_z) + D_z O_x)² + (D_y(y − O_z) + D_z O_y)²
//! − D_z² x² = 0` from 200 random starting `t` per ray, with `s = (y − O_z)/D_z`,
//! and rays with `|D_z| < 1e-6` treated as hitting the sphere centred on the
//! axis at the height where `y(t) = O_z`, of radius `x(t)`.
//!
//! Before timing, both methods are checked on a fixed ray set (random,
//! grazing within 1e-6 in angle and offset, horizontal with `D_z ∈ {0, ±1e-12}`,
//! far) against an independent
//! reference (branch and bound on `f(s) = r(s) − R(z(s))` with its Lipschitz
//! bound; tolerance `τ = 1e-9 ×` size, as in `tests/revolution_stress.rs`),
//! and their error counts are printed.
//!
//! Run with `cargo bench --bench revolution`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{DAffine3, DVec2, DVec3};
use prism::geometry::revolution::Revolution;
use prism::math::Ray;
use std::hint::black_box;
use std::time::Instant;

const VASE: [DVec2; 5] = [
    DVec2::new(0.0, 0.0),
    DVec2::new(1.2, 0.1),
    DVec2::new(0.3, 0.9),
    DVec2::new(0.9, 1.4),
    DVec2::new(0.5, 2.0),
];

fn point(points: &[DVec2], t: f64) -> DVec2 {
    let n = points.len() - 1;
    let mut sum = DVec2::ZERO;
    let mut binomial = 1.0;
    for (k, p) in points.iter().enumerate() {
        sum += *p * binomial * t.powi(k as i32) * (1.0 - t).powi((n - k) as i32);
        binomial = binomial * (n - k) as f64 / (k + 1) as f64;
    }
    sum
}

/// The hodograph evaluated at `t`, without allocating (the baseline should
/// not be slowed by the heap).
fn derivative(points: &[DVec2], t: f64) -> DVec2 {
    let n = points.len() - 1;
    let mut differences = [DVec2::ZERO; 16];
    for (difference, pair) in differences.iter_mut().zip(points.windows(2)) {
        *difference = (pair[1] - pair[0]) * n as f64;
    }
    point(&differences[..n], t)
}

struct Random(u64);

impl Random {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, low: f64, high: f64) -> f64 {
        low + (high - low) * self.uniform()
    }
    fn direction(&mut self) -> DVec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f64::consts::TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

// ---------------------------------------------------------------------------
// The baseline: Newton from 200 random starts.

fn baseline_intersect(ray: &Ray, random: &mut Random) -> Option<(f64, DVec3)> {
    let (o, d) = (ray.origin, ray.direction);
    let mut best: Option<(f64, f64)> = None;
    let mut keep = |s: f64, t: f64| {
        if s > 1e-9 && best.is_none_or(|(b, _)| s < b) {
            best = Some((s, t));
        }
    };
    if d.z.abs() < 1e-6 {
        // Sphere-like approximation at the height of the ray's origin.
        for _ in 0..200 {
            let mut t = random.uniform();
            for _ in 0..30 {
                let step = (point(&VASE, t).y - o.z) / derivative(&VASE, t).y;
                t -= step;
                if step.abs() < 1e-14 {
                    break;
                }
            }
            if !(0.0..=1.0).contains(&t) || (point(&VASE, t).y - o.z).abs() > 1e-10 {
                continue;
            }
            let radius = point(&VASE, t).x;
            let to_origin = o - DVec3::new(0.0, 0.0, point(&VASE, t).y);
            let b = to_origin.dot(d);
            let discriminant = b * b - (to_origin.length_squared() - radius * radius);
            if discriminant >= 0.0 {
                for s in [-b - discriminant.sqrt(), -b + discriminant.sqrt()] {
                    keep(s, t);
                }
            }
        }
    } else {
        for _ in 0..200 {
            let mut t = random.uniform();
            let mut converged = false;
            for _ in 0..30 {
                let (p, dp) = (point(&VASE, t), derivative(&VASE, t));
                let a = d.x * (p.y - o.z) + d.z * o.x;
                let b = d.y * (p.y - o.z) + d.z * o.y;
                let g = a * a + b * b - d.z * d.z * p.x * p.x;
                let slope = 2.0 * (a * d.x * dp.y + b * d.y * dp.y - d.z * d.z * p.x * dp.x);
                let step = g / slope;
                t -= step;
                if !t.is_finite() {
                    break;
                }
                if step.abs() < 1e-14 {
                    converged = true;
                    break;
                }
            }
            if converged && (0.0..=1.0).contains(&t) {
                keep((point(&VASE, t).y - o.z) / d.z, t);
            }
        }
    }
    best.map(|(s, t)| {
        let tangent = derivative(&VASE, t);
        let p = ray.at(s);
        let radial = DVec2::new(p.x, p.y).normalize_or_zero();
        (
            s,
            DVec3::new(tangent.y * radial.x, tangent.y * radial.y, -tangent.x).normalize(),
        )
    })
}

// ---------------------------------------------------------------------------
// Independent reference (Lipschitz branch and bound along the ray).

struct Reference {
    table: Vec<f64>,
    /// Bounds on |dR/dz| and |d²R/dz²| from the control polygon.
    slope_bound: f64,
    curvature_bound: f64,
}

const TABLE: usize = 1024;
const TAU_REFERENCE: f64 = 2e-9;

impl Reference {
    fn new() -> Self {
        let n = 4.0;
        let first: Vec<DVec2> = VASE.windows(2).map(|w| w[1] - w[0]).collect();
        let second: Vec<DVec2> = first.windows(2).map(|w| w[1] - w[0]).collect();
        let dx = first.iter().map(|d| d.x.abs()).fold(0.0, f64::max);
        let dy_max = first.iter().map(|d| d.y.abs()).fold(0.0, f64::max);
        let dy = first.iter().map(|d| d.y).fold(f64::INFINITY, f64::min);
        let ddx = second.iter().map(|d| d.x.abs()).fold(0.0, f64::max) * n * (n - 1.0);
        let ddy = second.iter().map(|d| d.y.abs()).fold(0.0, f64::max) * n * (n - 1.0);
        Self {
            table: (0..=TABLE).map(|k| point(&VASE, k as f64 / TABLE as f64).y).collect(),
            slope_bound: dx / dy,
            curvature_bound: (ddx * n * dy_max + n * dx * ddy) / (n * dy).powi(3),
        }
    }

    fn gap(&self, ray: &Ray, s: f64) -> f64 {
        let p = ray.at(s);
        let z = p.z.clamp(0.0, 2.0);
        let k = self.table.partition_point(|&y| y <= z).clamp(1, TABLE);
        let mut t = (k - 1) as f64 / TABLE as f64;
        for _ in 0..8 {
            t -= (point(&VASE, t).y - z) / derivative(&VASE, t).y;
        }
        p.x.hypot(p.y) - point(&VASE, t.clamp(0.0, 1.0)).x
    }

    /// `Some(Some(s))` for a clear first hit, `Some(None)` for a clear miss,
    /// `None` when a grazing touch or shallow lobe comes first.
    fn first_hit(&self, ray: &Ray) -> Option<Option<f64>> {
        let (o, d) = (ray.origin, ray.direction);
        let (mut low, mut high) = (0.0_f64, f64::INFINITY);
        if d.z != 0.0 {
            let (a, b) = ((0.0 - o.z) / d.z, (2.0 - o.z) / d.z);
            (low, high) = (low.max(a.min(b)), high.min(a.max(b)));
        } else if !(0.0..=2.0).contains(&o.z) {
            return Some(None);
        }
        let h2 = d.x * d.x + d.y * d.y;
        let center = -(o.x * d.x + o.y * d.y) / h2;
        let closest = (o + center * d).truncate().length_squared();
        let r = 1.2 * (1.0 + 1e-6);
        if closest > r * r {
            return Some(None);
        }
        let half = ((r * r - closest) / h2).sqrt();
        (low, high) = (low.max(center - half), high.min(center + half));
        if low >= high || low.is_nan() || high.is_nan() {
            return Some(None);
        }
        let lipschitz = h2.sqrt() + d.z.abs() * self.slope_bound;
        let mut stack = Vec::new();
        let samples = 64;
        for k in (0..samples).rev() {
            let (a, b) = (
                low + (high - low) * k as f64 / samples as f64,
                low + (high - low) * (k + 1) as f64 / samples as f64,
            );
            stack.push((a, self.gap(ray, a), b, self.gap(ray, b)));
        }
        while let Some((a, fa, b, fb)) = stack.pop() {
            // |f''| ≤ h²/r_min + D_z² max|R''|; f is monotone on [a, b] if
            // |f(b) − f(a)| > M (b − a)², and root-free if min |f| > M (b − a)²/8.
            let closest = (-(o.x * d.x + o.y * d.y) / h2).clamp(a, b);
            let curvature = h2 / (o + closest * d).truncate().length() + d.z * d.z * self.curvature_bound;
            let width = b - a;
            let single = (fb - fa).abs() > curvature * width * width || lipschitz * width <= TAU_REFERENCE;
            if (fa < 0.0) != (fb < 0.0) && single {
                let (mut lo, mut hi) = (a, b);
                for _ in 0..100 {
                    let m = 0.5 * (lo + hi);
                    if (self.gap(ray, m) < 0.0) == (fa < 0.0) {
                        lo = m;
                    } else {
                        hi = m;
                    }
                }
                let s = 0.5 * (lo + hi);
                // Clear if both lobes around it exceed τ and it is away from the rim.
                let reaches =
                    |x: f64, y: f64| (1..16).any(|k| self.gap(ray, x + (y - x) * k as f64 / 16.0).abs() > TAU_REFERENCE);
                let z = ray.at(s).z;
                let clear = (z - 2.0).abs() > TAU_REFERENCE && reaches(a.max(s - 1e-3), s) && reaches(s, b.min(s + 1e-3));
                return if clear { Some(Some(s)) } else { None };
            }
            let same_sign = (fa < 0.0) == (fb < 0.0);
            if same_sign && (fa.abs() + fb.abs() > lipschitz * width || fa.abs().min(fb.abs()) > curvature * width * width / 8.0)
            {
                continue;
            }
            if lipschitz * (b - a) <= TAU_REFERENCE {
                return None;
            }
            let m = 0.5 * (a + b);
            let fm = self.gap(ray, m);
            stack.push((m, fm, b, fb));
            stack.push((a, fa, m, fm));
        }
        Some(None)
    }
}

// ---------------------------------------------------------------------------
// Ray sets.

fn random_ray(random: &mut Random) -> Ray {
    let origin = DVec3::new(0.0, 0.0, 1.0) + 6.0 * random.direction();
    let target = DVec3::new(random.range(-1.2, 1.2), random.range(-1.2, 1.2), random.range(0.0, 2.0));
    Ray::new(origin, target - origin)
}

fn error_check_rays() -> Vec<Ray> {
    let mut random = Random(99);
    let mut rays = Vec::new();
    for i in 0..3000 {
        rays.push(match i % 4 {
            0 => random_ray(&mut random),
            1 => {
                // Horizontal: D_z ∈ {0, ±1e-12}.
                let height = random.range(0.0, 2.0);
                let phi = random.range(0.0, std::f64::consts::TAU);
                let origin = DVec3::new(6.0 * phi.cos(), 6.0 * phi.sin(), height);
                let target = DVec3::new(random.range(-1.0, 1.0), random.range(-1.0, 1.0), height);
                let mut direction = (target - origin).normalize();
                direction.z = [0.0, 1e-12, -1e-12][(i / 4) % 3];
                Ray::new(origin, direction)
            }
            2 => {
                // Grazing: tangent at a surface point, within 1e-6.
                let t = random.range(0.05, 0.95);
                let (p, tangent) = (point(&VASE, t), derivative(&VASE, t));
                let phi = random.range(0.0, std::f64::consts::TAU);
                let radial = DVec3::new(phi.cos(), phi.sin(), 0.0);
                let normal = (tangent.y * radial - tangent.x * DVec3::Z).normalize();
                let along = (tangent.x * radial + tangent.y * DVec3::Z).normalize();
                let angle = random.range(0.0, std::f64::consts::TAU);
                let direction =
                    (angle.cos() * along + angle.sin() * normal.cross(along) + random.range(-1e-6, 1e-6) * normal).normalize();
                let surface = DVec3::new(p.x * radial.x, p.x * radial.y, p.y) + random.range(-1e-6, 1e-6) * normal;
                Ray::new(surface - 6.0 * direction, direction)
            }
            _ => {
                let origin = DVec3::new(0.0, 0.0, 1.0) + 2e4 * random.direction();
                let target = DVec3::new(random.range(-1.2, 1.2), random.range(-1.2, 1.2), random.range(0.0, 2.0));
                Ray::new(origin, target - origin)
            }
        });
    }
    rays
}

/// Missed and false hits (or distance errors above 1e-4) of a method.
fn count_errors(rays: &[Ray], reference: &Reference, mut method: impl FnMut(&Ray) -> Option<f64>) -> (usize, usize, usize) {
    let (mut missed, mut false_hits, mut judged) = (0, 0, 0);
    for ray in rays {
        let Some(expected) = reference.first_hit(ray) else {
            continue;
        };
        judged += 1;
        match (expected, method(ray)) {
            (Some(_), None) => missed += 1,
            (None, Some(found)) => {
                if std::env::var("DEBUG_BENCH").is_ok() {
                    println!("false hit {found}: {ray:?}");
                }
                false_hits += 1
            }
            (Some(s), Some(found)) if (found - s).abs() > 1e-4 * s.max(2.0) => {
                if found > s {
                    missed += 1
                } else {
                    false_hits += 1
                }
            }
            _ => {}
        }
    }
    (missed, false_hits, judged)
}

fn benchmark(c: &mut Criterion) {
    let shape = Revolution::new(vec![VASE.to_vec()], false, DAffine3::IDENTITY).expect("valid vase");
    let reference = Reference::new();

    // Error counts on a fixed ray set.
    let rays = error_check_rays();
    let (missed, false_hits, judged) = count_errors(&rays, &reference, |ray| shape.intersect(ray, f64::INFINITY).map(|h| h.t));
    println!("errors, Bezier subdivision: {missed} missed, {false_hits} false hits of {judged} unambiguous rays");
    let mut random = Random(5);
    let (base_missed, base_false, _) = count_errors(&rays, &reference, |ray| baseline_intersect(ray, &mut random).map(|h| h.0));
    println!("errors, baseline Newton x200: {base_missed} missed, {base_false} false hits of {judged} unambiguous rays");

    // Hitting and missing rays (all inside the bounding box's reach).
    let mut random = Random(17);
    let (mut hitting, mut missing) = (Vec::new(), Vec::new());
    while hitting.len() < 512 || missing.len() < 512 {
        let ray = random_ray(&mut random);
        match reference.first_hit(&ray) {
            Some(Some(_)) if hitting.len() < 512 => hitting.push(ray),
            Some(None) if missing.len() < 512 => missing.push(ray),
            _ => {}
        }
    }

    // A direct timing summary (best of 5 passes, as the machine is shared),
    // then criterion's measurements.
    for (name, set) in [("hit", &hitting), ("miss", &missing)] {
        let (mut ours, mut baseline) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..5 {
            let start = Instant::now();
            for ray in set.iter() {
                black_box(shape.intersect(black_box(ray), f64::INFINITY));
            }
            ours = ours.min(start.elapsed().as_nanos() as f64 / set.len() as f64);
            let mut random = Random(3);
            let start = Instant::now();
            for ray in set.iter() {
                black_box(baseline_intersect(black_box(ray), &mut random));
            }
            baseline = baseline.min(start.elapsed().as_nanos() as f64 / set.len() as f64);
        }
        println!(
            "{name}: {ours:.0} ns/ray (subdivision) vs {baseline:.0} ns/ray (baseline), {:.0}x",
            baseline / ours
        );
    }

    let mut group = c.benchmark_group("revolution");
    group.sample_size(20);
    group.measurement_time(std::time::Duration::from_secs(3));
    for (name, set) in [("hit", &hitting), ("miss", &missing)] {
        group.throughput(Throughput::Elements(set.len() as u64));
        group.bench_function(format!("subdivision/{name}"), |b| {
            b.iter(|| {
                for ray in set.iter() {
                    black_box(shape.intersect(black_box(ray), f64::INFINITY));
                }
            })
        });
        group.bench_function(format!("baseline/{name}"), |b| {
            let mut random = Random(3);
            b.iter(|| {
                for ray in set.iter() {
                    black_box(baseline_intersect(black_box(ray), &mut random));
                }
            })
        });
    }
    group.finish();
}

criterion_group!(benches, benchmark);
criterion_main!(benches);
