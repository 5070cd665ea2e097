//! Light by way of a smooth ball: the paths from a point x outside a sphere
//! to a given point y that either refract in, cross it and refract out (a
//! glass ball, [`Bounce::Through`]) or reflect off it (a mirror ball,
//! [`Bounce::Off`]), and how much a bundle of them spreads on the way.
//!
//! This is the sphere's case of manifold next-event estimation (Hanika,
//! Droske and Fascione 2015; Zeltner, Georgiev and Jakob 2020), solved
//! without Newton steps in three dimensions: a ray that meets a sphere stays
//! in the plane through the sphere's centre that contains it (the normals
//! there lie in that plane), so every path from x to y lies in the plane of
//! x, y and the centre, and is one root of a function of one variable, the
//! ray's impact parameter (for reflection this is Alhazen's problem). The roots are bracketed by a fixed scan and
//! refined by regula falsi. A scan can miss two roots that fall between
//! neighbouring samples (near a fold of the caustic); the estimator built
//! on this therefore claims only the paths it finds, and
//! [`BallOptics::finds`] lets the path tracer give the rest to BSDF sampling,
//! so nothing is lost or counted twice.

use arrayvec::ArrayVec;
use glam::{DVec2, DVec3};

/// Most paths reported between one pair of points (a ball lens gives at
/// most three in its plane: the caustic has folds, not loops).
pub const MAX_PATHS: usize = 4;

/// Intervals of the impact parameter over (−1, 1) that bracket the roots
/// of paths through the ball.
const SCAN_SAMPLES: usize = 16;

/// Impact parameters closer to grazing than this are not used: the two
/// crossings transmit almost nothing there, and the difference quotients
/// of [`BallOptics::area_per_solid_angle`] need room on both sides.
const MAX_IMPACT: f64 = 1.0 - 1e-4;

/// Two paths are the same if their impact parameters agree this closely
/// (roots are refined to about 1e-14; distinct roots further apart than
/// this are all but certain).
const SAME_PATH: f64 = 1e-7;

/// Relative margin of [`BallOptics::hidden_behind_tangent_plane`], far
/// above the rounding of the paths' exit directions.
const TANGENT_PLANE_MARGIN: f64 = 1e-3;

/// A smooth sphere, as a lens or a convex mirror.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BallOptics {
    /// Centre, world space.
    pub center: DVec3,
    /// Radius (positive).
    pub radius: f64,
    /// Index of refraction inside over outside (not 1) for light passing
    /// through; not read for reflection.
    pub ior: f64,
}

/// How a path meets the ball.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bounce {
    /// Refracts in, crosses, refracts out.
    Through,
    /// Reflects off the outside.
    Off,
}

/// One path x → entry → exit → y through the ball (entry and exit are one
/// point for a reflection).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BallPath {
    /// Unit direction leaving x.
    pub direction: DVec3,
    /// Where the path enters the ball.
    pub entry: DVec3,
    /// Where it leaves.
    pub exit: DVec3,
    /// Unit direction after leaving, towards y.
    pub exit_direction: DVec3,
    /// Cosine of the angle of incidence, which for a path through is also
    /// the angle of emergence (the chord is symmetric).
    pub cos_incidence: f64,
    /// The ray's distance from the centre over the radius, signed (the sine
    /// of the angle of incidence): the root's coordinate.
    impact: f64,
}

/// The plane of x, y and the centre: origin at the centre, the first axis
/// towards x, the second towards y's side.
#[derive(Clone, Copy, Debug)]
struct Plane {
    towards_x: DVec3,
    across: DVec3,
    /// Distance of x from the centre.
    x_distance: f64,
    /// The radius over that distance: sin α = impact · this (see
    /// [`BallOptics::planar_path`]), a product where a division would sit
    /// on every evaluation of the scan and the refinement.
    aim_scale: f64,
    /// y in the plane's coordinates.
    y: DVec2,
}

/// Where a ray with a given impact parameter leaves the ball, in the plane.
#[derive(Clone, Copy, Debug)]
struct PlanarPath {
    direction: DVec2,
    entry: DVec2,
    exit: DVec2,
    exit_direction: DVec2,
    cos_incidence: f64,
}

