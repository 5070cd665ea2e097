//! Stress test of `Revolution::intersect` against references written
//! independently of the solver (no code from `geometry::bezier` is used):
//!
//! - closed forms for profiles whose surfaces are quadrics: a cylinder and a
//!   cone (linear profiles) and a paraboloid (quadratic profile
//!   `(0,0), (R/2,0), (R,H)`, i.e. `z = H r² / R²`);
//! - for general vase profiles (5 and 10 control points, and a chain of two
//!   segments), all with `y` strictly increasing, the distance-like function
//!   `f(s) = r(s) − R(z(s))` along the ray, where `R(z)` inverts `y(t) = z`
//!   (table, then Newton). `f` is Lipschitz with constant
//!   `L = |D_xy| + |D_z| max|x'/y'|` (bounded by the control polygon), so a
//!   branch-and-bound search over `s` either proves an interval root-free
//!   (`|f(a)| + |f(b)| > L (b − a)`, or `min |f| > M (b − a)² / 8` with `M`
//!   a bound on `|f''|`), finds a sign change on a piece where `f` is provably
//!   monotone (`|f(b) − f(a)| > M (b − a)²`; then bisects it),
//!   or shrinks the interval below `τ / L`, where the ray comes within `τ` of
//!   the surface: a grazing touch.
//!
//! Tolerance: `τ = 1e-9 ×` the profile's size. The reference says "hit" when
//! it finds a sign change whose lobe (the excursion of `f` up to the next
//! sign change) exceeds `τ`, away (by `τ`) from an open rim. Sign changes
//! with smaller lobes, touches, and rim crossings are ambiguous: the solver
//! may report them or not. A solver hit is correct if it matches the first
//! clear crossing (relative distance error below 1e-4, measured as
//! `|Δs| / max(s, size)`), or an ambiguous event before it. A missed hit is a
//! clear crossing the solver skipped; a false hit is any other reported hit.
//! Rays that start on the surface (exactly, or offset by `Ray::spawn`) must
//! not report anything closer than `1e-6 ×` the size (self-intersection).
//!
//! Run with `cargo test --test revolution_stress -- --nocapture` to see the
//! counts. 1,040,000 rays in all.

use glam::{DAffine3, DQuat, DVec2, DVec3};
use prism::geometry::revolution::Revolution;
use prism::math::Ray;

// ---------------------------------------------------------------------------
// Independent curve evaluation and random numbers.

fn curve_point(points: &[DVec2], t: f64) -> DVec2 {
    // Bernstein sum, written out (not de Casteljau, to stay independent).
    let n = points.len() - 1;
    let mut sum = DVec2::ZERO;
    let mut binomial = 1.0;
    for (k, p) in points.iter().enumerate() {
        sum += *p * binomial * t.powi(k as i32) * (1.0 - t).powi((n - k) as i32);
        binomial = binomial * (n - k) as f64 / (k + 1) as f64;
    }
    sum
}

fn curve_derivative(points: &[DVec2], t: f64) -> DVec2 {
    let n = points.len() - 1;
    let mut differences = [DVec2::ZERO; 16];
    for (k, w) in points.windows(2).enumerate() {
        differences[k] = (w[1] - w[0]) * n as f64;
    }
    curve_point(&differences[..n], t)
}

/// SplitMix64: a small deterministic generator.
struct Random(u64);

impl Random {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
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
// Reference events along a ray (local space, parameter s = world t).

#[derive(Clone, Copy, Debug)]
enum Event {
    /// A sign change of f that the solver must find (if it is the first).
    Clear { s: f64, normal: DVec3 },
    /// Something the solver may or may not report, covering `[low, high]`.
    Ambiguous { low: f64, high: f64 },
}

/// The references' view of a profile: the local surface and its events.
trait Reference {
    fn size(&self) -> f64;
    /// Events with `s ∈ (s_start, ∞)`, ordered by `s`.
    fn events(&self, origin: DVec3, direction: DVec3, s_start: f64) -> Vec<Event>;
}

fn tolerance(size: f64) -> f64 {
    1e-9 * size
}

/// Quadric profiles: r² = P(z) on z ∈ [z_low, z_high], P quadratic in z.
struct Quadric {
    /// P(z) = p0 + p1 z + p2 z².
    p: [f64; 3],
    z_low: f64,
    z_high: f64,
    /// Radius at z_low and z_high (0 = a pole, not an open rim).
    rim_radius: [f64; 2],
    /// For cones: the sign R(z) must have (r0 + k (z − z0) ≥ 0).
    cone_line: Option<(f64, f64)>,
    size: f64,
}

impl Quadric {
    fn radius(&self, z: f64) -> f64 {
        match self.cone_line {
            Some((intercept, slope)) => intercept + slope * z,
            None => (self.p[0] + self.p[1] * z + self.p[2] * z * z).max(0.0).sqrt(),
        }
    }
    fn gap(&self, origin: DVec3, direction: DVec3, s: f64) -> f64 {
        let p = origin + s * direction;
        p.x.hypot(p.y) - self.radius(p.z)
    }
    fn normal(&self, point: DVec3) -> DVec3 {
        // Gradient of r² − P(z), outward (away from the axis).
        let dp = self.p[1] + 2.0 * self.p[2] * point.z;
        DVec3::new(2.0 * point.x, 2.0 * point.y, -dp).normalize()
    }
}

impl Reference for Quadric {
    fn size(&self) -> f64 {
        self.size
    }

    fn events(&self, far_origin: DVec3, d: DVec3, s_start: f64) -> Vec<Event> {
        let tau = tolerance(self.size);
        // Solve from the ray's closest approach to the local origin, so far
        // origins do not cancel digits; shift the roots back at the end.
        let shift = -far_origin.dot(d) / d.length_squared();
        let o = far_origin + shift * d;
        let s_start = s_start - shift;
        // (o_x + s d_x)² + (o_y + s d_y)² − P(o_z + s d_z) = A s² + B s + C.
        let a = d.x * d.x + d.y * d.y - self.p[2] * d.z * d.z;
        let b = 2.0 * (o.x * d.x + o.y * d.y) - self.p[1] * d.z - 2.0 * self.p[2] * o.z * d.z;
        let c = o.x * o.x + o.y * o.y - self.p[0] - self.p[1] * o.z - self.p[2] * o.z * o.z;
        let mut roots = Vec::new();
        let scale = a.abs().max(b.abs()).max(c.abs());
        if a.abs() <= 1e-14 * scale {
            if b != 0.0 {
                roots.push(-c / b);
            }
        } else {
            let discriminant = b * b - 4.0 * a * c;
            if discriminant >= 0.0 {
                let q = -0.5 * (b + b.signum() * discriminant.sqrt());
                roots.push(q / a);
                if q != 0.0 {
                    roots.push(c / q);
                }
            } else {
                // Near miss: the closest approach of the quadratic.
                let s = -b / (2.0 * a);
                let z = o.z + s * d.z;
                if s > s_start && z >= self.z_low && z <= self.z_high && self.gap(o, d, s).abs() <= tau {
                    roots.push(s);
                }
            }
        }
        roots.sort_by(f64::total_cmp);
        let mut events = Vec::new();
        for &s in &roots {
            let z = o.z + s * d.z;
            if s <= s_start || z < self.z_low - tau || z > self.z_high + tau {
                continue;
            }
            if self.cone_line.is_some() && self.radius(z) < -tau {
                continue;
            }
            let near_rim = [(self.z_low, self.rim_radius[0]), (self.z_high, self.rim_radius[1])]
                .iter()
                .any(|&(rim, radius)| radius > 0.0 && (z - rim).abs() <= tau);
            // The depth of the lobe between two close roots.
            let shallow = roots.len() == 2 && {
                let middle = 0.5 * (roots[0] + roots[1]);
                self.gap(o, d, middle).abs() <= tau
            };
            let grazing = roots.len() == 1 && a.abs() > 1e-14 * scale;
            if near_rim || shallow || grazing {
                let spread = if shallow { (roots[1] - roots[0]).abs() } else { 0.0 };
                events.push(Event::Ambiguous {
                    low: s + shift - spread - tau,
                    high: s + shift + spread + tau,
                });
            } else {
                events.push(Event::Clear {
                    s: s + shift,
                    normal: self.normal(o + s * d),
                });
            }
        }
        events
    }
}

/// General profiles: chains of Bezier segments with y strictly increasing.
struct Vase {
    segments: Vec<Vec<DVec2>>,
    /// Per segment, y at 1025 equally spaced t.
    tables: Vec<Vec<f64>>,
    z_low: f64,
    z_high: f64,
    radius: f64,
    /// Bound on |dR/dz| = |x'/y'| from the control polygons.
    slope_bound: f64,
    /// Bound on |d²R/dz²| = |x''y' − x'y''| / y'³, likewise.
    curvature_bound: f64,
    rim_radius: [f64; 2],
    size: f64,
}

const TABLE: usize = 1024;

impl Vase {
    fn new(segments: Vec<Vec<DVec2>>) -> Self {
        let tables = segments
            .iter()
            .map(|points| (0..=TABLE).map(|k| curve_point(points, k as f64 / TABLE as f64).y).collect())
            .collect();
        let (mut slope_bound, mut curvature_bound) = (0.0_f64, 0.0_f64);
        for points in &segments {
            // Derivatives of a Bezier curve are bounded by its control
            // polygon's differences: |c'| ≤ n max|Δ|, |c''| ≤ n(n−1) max|Δ²|.
            let n = (points.len() - 1) as f64;
            let first: Vec<DVec2> = points.windows(2).map(|w| w[1] - w[0]).collect();
            let second: Vec<DVec2> = first.windows(2).map(|w| w[1] - w[0]).collect();
            let dx = first.iter().map(|d| d.x.abs()).fold(0.0, f64::max);
            let dy_max = first.iter().map(|d| d.y.abs()).fold(0.0, f64::max);
            let dy = first.iter().map(|d| d.y).fold(f64::INFINITY, f64::min);
            assert!(dy > 0.0, "reference profiles need y strictly increasing");
            slope_bound = slope_bound.max(dx / dy);
            let ddx = second.iter().map(|d| d.x.abs()).fold(0.0, f64::max) * n * (n - 1.0);
            let ddy = second.iter().map(|d| d.y.abs()).fold(0.0, f64::max) * n * (n - 1.0);
            curvature_bound = curvature_bound.max((ddx * n * dy_max + n * dx * ddy) / (n * dy).powi(3));
        }
        let first = segments[0][0];
        let last = *segments.last().and_then(|s| s.last()).expect("points");
        let radius = segments.iter().flatten().map(|p| p.x).fold(0.0, f64::max);
        Self {
            z_low: first.y,
            z_high: last.y,
            radius,
            slope_bound,
            curvature_bound,
            rim_radius: [first.x, last.x],
            size: radius.max(first.y.abs()).max(last.y.abs()),
            segments,
            tables,
        }
    }