impl BallOptics {
    /// Every path from `x` through the ball to `y` the scan finds (see the
    /// module notes), at impact parameters below [`MAX_IMPACT`]. Empty if
    /// either point is not outside the ball or the three points are (all
    /// but) on one line, where the paths form a cone rather than points.
    pub fn paths(&self, bounce: Bounce, x: DVec3, y: DVec3) -> ArrayVec<BallPath, MAX_PATHS> {
        let mut paths = ArrayVec::new();
        let Some(plane) = self.plane(x, y) else {
            return paths;
        };
        // Which side of the exit ray's line y is on (the perpendicular
        // component of the way to y), and whether ahead of the exit point
        // (negative: behind it, not a path).
        let miss = |impact: f64| {
            let path = self.planar_path(bounce, plane.aim_scale, impact);
            let to_y = plane.y - path.exit;
            (path.exit_direction.perp_dot(to_y), path.exit_direction.dot(to_y))
        };
        // A reflection reaches y's side of the line from x through the
        // centre only from that side of the ball (positive impact): the
        // reflected ray leaves a point on the other side heading further
        // into it. And a convex mirror shows a point once (Alhazen), so
        // one bracket holds the root. Paths through cross the line, and
        // inside the caustic three reach the same point.
        let (first, samples) = match bounce {
            Bounce::Through => (-MAX_IMPACT, SCAN_SAMPLES),
            Bounce::Off => (0.0, 1),
        };
        let step = (MAX_IMPACT - first) / samples as f64;
        let mut low = first;
        let (mut low_miss, mut low_ahead) = miss(low);
        for i in 1..=samples {
            let high = first + step * i as f64;
            let (high_miss, high_ahead) = miss(high);
            // A sign change in a narrow bracket of the scan through the ball
            // where y lies behind the exit point at both ends is a line
            // through y that light would have to travel backwards: not
            // refined (most of a glass ball's brackets under a light above
            // it). Only a bracket in which `ahead` changed sign twice could
            // hide a path this way; as for every path the scan misses, BSDF
            // sampling then keeps it (see the module notes). The mirror's one
            // bracket spans every impact a reflection towards y can have, so
            // its root is always refined.
            let behind = bounce == Bounce::Through && low_ahead <= 0.0 && high_ahead <= 0.0;
            if (low_miss < 0.0) != (high_miss < 0.0) && !behind {
                let impact = refine(&miss, (low, low_miss), (high, high_miss));
                let (_, ahead) = miss(impact);
                if ahead > 0.0 && !paths.is_full() {
                    let planar = self.planar_path(bounce, plane.aim_scale, impact);
                    paths.push(plane.lift(self.center, planar, impact));
                }
            }
            (low, low_miss, low_ahead) = (high, high_miss, high_ahead);
        }
        paths
    }

    /// Whether the whole ball lies behind the tangent plane at the point `y`
    /// of a surface with unit normal `normal`: n · (c − y) < −R, with a
    /// margin. Then every exit point e has n · (e − y) < 0, so no path from
    /// the ball reaches y from the side `normal` faces (a one-sided light's
    /// point there receives none, whatever x), and the root search can be
    /// skipped.
    pub fn hidden_behind_tangent_plane(&self, y: DVec3, normal: DVec3) -> bool {
        normal.dot(self.center - y) < -self.radius * (1.0 + TANGENT_PLANE_MARGIN)
    }

    /// Whether [`paths`](Self::paths) from `x` to `y` includes the one
    /// leaving `x` along `direction`: the test that partitions the paths
    /// through the ball between the estimator using `paths` and BSDF sampling.
    pub fn finds(&self, bounce: Bounce, x: DVec3, y: DVec3, direction: DVec3) -> bool {
        self.path_along(bounce, x, y, direction).is_some()
    }

    /// The path of [`paths`](Self::paths) from `x` to `y` that leaves `x`
    /// along `direction`, if the scan finds it.
    pub fn path_along(&self, bounce: Bounce, x: DVec3, y: DVec3, direction: DVec3) -> Option<BallPath> {
        let plane = self.plane(x, y)?;
        // The impact parameter of `direction`: its distance from the centre
        // over the radius, signed by the side of the line from x to the centre.
        let impact = plane.x_distance * direction.dot(plane.across) / self.radius;
        self.paths(bounce, x, y)
            .into_iter()
            .find(|path| (path.impact - impact).abs() < SAME_PATH)
    }