    /// The segment and t with y(t) = z.
    fn parameter_at_height(&self, z: f64) -> (usize, f64) {
        let segment = self
            .segments
            .iter()
            .position(|points| z <= points[points.len() - 1].y)
            .unwrap_or(self.segments.len() - 1);
        let points = &self.segments[segment];
        let table = &self.tables[segment];
        let k = table.partition_point(|&y| y <= z).clamp(1, TABLE);
        let (mut low, mut high) = ((k - 1) as f64 / TABLE as f64, k as f64 / TABLE as f64);
        let fraction = ((z - table[k - 1]) / (table[k] - table[k - 1])).clamp(0.0, 1.0);
        let mut t = low + fraction * (high - low);
        for _ in 0..30 {
            let residual = curve_point(points, t).y - z;
            if residual > 0.0 {
                high = t;
            } else {
                low = t;
            }
            let next = t - residual / curve_derivative(points, t).y;
            let next = if next > low && next < high { next } else { 0.5 * (low + high) };
            if (next - t).abs() <= 1e-16 || high - low <= 1e-16 {
                t = next;
                break;
            }
            t = next;
        }
        (segment, t)
    }

    fn gap(&self, o: DVec3, d: DVec3, s: f64) -> f64 {
        let p = o + s * d;
        let (segment, t) = self.parameter_at_height(p.z.clamp(self.z_low, self.z_high));
        p.x.hypot(p.y) - curve_point(&self.segments[segment], t).x
    }

    fn normal(&self, p: DVec3) -> DVec3 {
        let (segment, t) = self.parameter_at_height(p.z);
        let tangent = curve_derivative(&self.segments[segment], t);
        let radial = DVec2::new(p.x, p.y).normalize_or_zero();
        DVec3::new(tangent.y * radial.x, tangent.y * radial.y, -tangent.x).normalize()
    }

    /// A bound on |f''| over [a, b]: r'' = (h² − r'²)/r ≤ h²/r_min, and
    /// |d²R(z(s))/ds²| ≤ D_z² max|R''|. Infinite if the ray meets the axis.
    fn second_derivative_bound(&self, o: DVec3, d: DVec3, a: f64, b: f64) -> f64 {
        let h2 = d.x * d.x + d.y * d.y;
        let closest = if h2 > 0.0 {
            (-(o.x * d.x + o.y * d.y) / h2).clamp(a, b)
        } else {
            a
        };
        let r_min = (o + closest * d).truncate().length();
        h2 / r_min + d.z * d.z * self.curvature_bound
    }

    /// Branch and bound on [a, b] (see the module docs).
    #[allow(clippy::too_many_arguments)]
    fn search(&self, o: DVec3, d: DVec3, a: f64, fa: f64, b: f64, fb: f64, lipschitz: f64, out: &mut Vec<(f64, f64, bool)>) {
        let tau = tolerance(self.size);
        let width = b - a;
        let curvature = self.second_derivative_bound(o, d, a, b);
        // f = chord + e with |e'| ≤ M w (Rolle: e(a) = e(b) = 0), so f is
        // monotone, with one crossing, if |f(b) − f(a)| > M w².
        let single = (fb - fa).abs() > curvature * width * width || lipschitz * width <= tau;
        if (fa == 0.0 || (fa < 0.0) != (fb < 0.0)) && single {
            let (mut low, mut high, mut f_low) = (a, b, fa);
            for _ in 0..200 {
                let middle = 0.5 * (low + high);
                if middle <= low || middle >= high {
                    break;
                }
                let f = self.gap(o, d, middle);
                if (f < 0.0) == (f_low < 0.0) && f_low != 0.0 {
                    low = middle;
                    f_low = f;
                } else {
                    high = middle;
                }
            }
            out.push((low, high, true));
        } else if fa.abs() + fb.abs() > lipschitz * (b - a) {
            // Root-free by the Lipschitz bound.
        } else if (fa < 0.0) == (fb < 0.0) && fa.abs().min(fb.abs()) > curvature * width * width / 8.0 {
            // Root-free: f stays within M w²/8 of its chord (M ≥ |f''|).
        } else if lipschitz * (b - a) <= tau {
            out.push((a, b, false));
        } else {
            let middle = 0.5 * (a + b);
            let f = self.gap(o, d, middle);
            self.search(o, d, a, fa, middle, f, lipschitz, out);
            self.search(o, d, middle, f, b, fb, lipschitz, out);
        }
    }
}

impl Reference for Vase {
    fn size(&self) -> f64 {
        self.size
    }