    /// Area on the plane through `y` with normal `normal` per unit solid
    /// angle at `x`, for rays near `path` (the ball's lens effect: the
    /// inverse of the generalised geometry term without its cosines). By
    /// central differences over two orthogonal tilts of the direction; the
    /// tilt's size balances truncation (h²) against rounding (ε/h).
    /// `None` if a tilted ray misses the ball or the plane.
    pub fn area_per_solid_angle(&self, bounce: Bounce, x: DVec3, path: &BallPath, y: DVec3, normal: DVec3) -> Option<f64> {
        const TILT: f64 = 1e-6;
        let (u, v) = path.direction.any_orthonormal_pair();
        let landing = |tilt: DVec3| -> Option<DVec3> {
            let (exit, exit_direction) = self.trace(bounce, x, (path.direction + tilt).normalize())?;
            let along = exit_direction.dot(normal);
            let distance = (y - exit).dot(normal) / along;
            (distance > 0.0 && distance.is_finite()).then(|| exit + exit_direction * distance)
        };
        let du = landing(u * TILT)? - landing(-u * TILT)?;
        let dv = landing(v * TILT)? - landing(-v * TILT)?;
        // d(direction) = da·u + db·v to first order: unit area in (a, b) is unit solid angle.
        let area = du.cross(dv).length() / (4.0 * TILT * TILT);
        (area.is_finite() && area > 0.0).then_some(area)
    }

    /// The ray from `x` along unit `direction` through or off the ball:
    /// where it leaves and in which direction, if it meets the ball.
    pub fn trace(&self, bounce: Bounce, x: DVec3, direction: DVec3) -> Option<(DVec3, DVec3)> {
        let to_x = x - self.center;
        let along = to_x.dot(direction);
        let discriminant = along * along - (to_x.length_squared() - self.radius * self.radius);
        if along >= 0.0 || discriminant <= 0.0 {
            return None;
        }
        let entry = x + direction * (-along - discriminant.sqrt());
        let normal = (entry - self.center) / self.radius;
        let cos_incidence = (-direction.dot(normal)).clamp(0.0, 1.0);
        if bounce == Bounce::Off {
            return Some((entry, reflect(direction, normal, cos_incidence)));
        }
        let sin2_incidence = 1.0 - cos_incidence * cos_incidence;
        let (inside, cos_inside) = refract_in(direction, normal, cos_incidence, sin2_incidence, self.ior.recip());
        let exit = entry + inside * (2.0 * self.radius * cos_inside);
        let exit_normal = (exit - self.center) / self.radius;
        Some((exit, refract_out(inside, exit_normal, cos_inside, cos_incidence, self.ior)))
    }

    fn plane(&self, x: DVec3, y: DVec3) -> Option<Plane> {
        let (to_x, to_y) = (x - self.center, y - self.center);
        let x_distance = to_x.length();
        let outside = |distance: f64| distance > self.radius * (1.0 + 1e-9);
        if !outside(x_distance) || !outside(to_y.length()) {
            return None;
        }
        let towards_x = to_x / x_distance;
        let off_line = to_y - towards_x * to_y.dot(towards_x);
        let off = off_line.length();
        if off <= 1e-9 * to_y.length() {
            return None;
        }
        let across = off_line / off;
        Some(Plane {
            towards_x,
            across,
            x_distance,
            aim_scale: self.radius / x_distance,
            y: DVec2::new(to_y.dot(towards_x), off),
        })
    }

    /// The path in the plane (centre at the origin, x at (`x_distance`, 0))
    /// of the ray whose distance from the centre is `impact` radii. With θ
    /// the angle of incidence (sin θ = impact) and α the ray's angle to the
    /// line from x to the centre (sin α = R sin θ / |x|), the ray meets the
    /// circle at polar angle θ − α: the triangle x, centre, entry.
    /// `aim_scale` is R / |x|.
    ///
    /// The root scan and its refinement evaluate this a few dozen times per
    /// connection, each step of the refinement waiting on the one before,
    /// so its chain of dependent operations is kept short: sin²θ is the
    /// impact squared rather than 1 − cos²θ (so Snell's law does not wait
    /// for cos θ's square root), and the divisions by R, |x| and η are
    /// products with reciprocals that do not depend on the impact (R/|x|
    /// made once per pair of points).
    fn planar_path(&self, bounce: Bounce, aim_scale: f64, impact: f64) -> PlanarPath {
        let radius = self.radius;
        let sin2_incidence = impact * impact;
        let cos_incidence = (1.0 - sin2_incidence).sqrt();
        let sin_aim = impact * aim_scale;
        let cos_aim = (1.0 - sin_aim * sin_aim).sqrt();
        let entry_normal = DVec2::new(
            cos_incidence * cos_aim + impact * sin_aim,
            impact * cos_aim - cos_incidence * sin_aim,
        );
        let direction = DVec2::new(-cos_aim, sin_aim);
        let entry = entry_normal * radius;
        if bounce == Bounce::Off {
            return PlanarPath {
                direction,
                entry,
                exit: entry,
                exit_direction: reflect(direction, entry_normal, cos_incidence),
                cos_incidence,
            };
        }
        let (inside, cos_inside) = refract_in(direction, entry_normal, cos_incidence, sin2_incidence, self.ior.recip());
        let exit = entry + inside * (2.0 * radius * cos_inside);
        let exit_direction = refract_out(inside, exit * radius.recip(), cos_inside, cos_incidence, self.ior);
        PlanarPath {
            direction,
            entry,
            exit,
            exit_direction,
            cos_incidence,
        }
    }
}

impl Plane {
    fn lift(&self, center: DVec3, path: PlanarPath, impact: f64) -> BallPath {
        let point = |p: DVec2| center + self.towards_x * p.x + self.across * p.y;
        let vector = |v: DVec2| (self.towards_x * v.x + self.across * v.y).normalize();
        BallPath {
            direction: vector(path.direction),
            entry: point(path.entry),
            exit: point(path.exit),
            exit_direction: vector(path.exit_direction),
            cos_incidence: path.cos_incidence,
            impact,
        }
    }
}

/// Vectors of two or three dimensions, for refraction in the plane and in space.
trait Vector: Copy + std::ops::Add<Output = Self> + std::ops::Sub<Output = Self> + std::ops::Mul<f64, Output = Self> {}
impl Vector for DVec2 {}
impl Vector for DVec3 {}

/// The mirror direction off the outward `normal`.
fn reflect<V: Vector>(direction: V, normal: V, cos_incidence: f64) -> V {
    direction + normal * (2.0 * cos_incidence)
}

/// Snell's law entering the ball (pbrt-v4 eq. 9.4 with η = `ior`): the
/// direction inside and the cosine of its angle to the inward normal.
/// `normal` is the outward normal, `cos_incidence` = −direction · normal,
/// `sin2_incidence` = 1 − cos², `inverse_ior` = 1/η.
fn refract_in<V: Vector>(direction: V, normal: V, cos_incidence: f64, sin2_incidence: f64, inverse_ior: f64) -> (V, f64) {
    let sin2_inside = sin2_incidence * (inverse_ior * inverse_ior);
    let cos_inside = (1.0 - sin2_inside).max(0.0).sqrt();
    (
        direction * inverse_ior + normal * (cos_incidence * inverse_ior - cos_inside),
        cos_inside,
    )
}

/// Snell's law leaving it, where the angles are those of entry in reverse
/// (relative index 1/`ior`; no total internal reflection on a symmetric chord).
fn refract_out<V: Vector>(inside: V, normal: V, cos_inside: f64, cos_incidence: f64, ior: f64) -> V {
    inside * ior - normal * (ior * cos_inside - cos_incidence)
}