    fn events(&self, o: DVec3, d: DVec3, s_start: f64) -> Vec<Event> {
        let tau = tolerance(self.size);
        // Clip to the slab of z and the bounding cylinder (f > 0 outside it).
        let (mut low, mut high) = (s_start, f64::INFINITY);
        if d.z != 0.0 {
            let (s0, s1) = ((self.z_low - o.z) / d.z, (self.z_high - o.z) / d.z);
            low = low.max(s0.min(s1));
            high = high.min(s0.max(s1));
        } else if o.z < self.z_low || o.z > self.z_high {
            return Vec::new();
        }
        let h2 = d.x * d.x + d.y * d.y;
        let r = self.radius * (1.0 + 1e-6);
        if h2 > 0.0 {
            let center = -(o.x * d.x + o.y * d.y) / h2;
            let closest = (o + center * d).truncate().length_squared();
            if closest > r * r {
                return Vec::new();
            }
            let half = ((r * r - closest) / h2).sqrt();
            low = low.max(center - half);
            high = high.min(center + half);
        }
        if low >= high || low.is_nan() || high.is_nan() {
            return Vec::new();
        }
        let lipschitz = h2.sqrt() + d.z.abs() * self.slope_bound;
        let samples = 32;
        let mut found = Vec::new();
        let mut previous = (low, self.gap(o, d, low));
        for k in 1..=samples {
            let s = low + (high - low) * k as f64 / samples as f64;
            let current = (s, self.gap(o, d, s));
            self.search(o, d, previous.0, previous.1, current.0, current.1, lipschitz, &mut found);
            previous = current;
        }
        // Classify: a crossing is clear if the lobes on both sides reach τ
        // and it is not at an open rim.
        let mut events = Vec::new();
        for (index, &(a, b, crossing)) in found.iter().enumerate() {
            let s = 0.5 * (a + b);
            if !crossing {
                events.push(Event::Ambiguous {
                    low: a - tau,
                    high: b + tau,
                });
                continue;
            }
            let lobe_reaches =
                |from: f64, to: f64| (1..16).any(|k| self.gap(o, d, from + (to - from) * k as f64 / 16.0).abs() > tau);
            let previous_end = if index > 0 { found[index - 1].1 } else { low };
            let next_start = found.get(index + 1).map_or(high, |e| e.0);
            let z = o.z + s * d.z;
            let near_rim = [(self.z_low, self.rim_radius[0]), (self.z_high, self.rim_radius[1])]
                .iter()
                .any(|&(rim, radius)| radius > 0.0 && (z - rim).abs() <= tau);
            if near_rim || !lobe_reaches(previous_end, s) || !lobe_reaches(s, next_start) {
                events.push(Event::Ambiguous {
                    low: previous_end - tau,
                    high: next_start + tau,
                });
            } else {
                events.push(Event::Clear {
                    s,
                    normal: self.normal(o + s * d),
                });
            }
        }
        events
    }
}

// ---------------------------------------------------------------------------
// Comparison and bookkeeping.

#[derive(Default, Debug)]
struct Tally {
    rays: usize,
    clear_hits: usize,
    clear_misses: usize,
    ambiguous: usize,
    missed: usize,
    false_hits: usize,
    max_relative_distance_error: f64,
    max_normal_angle: f64,
}

impl Tally {
    fn merge(&mut self, other: &Tally) {
        self.rays += other.rays;
        self.clear_hits += other.clear_hits;
        self.clear_misses += other.clear_misses;
        self.ambiguous += other.ambiguous;
        self.missed += other.missed;
        self.false_hits += other.false_hits;
        self.max_relative_distance_error = self.max_relative_distance_error.max(other.max_relative_distance_error);
        self.max_normal_angle = self.max_normal_angle.max(other.max_normal_angle);
    }
}

/// A profile under test: the solver's shape, its reference and its placement.
struct Case {
    name: String,
    shape: Revolution,
    reference: Box<dyn Reference>,
    to_world: DAffine3,
    /// Local-space bounds used to aim rays.
    radius: f64,
    z_low: f64,
    z_high: f64,
    /// Profile end points, for the closed-form axis check and on-surface starts.
    profile: Vec<Vec<DVec2>>,
}

impl Case {
    fn new(name: &str, profile: Vec<Vec<DVec2>>, reference: Box<dyn Reference>, to_world: DAffine3) -> Self {
        let shape = Revolution::new(profile.clone(), false, to_world).expect("valid profile");
        let points = profile.iter().flatten();
        let radius = points.clone().map(|p| p.x).fold(0.0, f64::max);
        let z_low = points.clone().map(|p| p.y).fold(f64::INFINITY, f64::min);
        let z_high = points.map(|p| p.y).fold(f64::NEG_INFINITY, f64::max);
        Self {
            name: name.into(),
            shape,
            reference,
            to_world,
            radius,
            z_low,
            z_high,
            profile,
        }
    }

    fn scale(&self) -> f64 {
        self.to_world.matrix3.x_axis.length()
    }

    fn surface_point(&self, random: &mut Random) -> DVec3 {
        let segment = &self.profile[(random.next_u64() % self.profile.len() as u64) as usize];
        let p = curve_point(segment, random.uniform());
        let phi = random.range(0.0, std::f64::consts::TAU);
        DVec3::new(p.x * phi.cos(), p.x * phi.sin(), p.y)
    }

    fn random_target(&self, random: &mut Random) -> DVec3 {
        DVec3::new(
            random.range(-self.radius, self.radius),
            random.range(-self.radius, self.radius),
            random.range(self.z_low, self.z_high),
        )
    }

    /// Checks one world ray; `s_start` excludes self-hits of on-surface starts.
    fn check(&self, ray: &Ray, s_start: f64, tally: &mut Tally) {
        tally.rays += 1;
        let to_local = self.to_world.inverse();
        let origin = to_local.transform_point3(ray.origin);
        let direction = to_local.transform_vector3(ray.direction);
        let events = self.reference.events(origin, direction, s_start);
        let hit = self.shape.intersect(ray, f64::INFINITY);
        let world_size = self.reference.size() * self.scale();
        let first_clear = events.iter().position(|e| matches!(e, Event::Clear { .. }));
        let Some(hit) = hit else {
            if first_clear.is_some() {
                tally.missed += 1;
                if tally.missed <= 3 {
                    println!("[{}] missed: {ray:?} events {events:?}", self.name);
                }
            } else if events.is_empty() {
                tally.clear_misses += 1;
            } else {
                tally.ambiguous += 1;
            }
            return;
        };
        if hit.t <= s_start {
            tally.false_hits += 1;
            println!("[{}] self-intersection at {}: {ray:?}", self.name, hit.t);
            return;
        }
        let candidates = &events[..first_clear.map_or(events.len(), |i| i + 1)];
        for event in candidates {
            match *event {
                Event::Clear { s, normal } => {
                    let error = (hit.t - s).abs() / s.max(world_size);
                    if error < 1e-4 {
                        tally.clear_hits += 1;
                        tally.max_relative_distance_error = tally.max_relative_distance_error.max(error);
                        let world_normal = (to_local.matrix3.transpose() * normal).normalize();
                        // Angle from the chord, accurate for small angles (acos is not).
                        let angle = 2.0 * (0.5 * (world_normal - hit.geometric_normal).length()).min(1.0).asin();
                        tally.max_normal_angle = tally.max_normal_angle.max(angle);
                        return;
                    }
                }
                Event::Ambiguous { low, high } => {
                    let slack = 1e-4 * hit.t.max(world_size);
                    if hit.t >= low - slack && hit.t <= high + slack {
                        tally.ambiguous += 1;
                        return;
                    }
                }
            }
        }
        let skipped = first_clear.is_some_and(|i| matches!(events[i], Event::Clear { s, .. } if hit.t > s));
        if skipped {
            tally.missed += 1;
        } else {
            tally.false_hits += 1;
        }
        if tally.missed + tally.false_hits <= 3 {
            println!(
                "[{}] wrong hit t = {} ({}): {ray:?} events {events:?}",
                self.name,
                hit.t,
                if skipped { "skipped nearer" } else { "false" }
            );
        }
    }
}

fn world_ray(case: &Case, local_origin: DVec3, local_direction: DVec3) -> Ray {
    Ray::new(
        case.to_world.transform_point3(local_origin),
        case.to_world.transform_vector3(local_direction),
    )
}

/// The ray categories of the issue, `count` rays each.
fn run_categories(case: &Case, count: usize, seed: u64) -> Vec<(&'static str, Tally)> {
    let mut random = Random(seed);
    let size = case.reference.size();
    let center = DVec3::new(0.0, 0.0, 0.5 * (case.z_low + case.z_high));
    let mut results = Vec::new();

    let mut tally = Tally::default();
    for _ in 0..count {
        let origin = center + 3.0 * size * random.direction();
        let target = case.random_target(&mut random);
        case.check(&world_ray(case, origin, target - origin), 0.0, &mut tally);
    }
    results.push(("random", tally));

    let mut tally = Tally::default();
    for _ in 0..count {
        // Tangent at a surface point, tilted and shifted by up to 1e-6.
        let segment = &case.profile[(random.next_u64() % case.profile.len() as u64) as usize];
        let t = random.range(0.02, 0.98);
        let (p, tangent) = (curve_point(segment, t), curve_derivative(segment, t));
        let phi = random.range(0.0, std::f64::consts::TAU);
        let radial = DVec3::new(phi.cos(), phi.sin(), 0.0);
        let point = DVec3::new(p.x * radial.x, p.x * radial.y, p.y);
        let normal = (tangent.y * radial - tangent.x * DVec3::Z).normalize();
        let along = (tangent.x * radial + tangent.y * DVec3::Z).normalize();
        let around = normal.cross(along);
        let angle = random.range(0.0, std::f64::consts::TAU);
        let in_plane = angle.cos() * along + angle.sin() * around;
        let direction = (in_plane + random.range(-1e-6, 1e-6) * normal).normalize();
        let offset = random.range(-1e-6, 1e-6) * size * normal;
        let origin = point + offset - 3.0 * size * direction;
        case.check(&world_ray(case, origin, direction), 0.0, &mut tally);
    }
    results.push(("grazing", tally));

    let mut tally = Tally::default();
    for i in 0..count {
        let dz = [0.0, 1e-12, -1e-12][i % 3];
        let height = random.range(case.z_low - 0.05 * size, case.z_high + 0.05 * size);
        let phi = random.range(0.0, std::f64::consts::TAU);
        let origin = DVec3::new(3.0 * size * phi.cos(), 3.0 * size * phi.sin(), height);
        let target = DVec3::new(
            random.range(-case.radius, case.radius),
            random.range(-case.radius, case.radius),
            height,
        );
        let mut direction = (target - origin).normalize();
        direction.z = dz;
        case.check(&world_ray(case, origin, direction), 0.0, &mut tally);
    }
    results.push(("horizontal", tally));

    let mut tally = Tally::default();
    for _ in 0..count {
        let origin = center + 3.0 * size * random.direction();
        let target = DVec3::new(0.0, 0.0, random.range(case.z_low, case.z_high));
        case.check(&world_ray(case, origin, target - origin), 0.0, &mut tally);
    }
    results.push(("through axis", tally));

    let mut tally = Tally::default();
    for _ in 0..count {
        let origin = center + 1e4 * size * random.direction();
        let target = case.random_target(&mut random);
        case.check(&world_ray(case, origin, target - origin), 0.0, &mut tally);
    }
    results.push(("far (1e4 x size)", tally));

    let mut tally = Tally::default();
    for _ in 0..count {
        let origin = case.surface_point(&mut random);
        case.check(&world_ray(case, origin, random.direction()), 1e-6 * size, &mut tally);
    }
    results.push(("start on surface", tally));

    let mut tally = Tally::default();
    let mut spawned = 0;
    while spawned < count {
        let origin = center + 3.0 * size * random.direction();
        let target = case.random_target(&mut random);
        let Some(hit) = case.shape.intersect(&world_ray(case, origin, target - origin), f64::INFINITY) else {
            continue;
        };
        let ray = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, random.direction());
        case.check(&ray, 1e-6 * size * case.scale(), &mut tally);
        spawned += 1;
    }
    results.push(("spawned from hits", tally));