/// A root of `miss` between two impact parameters where its first value
/// changes sign: regula falsi with the Illinois modification (Dowell and
/// Jarratt 1971), which converges superlinearly and keeps the bracket.
fn refine(miss: &impl Fn(f64) -> (f64, f64), mut low: (f64, f64), mut high: (f64, f64)) -> f64 {
    let mut kept_side = 0i8;
    for _ in 0..64 {
        let width = high.0 - low.0;
        if width.abs() < 1e-14 {
            break;
        }
        let denominator = high.1 - low.1;
        let mut impact = low.0 - low.1 * width / denominator;
        // Stay strictly inside the bracket (a flat secant can leave it).
        let inside = impact > low.0.min(high.0) && impact < low.0.max(high.0);
        if !inside || !impact.is_finite() {
            impact = 0.5 * (low.0 + high.0);
        }
        let value = miss(impact).0;
        if value == 0.0 {
            return impact;
        }
        if (value < 0.0) == (low.1 < 0.0) {
            low = (impact, value);
            if kept_side == 1 {
                high.1 *= 0.5;
            }
            kept_side = 1;
        } else {
            high = (impact, value);
            if kept_side == -1 {
                low.1 *= 0.5;
            }
            kept_side = -1;
        }
    }
    0.5 * (low.0 + high.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball() -> BallOptics {
        BallOptics {
            center: DVec3::new(1.0, 2.0, -0.5),
            radius: 1.5,
            ior: 1.5,
        }
    }

    /// Pairs of points around the ball: x on one side, y anywhere (behind
    /// the ball for paths through, all around for reflections).
    fn point_pairs(ball: &BallOptics, bounce: Bounce) -> impl Iterator<Item = (DVec3, DVec3)> {
        let center = ball.center;
        (0..400).map(move |i| {
            let a = i as f64 * 0.618_034;
            let x = center + DVec3::new(3.0 + a.fract(), (a * 1.7).fract() - 0.5, (a * 2.3).fract() - 0.5);
            let toward = match bounce {
                Bounce::Through => DVec3::new(
                    -2.0 - 6.0 * (a * 3.1).fract(),
                    4.0 * (a * 0.7).fract() - 2.0,
                    2.0 * (a * 1.3).fract() - 1.0,
                ),
                Bounce::Off => DVec3::new(
                    8.0 * (a * 3.1).fract() - 2.0,
                    6.0 * (a * 0.7).fract() - 3.0,
                    6.0 * (a * 1.3).fract() - 3.0,
                ),
            };
            (x, center + toward.normalize() * (2.0 + 4.0 * (a * 0.37).fract()))
        })
    }

    /// Every path found, traced in three dimensions from x along its
    /// direction, passes through y; and it obeys Snell's law at both
    /// crossings, or the law of reflection.
    #[test]
    fn paths_found_reach_y() {
        let ball = ball();
        for bounce in [Bounce::Through, Bounce::Off] {
            let mut found = 0;
            for (x, y) in point_pairs(&ball, bounce) {
                for path in ball.paths(bounce, x, y) {
                    found += 1;
                    let (exit, exit_direction) = ball.trace(bounce, x, path.direction).expect("meets the ball");
                    assert!((exit - path.exit).length() < 1e-9, "exit {exit} vs {}", path.exit);
                    let to_y = y - exit;
                    let off = (to_y - exit_direction * to_y.dot(exit_direction)).length();
                    assert!(off < 1e-8 * to_y.length(), "{bounce:?}: misses y by {off}");
                    let normal = (path.entry - ball.center) / ball.radius;
                    match bounce {
                        Bounce::Through => {
                            let inside = (path.exit - path.entry).normalize();
                            let sin_out = path.direction.cross(normal).length();
                            let sin_in = inside.cross(normal).length();
                            assert!((sin_out - ball.ior * sin_in).abs() < 1e-9);
                        }
                        Bounce::Off => {
                            assert!((path.direction.dot(normal) + exit_direction.dot(normal)).abs() < 1e-12);
                            assert!(path.direction.cross(exit_direction).dot(normal).abs() < 1e-12, "out of plane");
                        }
                    }
                }
            }
            assert!(found > 300, "{bounce:?}: only {found} paths");
        }
    }

    /// No path reaches the front of a point whose tangent plane has the
    /// ball behind it; and the test is not looser than it need be: points
    /// whose tangent plane cuts the ball (−R < n · (c − y) < 0) do receive
    /// paths from the front.
    #[test]
    fn no_path_reaches_the_front_of_a_point_whose_tangent_plane_hides_the_ball() {
        let ball = ball();
        let (mut hidden, mut cut_and_reached) = (0, 0);
        for bounce in [Bounce::Through, Bounce::Off] {
            for (i, (x, y)) in point_pairs(&ball, bounce).enumerate() {
                let paths = ball.paths(bounce, x, y);
                for k in 0..24 {
                    // Normals spread over the sphere (a golden-angle spiral).
                    let z = 1.0 - (2 * k + 1) as f64 / 24.0;
                    let azimuth = 2.399_963 * (k + i) as f64;
                    let radial = (1.0 - z * z).sqrt();
                    let normal = DVec3::new(radial * azimuth.cos(), radial * azimuth.sin(), z);
                    for path in &paths {
                        let from_front = normal.dot(-path.exit_direction) > 0.0;
                        if ball.hidden_behind_tangent_plane(y, normal) {
                            hidden += 1;
                            assert!(!from_front, "{bounce:?}: a path reaches the front of {y} (normal {normal})");
                        } else if from_front && normal.dot(ball.center - y) < 0.0 {
                            cut_and_reached += 1;
                        }
                    }
                }
            }
        }
        assert!(
            hidden > 1000 && cut_and_reached > 100,
            "{hidden} hidden, {cut_and_reached} cut and reached"
        );
    }

    /// Behind a ball lit from far away, points near the axis between the
    /// marginal and the paraxial focus see three paths (inside the
    /// caustic), points far off it one; a convex mirror shows each point
    /// once. The scan finds as many as a scan 10⁴ times finer, the triples
    /// included, and `finds` recognises each.
    #[test]
    fn finds_every_path_a_fine_scan_finds() {
        let ball = BallOptics {
            center: DVec3::ZERO,
            radius: 1.0,
            ior: 1.5,
        };
        let x = DVec3::new(1e3, 0.0, 0.0);
        let mut triples = 0;
        for bounce in [Bounce::Through, Bounce::Off] {
            for i in 0..40 {
                let y = match bounce {
                    Bounce::Through => DVec3::new(-1.1 - 0.02 * i as f64, 0.003 + 0.01 * (i % 7) as f64, 0.0),
                    Bounce::Off => DVec3::new(3.0 - 0.15 * i as f64, 1.2 + 0.05 * (i % 7) as f64, 0.3),
                };
                let plane = ball.plane(x, y).expect("a plane");
                let n = 160_000;
                let mut count = 0;
                let mut previous = None;
                for k in 0..=n {
                    let impact = -MAX_IMPACT + 2.0 * MAX_IMPACT * k as f64 / n as f64;
                    let path = ball.planar_path(bounce, plane.aim_scale, impact);
                    let to_y = plane.y - path.exit;
                    let side = path.exit_direction.perp_dot(to_y) < 0.0;
                    let ahead = path.exit_direction.dot(to_y) > 0.0;
                    if previous.is_some_and(|p| p != side) && ahead {
                        count += 1;
                    }
                    previous = Some(side);
                }
                let paths = ball.paths(bounce, x, y);
                assert_eq!(paths.len(), count, "{bounce:?} at {y}");
                if bounce == Bounce::Off {
                    assert_eq!(count, 1, "a convex mirror at {y}");
                }
                triples += usize::from(count == 3);
                for path in &paths {
                    assert!(ball.finds(bounce, x, y, path.direction));
                    let tilted = (path.direction + DVec3::new(0.0, 1e-5, 0.0)).normalize();
                    assert!(!ball.finds(bounce, x, y, tilted));
                }
            }
        }
        assert!(triples >= 5, "{triples} points inside the caustic");
    }

    /// The spread against an independent measure: the area of the image on
    /// y's plane of a small square of directions around each path (by the
    /// shoelace formula over its traced boundary) over its solid angle.
    #[test]
    fn spread_matches_the_area_of_a_traced_square() {
        let ball = ball();
        let x = ball.center + DVec3::new(4.0, 0.5, 0.2);
        let normal = DVec3::new(1.0, 0.3, -0.2).normalize();
        for (bounce, y) in [
            (Bounce::Through, ball.center + DVec3::new(-5.0, -0.4, 0.9)),
            (Bounce::Off, ball.center + DVec3::new(2.0, 3.0, -1.0)),
        ] {
            let paths = ball.paths(bounce, x, y);
            assert!(!paths.is_empty());
            for path in paths {
                let spread = ball.area_per_solid_angle(bounce, x, &path, y, normal).expect("spread");
                let (u, v) = path.direction.any_orthonormal_pair();
                let h = 1e-3;
                let steps = 200;
                let mut boundary = Vec::new();
                for side in 0..4 {
                    for k in 0..steps {
                        let t = -h + 2.0 * h * k as f64 / steps as f64;
                        let (a, b) = match side {
                            0 => (t, -h),
                            1 => (h, t),
                            2 => (-t, h),
                            _ => (-h, -t),
                        };
                        let d = (path.direction + u * a + v * b).normalize();
                        let (exit, e) = ball.trace(bounce, x, d).expect("meets the ball");
                        boundary.push(exit + e * ((y - exit).dot(normal) / e.dot(normal)));
                    }
                }
                let mut twice_area = DVec3::ZERO;
                for k in 0..boundary.len() {
                    twice_area += (boundary[k] - y).cross(boundary[(k + 1) % boundary.len()] - y);
                }
                let area = twice_area.dot(normal).abs() / 2.0;
                // The square's solid angle: ∫∫ (1 + a² + b²)^(−3/2) da db ≈ 4h²(1 − h²).
                let counted = area / (4.0 * h * h * (1.0 - h * h));
                assert!(
                    (counted / spread - 1.0).abs() < 1e-3,
                    "{bounce:?}: spread {spread} vs traced {counted}"
                );
            }
        }
    }
}