    // Exactly along the axis: closed form, the poles (x = 0 ends) only.
    let mut tally = Tally::default();
    let first = case.profile[0][0];
    let last = *case.profile.last().and_then(|s| s.last()).expect("points");
    for i in 0..count {
        let up = i % 2 == 0;
        let height = random.range(case.z_low - size, case.z_high + size);
        let origin = DVec3::new(0.0, 0.0, height);
        let direction = if up { DVec3::Z } else { -DVec3::Z };
        let poles = [first, last]
            .into_iter()
            .filter(|p| p.x == 0.0)
            .map(|p| (p.y - height) * direction.z);
        let expected = poles.filter(|&s| s > 0.0).fold(f64::INFINITY, f64::min);
        let hit = case.shape.intersect(&world_ray(case, origin, direction), f64::INFINITY);
        tally.rays += 1;
        let world_size = size * case.scale();
        match (hit, expected.is_finite()) {
            (None, false) => tally.clear_misses += 1,
            (None, true) => tally.missed += 1,
            (Some(_), false) => tally.false_hits += 1,
            (Some(hit), true) => {
                let error = (hit.t - expected * case.scale()).abs() / (expected * case.scale()).max(world_size);
                if error < 1e-4 {
                    tally.clear_hits += 1;
                    tally.max_relative_distance_error = tally.max_relative_distance_error.max(error);
                } else {
                    tally.false_hits += 1;
                }
            }
        }
    }
    results.push(("along the axis", tally));
    results
}

// ---------------------------------------------------------------------------
// Profiles.

/// A similarity with exact arithmetic on directions (translation and scale
/// 2), so D_z = 0 stays exactly 0 in local space.
fn exact_placement() -> DAffine3 {
    DAffine3::from_scale_rotation_translation(DVec3::splat(2.0), DQuat::IDENTITY, DVec3::new(3.0, -1.0, 0.5))
}

fn rotated_placement(seed: u64) -> DAffine3 {
    let mut random = Random(seed);
    let axis = random.direction();
    DAffine3::from_scale_rotation_translation(
        DVec3::splat(random.range(0.5, 3.0)),
        DQuat::from_axis_angle(axis, random.range(0.0, 6.0)),
        DVec3::new(random.range(-5.0, 5.0), random.range(-5.0, 5.0), random.range(-5.0, 5.0)),
    )
}

fn quadric_cases(to_world: DAffine3) -> Vec<Case> {
    let (r0, r1, height) = (1.0, 0.3, 2.0);
    let slope = (r1 - r0) / height;
    let cylinder = Quadric {
        p: [0.81, 0.0, 0.0],
        z_low: -1.0,
        z_high: 1.0,
        rim_radius: [0.9, 0.9],
        cone_line: None,
        size: 1.0,
    };
    let cone = Quadric {
        p: [r0 * r0, 2.0 * r0 * slope, slope * slope],
        z_low: 0.0,
        z_high: height,
        rim_radius: [r0, r1],
        cone_line: Some((r0, slope)),
        size: height,
    };
    // x = R t, y = H t²: z = H r² / R².
    let (radius, top) = (1.5, 2.0);
    let paraboloid = Quadric {
        p: [0.0, radius * radius / top, 0.0],
        z_low: 0.0,
        z_high: top,
        rim_radius: [0.0, radius],
        cone_line: None,
        size: top,
    };
    vec![
        Case::new(
            "cylinder",
            vec![vec![DVec2::new(0.9, -1.0), DVec2::new(0.9, 1.0)]],
            Box::new(cylinder),
            to_world,
        ),
        Case::new(
            "cone",
            vec![vec![DVec2::new(r0, 0.0), DVec2::new(r1, height)]],
            Box::new(cone),
            to_world,
        ),
        Case::new(
            "paraboloid",
            vec![vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(0.5 * radius, 0.0),
                DVec2::new(radius, top),
            ]],
            Box::new(paraboloid),
            to_world,
        ),
    ]
}

fn random_vase(random: &mut Random, points: usize, pole: bool) -> Vec<DVec2> {
    let mut y = 0.0;
    (0..points)
        .map(|i| {
            let x = if i == 0 && pole { 0.0 } else { random.range(0.1, 1.4) };
            let point = DVec2::new(x, y);
            y += random.range(0.15, 0.6);
            point
        })
        .collect()
}

fn vase_cases(to_world: DAffine3, seed: u64) -> Vec<Case> {
    let mut random = Random(seed);
    let fixed = vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(1.2, 0.1),
        DVec2::new(0.3, 0.9),
        DVec2::new(0.9, 1.4),
        DVec2::new(0.5, 2.0),
    ];
    let mut profiles = vec![("vase", vec![fixed])];
    for i in 0..4 {
        profiles.push(("random 5-point vase", vec![random_vase(&mut random, 5, i % 2 == 0)]));
    }
    profiles.push(("random 10-point vase", vec![random_vase(&mut random, 10, true)]));
    // A chain of two cubic segments, joined with a continuous tangent.
    let lower = vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.1),
        DVec2::new(1.1, 0.6),
        DVec2::new(0.7, 1.0),
    ];
    let upper = vec![
        DVec2::new(0.7, 1.0),
        DVec2::new(0.3, 1.4),
        DVec2::new(0.4, 1.8),
        DVec2::new(0.8, 2.1),
    ];
    profiles.push(("two-segment chain", vec![lower, upper]));
    profiles
        .into_iter()
        .map(|(name, profile)| {
            let reference = Vase::new(profile.clone());
            Case::new(name, profile, Box::new(reference), to_world)
        })
        .collect()
}

fn run(cases: Vec<Case>, rays_per_category: usize, seed: u64) -> Tally {
    let mut total = Tally::default();
    for (index, case) in cases.iter().enumerate() {
        let start = std::time::Instant::now();
        let results = run_categories(case, rays_per_category, seed + index as u64);
        println!("{} took {:?}", case.name, start.elapsed());
        for (category, tally) in results {
            println!(
                "{:<22} {:<18} rays {:>6}  hits {:>6}  misses {:>6}  ambiguous {:>4}  missed {}  false {}  max rel. distance error {:.1e}  max normal angle {:.1e} rad",
                case.name,
                category,
                tally.rays,
                tally.clear_hits,
                tally.clear_misses,
                tally.ambiguous,
                tally.missed,
                tally.false_hits,
                tally.max_relative_distance_error,
                tally.max_normal_angle
            );
            total.merge(&tally);
        }
    }
    println!("TOTAL {total:?}");
    assert_eq!(total.missed, 0, "missed hits");
    assert_eq!(total.false_hits, 0, "false hits");
    assert!(total.max_relative_distance_error < 1e-4);
    assert!(total.max_normal_angle < 1e-6, "normal error {}", total.max_normal_angle);
    total
}

/// Rays per category and profile; 8 categories × 10 profiles in each of the
/// two placements below gives 1,040,000 rays.
const RAYS_PER_CATEGORY: usize = 6_500;

#[test]
fn quadrics_and_vases_in_exact_placement() {
    let mut cases = quadric_cases(exact_placement());
    cases.extend(vase_cases(exact_placement(), 11));
    run(cases, RAYS_PER_CATEGORY, 1);
}

#[test]
fn quadrics_and_vases_rotated_and_scaled() {
    let mut cases = quadric_cases(rotated_placement(5));
    cases.extend(vase_cases(rotated_placement(7), 23));
    run(cases, RAYS_PER_CATEGORY, 1000);
}
