//! Surfaces of revolution of Bezier profiles: a chain of planar Bezier
//! segments `(x(t), y(t))` rotated about the local z axis, so a surface point
//! is `(x(t) cos φ, x(t) sin φ, y(t))`, with optional flat caps.
//!
//! # Intersection
//! Rotate the local frame about z so the ray's horizontal direction is `+x'`:
//! the ray is `(o + s h, δ, o_z + s D_z)` with `h = |D_xy|`, `o = O·D̂_xy` and
//! `δ` the signed distance of the ray's vertical plane from the axis. Where
//! the ray is at height `y(t)`, `D_z (o + s h) = a(t)` with
//! `a(t) = h (y(t) − O_z) + D_z o`, and the surface condition
//! `(o + s h)² + δ² = x(t)²` becomes, multiplied by `D_z²`,
//!
//! `F(t) = a(t)² − D_z² (x(t)² − δ²) = 0`,
//!
//! the issue's `(D_x(y − O_z) + D_z O_x)² + (D_y(y − O_z) + D_z O_y)² = D_z² x²`
//! in a rotated frame: a polynomial of degree `2n` that never divides by `D_z`.
//!
//! Roots are isolated by Bernstein subdivision with Descartes' rule of signs
//! (`roots::isolate_roots`). The factors `a` and `x` (degree `n`) are
//! subdivided, not `F`: the coefficients of `F` on a small piece are formed
//! from the piece's own factors, so their error is relative to the piece's
//! size. Near-horizontal rays make `F` nearly a perfect square, `a² ≈ D_z² x²`,
//! and expanding it once on `[0, 1]` would lose every digit there. Isolated
//! roots are polished by safeguarded Newton on `F`.
//!
//! Only the nearest hit matters, so the search keeps the nearest verified
//! hit so far (caps are tried first) and skips every piece of the profile
//! whose hits can only be farther: on the surface `D_z (o + s h) = a(t)` and
//! `|o + s h| ≤ x(t)`, so the convex hulls of a piece's `a` and `x`
//! coefficients bound `s` from below (`RayProfilePiece::nearest_parameter`).
//! Pieces are sized to the profile's degree, since they are copied at every
//! split. Together with stopping Newton once `F` is below its rounding error,
//! this halved the instructions per ray (callgrind, `examples/revolution_cost.rs`).
//!
//! For each root the ray parameter comes from whichever formula has the
//! smaller error bound: the height equation `s = (y − O_z) / D_z` (good for
//! steep rays) or the radial one `s = (−o ± √(x² − δ²)) / h` (good for
//! shallow rays), its branch being the sign of `a / D_z`. When that sign is
//! below its error (a cluster of two roots, entry and exit, that `f64` cannot
//! separate, as for `|D_z| ≲ 1e-15`) both branches are candidates. Each
//! candidate is verified: the ray point must lie on the tangent line of the
//! profile at `t`, within the accumulated error bounds.
//!
//! `D_z = 0` exactly makes `F = h² (y − O_z)²`, all roots double. That case
//! is solved exactly as stated: the roots of `y(t) = O_z` (degree `n`), then
//! the circle–line problem `|O_xy + s D_xy| = x(t)` for each, both of its
//! solutions. A vertical ray (`h = 0`) needs no special case: the frame then
//! uses `D̂_xy = x̂`, `a = D_z O_x` and `F = D_z² (|O_xy|² − x²)`.
//!
//! # Conventions
//! - Profile points need `x ≥ 0` (the surface would otherwise fold through
//!   the axis). Outward is to the right of the profile's direction of travel
//!   in the `(x, y)` plane: the 2-D normal is `(y', −x')`, so a profile
//!   running upwards at `x > 0` faces away from the axis. On the axis the
//!   normal is `∓z` by the sign of `x'`. Where `c'(t) = 0` the tangent comes
//!   from the next non-vanishing derivative (`bezier::tangent_direction`).
//! - Caps close that orientation: the disc at the chain's start faces `−z`,
//!   the one at its end `+z`.
//! - `uv = (φ / 2π, (segment + t) / segments)`; caps use `v = 0` (start) and
//!   `v = 1` (end).
//! - The ray is taken into local space without renormalising its direction,
//!   so the local `s` is the world `t`. The transform must be a similarity
//!   (rotation, uniform scale, translation, optionally a mirror) so that
//!   `area` and `sample_area` are exact in world space.
//!
//! # Precision
//! Roots are polished to a few ulps of `t`, and every hit carries error
//! bounds built from `γ(n)` terms and the root's uncertainty; hits closer
//! than their own error bound are rejected, so a ray starting on the surface
//! does not find its own origin. Rays that pass within about `1e-15 ×` the
//! object's size of tangency may be reported as hit or miss.

use crate::geometry::bezier::{self, MAX_CONTROL_POINTS};
use crate::geometry::hit::{AreaSample, SurfaceHit};
use crate::math::bernstein::{self, MAX_COEFFICIENTS, binomial_row};
use crate::math::roots::{self, BernsteinPiece, IsolatedRoot, PolynomialPiece};
use crate::math::{Aabb, Ray, gamma};
use glam::{DAffine3, DMat3, DVec2, DVec3};
use std::cell::Cell;
use std::f64::consts::TAU;

/// Width in `t` below which root isolation stops splitting (≈ 2⁻⁴³).
const MINIMUM_ROOT_WIDTH: f64 = 1e-13;
/// Bins of the tabulated area distribution, per segment.
const AREA_BINS: usize = 64;

/// Gauss–Legendre nodes and weights of order 8 on `[−1, 1]` (Abramowitz and
/// Stegun, table 25.4); exact for polynomials up to degree 15.
const GAUSS_LEGENDRE_8: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_2, 0.101_228_536_290_376_3),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (0.960_289_856_497_536_2, 0.101_228_536_290_376_3),
];

/// A Bezier profile rotated about the local z axis, placed by an affine map.
#[derive(Clone, Debug)]
pub struct Revolution {
    segments: Vec<Segment>,
    caps: Vec<Cap>,
    local_to_world: DAffine3,
    world_to_local: DAffine3,
    /// Inverse transpose of the linear part, for normals.
    normal_to_world: DMat3,
    /// Componentwise absolute value of the linear part, for error bounds.
    absolute_linear: DMat3,
    /// Uniform scale factor of the similarity transform.
    scale_factor: f64,
    /// Largest `x`, and the `y` range, of all control points.
    radius: f64,
    z_min: f64,
    z_max: f64,
    /// Largest absolute control-point coordinate: the scale of rounding errors.
    size: f64,
    /// Cumulative local areas: segments first, then caps.
    cumulative_area: Vec<f64>,
}

/// One Bezier piece of the profile with its bounds and area table.
#[derive(Clone, Debug)]
struct Segment {
    points: Vec<DVec2>,
    x: [f64; MAX_CONTROL_POINTS],
    y: [f64; MAX_CONTROL_POINTS],
    degree: usize,
    radius: f64,
    z_min: f64,
    z_max: f64,
    /// Largest `|y|` of the control points.
    height_size: f64,
    /// Area swept by `t ∈ [0, k/AREA_BINS]`, `k = 0…AREA_BINS`.
    area_table: Vec<f64>,
}

/// A flat disc closing one end of the profile.
#[derive(Clone, Copy, Debug)]
struct Cap {
    z: f64,
    radius: f64,
    /// `−1` for the start (faces `−z`), `+1` for the end.
    side: f64,
}

/// A candidate hit before the nearest one is chosen.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    s: f64,
    surface: CandidateSurface,
}

#[derive(Clone, Copy, Debug)]
enum CandidateSurface {
    Profile { segment: usize, t: f64, t_uncertainty: f64 },
    Cap { cap: usize },
}

/// The ray in local space, with the rotated-frame quantities of the module
/// docs.
#[derive(Clone, Copy, Debug)]
struct LocalRay {
    origin: DVec3,
    direction: DVec3,
    /// `h = |D_xy|`.
    horizontal_speed: f64,
    /// `o = O_xy · D̂_xy`: minus the ray parameter (times `h`) of the closest
    /// approach to the axis.
    along: f64,
    /// `δ`: signed distance from the axis to the ray's vertical plane.
    across: f64,
    /// Error bound of `along` and `across`.
    frame_error: f64,
}

impl LocalRay {
    fn new(origin: DVec3, direction: DVec3) -> Self {
        let horizontal_speed = direction.x.hypot(direction.y);
        let unit = if horizontal_speed > 0.0 {
            DVec2::new(direction.x, direction.y) / horizontal_speed
        } else {
            DVec2::X
        };
        Self {
            origin,
            direction,
            horizontal_speed,
            along: origin.x * unit.x + origin.y * unit.y,
            across: origin.y * unit.x - origin.x * unit.y,
            frame_error: gamma(8) * (origin.x.abs() + origin.y.abs()),
        }
    }

    /// The range of `s` where the ray is inside the cylinder `r ≤ radius`,
    /// `z ∈ [z_min, z_max]`, or `None` if it never is.
    fn cylinder_span(&self, radius: f64, z_min: f64, z_max: f64) -> Option<(f64, f64)> {
        let (mut low, mut high) = (f64::NEG_INFINITY, f64::INFINITY);
        if self.horizontal_speed > 0.0 {
            let remaining = (radius - self.across.abs()) * (radius + self.across.abs());
            if remaining < 0.0 {
                return None;
            }
            let half = remaining.sqrt() / self.horizontal_speed;
            let center = -self.along / self.horizontal_speed;
            (low, high) = (center - half, center + half);
        } else if self.origin.x.hypot(self.origin.y) > radius {
            return None;
        }
        let dz = self.direction.z;
        if dz != 0.0 {
            let (a, b) = ((z_min - self.origin.z) / dz, (z_max - self.origin.z) / dz);
            (low, high) = (low.max(a.min(b)), high.min(a.max(b)));
        } else if self.origin.z < z_min || self.origin.z > z_max {
            return None;
        }
        // Widen by the rounding of the quotients above.
        let slack = 1e-9 * (low.abs().min(high.abs()) + 1.0);
        (low <= high).then_some((low - slack, high + slack))
    }
}

impl Revolution {
    /// A surface of revolution of the profile chain `segments` (each 2 to
    /// `MAX_CONTROL_POINTS` control points `(x, y)`, `x ≥ 0`), with discs
    /// closing its ends if `caps`, placed by the similarity `local_to_world`.
    pub fn new(segments: Vec<Vec<DVec2>>, caps: bool, local_to_world: DAffine3) -> Result<Self, String> {
        if segments.is_empty() {
            return Err("a surface of revolution needs at least one profile segment".into());
        }
        for (index, points) in segments.iter().enumerate() {
            if points.len() < 2 || points.len() > MAX_CONTROL_POINTS {
                return Err(format!(
                    "profile segment {index} has {} control points; each segment needs 2 to {MAX_CONTROL_POINTS}",
                    points.len()
                ));
            }
            if let Some(point) = points.iter().find(|p| !p.is_finite()) {
                return Err(format!("profile segment {index} has a non-finite control point {point}"));
            }
            if let Some(point) = points.iter().find(|p| p.x < 0.0) {
                return Err(format!(
                    "profile segment {index} has control point {point} with x < 0; profiles must stay on one side of the axis"
                ));
            }
        }
        let linear = local_to_world.matrix3;
        if !linear.is_finite() || !local_to_world.translation.is_finite() {
            return Err("the transform of a surface of revolution must be finite".into());
        }
        // A similarity has MᵀM = k² I; only then are areas scaled by k².
        let gram = linear.transpose() * linear;
        let scale_squared = gram.x_axis.x;
        let off_identity = (gram - DMat3::from_diagonal(DVec3::splat(scale_squared))).abs();
        if scale_squared.is_nan()
            || scale_squared <= 0.0
            || off_identity.to_cols_array().iter().any(|&e| e > 1e-9 * scale_squared)
        {
            return Err("the transform of a surface of revolution must be a similarity (rotation, uniform scale, translation); bake other scales into the profile".into());
        }
        let world_to_local = local_to_world.inverse();

        let segments: Vec<Segment> = segments.into_iter().map(Segment::new).collect();
        let mut cap_list = Vec::new();
        if caps {
            let first = segments[0].points[0];
            let last_segment = &segments[segments.len() - 1];
            let last = last_segment.points[last_segment.points.len() - 1];
            for (point, side) in [(first, -1.0), (last, 1.0)] {
                if point.x > 0.0 {
                    cap_list.push(Cap {
                        z: point.y,
                        radius: point.x,
                        side,
                    });
                }
            }
        }
        let mut cumulative_area = Vec::with_capacity(segments.len() + cap_list.len());
        let mut total = 0.0;
        for area in segments.iter().map(Segment::area).chain(cap_list.iter().map(Cap::area)) {
            total += area;
            cumulative_area.push(total);
        }
        if total.is_nan() || total <= 0.0 {
            return Err("the profile sweeps no area (it lies on the axis or is a single point)".into());
        }
        let radius = segments.iter().fold(0.0_f64, |m, s| m.max(s.radius));
        let z_min = segments.iter().fold(f64::INFINITY, |m, s| m.min(s.z_min));
        let z_max = segments.iter().fold(f64::NEG_INFINITY, |m, s| m.max(s.z_max));
        Ok(Self {
            size: radius.max(z_min.abs()).max(z_max.abs()),
            segments,
            caps: cap_list,
            local_to_world,
            world_to_local,
            normal_to_world: world_to_local.matrix3.transpose(),
            absolute_linear: linear.abs(),
            scale_factor: scale_squared.sqrt(),
            radius,
            z_min,
            z_max,
            cumulative_area,
        })
    }

    /// World-space bounds: the transformed box around the control points.
    pub fn bounds(&self) -> Aabb {
        let corners: Vec<DVec3> = (0..8)
            .map(|i| {
                let local = DVec3::new(
                    if i & 1 == 0 { -self.radius } else { self.radius },
                    if i & 2 == 0 { -self.radius } else { self.radius },
                    if i & 4 == 0 { self.z_min } else { self.z_max },
                );
                self.local_to_world.transform_point3(local)
            })
            .collect();
        Aabb::from_points(&corners)
    }

    /// World-space surface area, caps included:
    /// `A = k² Σ 2π ∫ x(t) |c'(t)| dt` (Pappus), by Gauss–Legendre quadrature.
    pub fn area(&self) -> f64 {
        self.cumulative_area.last().copied().unwrap_or(0.0) * self.scale_factor * self.scale_factor
    }

    /// The nearest intersection with `0 < t < t_max`, if any.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<SurfaceHit> {
        let local = LocalRay::new(
            self.world_to_local.transform_point3(ray.origin),
            self.world_to_local.transform_vector3(ray.direction),
        );
        if local.horizontal_speed == 0.0 && local.direction.z == 0.0 {
            return None;
        }
        // Cheap rejection by the bounding cylinder of the whole profile.
        let margin = 1e-9 * self.size;
        let (_, exit) = local.cylinder_span(self.radius * (1.0 + 1e-9) + margin, self.z_min - margin, self.z_max + margin)?;
        if exit < 0.0 {
            return None;
        }
        // `cutoff` is the nearest hit so far (or `t_max`): root isolation
        // drops the parts of the profile that can only hold farther hits.
        let cutoff = Cell::new(t_max);
        let mut best: Option<Candidate> = None;
        let mut consider = |candidate: Candidate| {
            if candidate.s < cutoff.get() {
                best = Some(candidate);
                cutoff.set(candidate.s);
            }
        };
        // Caps first: they are cheap, and a near cap hit prunes the profile.
        for (index, cap) in self.caps.iter().enumerate() {
            if let Some(s) = cap.intersect(&local) {
                consider(Candidate {
                    s,
                    surface: CandidateSurface::Cap { cap: index },
                });
            }
        }
        for (index, segment) in self.segments.iter().enumerate() {
            let Some((entry, exit)) = segment.span(&local, margin) else {
                continue;
            };
            if exit < 0.0 || entry >= cutoff.get() {
                continue;
            }
            segment.intersect(&local, index, self.size, &cutoff, &mut consider);
        }
        best.map(|candidate| self.surface_hit(&local, candidate))
    }

    /// A point drawn uniformly by area (density `1 / area()` with respect to
    /// world-space area): `u.x` selects the area fraction along the profile,
    /// inverted exactly within a tabulated bin, and `u.y` the angle `φ = 2π u.y`.
    pub fn sample_area(&self, u: DVec2) -> AreaSample {
        let total = self.cumulative_area.last().copied().unwrap_or(0.0);
        let target = u.x.clamp(0.0, 1.0) * total;
        let component = self
            .cumulative_area
            .partition_point(|&c| c <= target)
            .min(self.cumulative_area.len() - 1);
        let before = if component == 0 {
            0.0
        } else {
            self.cumulative_area[component - 1]
        };
        let phi = TAU * u.y.clamp(0.0, 1.0);
        let (sin_phi, cos_phi) = phi.sin_cos();
        let (local_point, local_normal, uv, local_error) = if component < self.segments.len() {
            let segment = &self.segments[component];
            let t = segment.invert_area(target - before);
            let (point, _) = bezier::evaluate_with_derivative(&segment.points, t);
            let normal = profile_normal(&segment.points, t, point.x, cos_phi, sin_phi);
            let v = (component as f64 + t) / self.segments.len() as f64;
            let local = DVec3::new(point.x * cos_phi, point.x * sin_phi, point.y);
            let error = gamma(4 * segment.degree as u32 + 16) * (self.size + point.x + point.y.abs());
            (local, normal, DVec2::new(u.y, v), error)
        } else {
            let cap = self.caps[component - self.segments.len()];
            let fraction = ((target - before) / cap.area()).clamp(0.0, 1.0);
            // Uniform on the disc: r = R √ξ has density 2r/R² (pbrt-v4 A.5.1).
            let r = cap.radius * fraction.sqrt();
            let local = DVec3::new(r * cos_phi, r * sin_phi, cap.z);
            let v = if cap.side < 0.0 { 0.0 } else { 1.0 };
            (
                local,
                DVec3::new(0.0, 0.0, cap.side),
                DVec2::new(u.y, v),
                gamma(8) * (self.size + r),
            )
        };
        let (point, point_error) = self.to_world_with_error(local_point, DVec3::splat(local_error));
        AreaSample {
            point,
            point_error,
            normal: (self.normal_to_world * local_normal).normalize(),
            uv,
        }
    }

    /// World position and per-axis error bound of a local point whose own
    /// error bound is `local_error` (pbrt-v4 6.8.3: `|M| e + γ(3)(|M||p| + |t|)`).
    fn to_world_with_error(&self, local: DVec3, local_error: DVec3) -> (DVec3, DVec3) {
        let point = self.local_to_world.transform_point3(local);
        let rounding = gamma(3) * (self.absolute_linear * local.abs() + self.local_to_world.translation.abs());
        (point, self.absolute_linear * local_error + rounding)
    }

    /// Builds the reported hit for the chosen candidate.
    fn surface_hit(&self, ray: &LocalRay, candidate: Candidate) -> SurfaceHit {
        let on_ray = ray.origin + candidate.s * ray.direction;
        let radial = on_ray.x.hypot(on_ray.y);
        let phi = if radial > 0.0 {
            on_ray.y.atan2(on_ray.x).rem_euclid(TAU)
        } else {
            0.0
        };
        let (sin_phi, cos_phi) = phi.sin_cos();
        let (local_point, local_normal, v, local_error) = match candidate.surface {
            CandidateSurface::Profile {
                segment,
                t,
                t_uncertainty,
            } => {
                let curve = &self.segments[segment];
                let (point, derivative) = bezier::evaluate_with_derivative(&curve.points, t);
                let tangent = bezier::tangent_direction(&curve.points, t).unwrap_or(DVec2::Y);
                // Project the ray point, in the (r, z) plane, onto the
                // profile's tangent line at t: removes the error normal to the
                // surface, to first order.
                let normal_2d = DVec2::new(tangent.y, -tangent.x);
                let offset = DVec2::new(radial, on_ray.z) - point;
                let projected = DVec2::new(radial, on_ray.z) - offset.dot(normal_2d) * normal_2d;
                let r = projected.x.max(0.0);
                let local = DVec3::new(r * cos_phi, r * sin_phi, projected.y);
                let normal = profile_normal(&curve.points, t, point.x.min(r), cos_phi, sin_phi);
                let error = gamma(4 * curve.degree as u32 + 16) * (self.size + r + projected.y.abs())
                    + derivative.length() * t_uncertainty
                    + gamma(8) * (ray.origin.abs().max_element() + (candidate.s * ray.direction).abs().max_element());
                let v = (segment as f64 + t) / self.segments.len() as f64;
                (local, normal, v, error)
            }
            CandidateSurface::Cap { cap } => {
                let cap = self.caps[cap];
                let local = DVec3::new(on_ray.x, on_ray.y, cap.z);
                let error =
                    gamma(8) * (radial + ray.origin.abs().max_element() + (candidate.s * ray.direction).abs().max_element());
                (
                    local,
                    DVec3::new(0.0, 0.0, cap.side),
                    if cap.side < 0.0 { 0.0 } else { 1.0 },
                    error,
                )
            }
        };
        let (point, point_error) = self.to_world_with_error(local_point, DVec3::splat(local_error));
        let normal = (self.normal_to_world * local_normal).normalize();
        SurfaceHit {
            t: candidate.s,
            point,
            point_error,
            geometric_normal: normal,
            shading_normal: normal,
            uv: DVec2::new(phi / TAU, v),
        }
    }
}

/// Unit local normal of the profile surface at parameter `t`, angle `φ`:
/// the 2-D normal `(y', −x')` rotated by `φ`, or `∓z` on the axis.
fn profile_normal(points: &[DVec2], t: f64, radius: f64, cos_phi: f64, sin_phi: f64) -> DVec3 {
    let tangent = bezier::tangent_direction(points, t).unwrap_or(DVec2::Y);
    let normal_2d = DVec2::new(tangent.y, -tangent.x);
    if radius <= 0.0 {
        // On the axis every φ gives the same point: only ±z is consistent.
        return DVec3::new(0.0, 0.0, if normal_2d.y < 0.0 { -1.0 } else { 1.0 });
    }
    DVec3::new(normal_2d.x * cos_phi, normal_2d.x * sin_phi, normal_2d.y).normalize()
}

impl Cap {
    fn area(&self) -> f64 {
        std::f64::consts::PI * self.radius * self.radius
    }

    /// Ray parameter of the hit with the disc, if beyond its error bound.
    fn intersect(&self, ray: &LocalRay) -> Option<f64> {
        let dz = ray.direction.z;
        if dz == 0.0 {
            return None;
        }
        let s = (self.z - ray.origin.z) / dz;
        let s_error = 2.0 * gamma(3) * (self.z.abs() + ray.origin.z.abs()) / dz.abs();
        let point = ray.origin + s * ray.direction;
        (s > s_error && point.x.hypot(point.y) <= self.radius).then_some(s)
    }
}

impl Segment {
    fn new(points: Vec<DVec2>) -> Self {
        let degree = points.len() - 1;
        let mut x = [0.0; MAX_CONTROL_POINTS];
        let mut y = [0.0; MAX_CONTROL_POINTS];
        for (i, p) in points.iter().enumerate() {
            x[i] = p.x;
            y[i] = p.y;
        }
        let radius = points.iter().fold(0.0_f64, |m, p| m.max(p.x));
        let z_min = points.iter().fold(f64::INFINITY, |m, p| m.min(p.y));
        let z_max = points.iter().fold(f64::NEG_INFINITY, |m, p| m.max(p.y));
        let mut segment = Self {
            points,
            x,
            y,
            degree,
            radius,
            z_min,
            z_max,
            height_size: z_min.abs().max(z_max.abs()),
            area_table: Vec::new(),
        };
        // Tabulate the swept area over AREA_BINS equal bins of t.
        let mut table = Vec::with_capacity(AREA_BINS + 1);
        let mut running = 0.0;
        table.push(0.0);
        for bin in 0..AREA_BINS {
            let (start, end) = (bin as f64 / AREA_BINS as f64, (bin + 1) as f64 / AREA_BINS as f64);
            running += segment.swept_area(start, end);
            table.push(running);
        }
        segment.area_table = table;
        segment
    }

    fn area(&self) -> f64 {
        self.area_table[AREA_BINS]
    }

    /// Area density along the profile, `dA/dt = 2π x(t) |c'(t)|`.
    fn area_density(&self, t: f64) -> f64 {
        let (point, derivative) = bezier::evaluate_with_derivative(&self.points, t);
        TAU * point.x * derivative.length()
    }

    /// `∫ₐᵇ 2π x |c'| dt` by 8-point Gauss–Legendre quadrature.
    fn swept_area(&self, a: f64, b: f64) -> f64 {
        let (half, middle) = (0.5 * (b - a), 0.5 * (a + b));
        half * GAUSS_LEGENDRE_8
            .iter()
            .map(|&(node, weight)| weight * self.area_density(middle + half * node))
            .sum::<f64>()
    }

    /// The `t` at which the swept area reaches `area`: the tabulated bin,
    /// then safeguarded Newton on `∫ = area` inside it, so the sampled density
    /// is uniform up to quadrature error (≈ 1e-14 relative), not piecewise.
    fn invert_area(&self, area: f64) -> f64 {
        let bin = self.area_table.partition_point(|&c| c <= area).clamp(1, AREA_BINS) - 1;
        let (mut low, mut high) = (bin as f64 / AREA_BINS as f64, (bin + 1) as f64 / AREA_BINS as f64);
        let start = low;
        let remaining = (area - self.area_table[bin]).max(0.0);
        let bin_area = self.area_table[bin + 1] - self.area_table[bin];
        if bin_area <= 0.0 {
            return low;
        }
        let mut t = low + (high - low) * (remaining / bin_area).min(1.0);
        for _ in 0..60 {
            let residual = self.swept_area(start, t) - remaining;
            if residual > 0.0 {
                high = t;
            } else {
                low = t;
            }
            let density = self.area_density(t);
            let newton = t - residual / density;
            let next = if newton.is_finite() && newton > low && newton < high {
                newton
            } else {
                0.5 * (low + high)
            };
            if (next - t).abs() <= 4.0 * f64::EPSILON {
                return next;
            }
            t = next;
        }
        t
    }

    /// The range of ray parameters inside this segment's bounding cylinder.
    fn span(&self, ray: &LocalRay, margin: f64) -> Option<(f64, f64)> {
        ray.cylinder_span(self.radius * (1.0 + 1e-9) + margin, self.z_min - margin, self.z_max + margin)
    }

    /// Reports every verified candidate hit of the ray with this segment.
    fn intersect(&self, ray: &LocalRay, index: usize, size: f64, cutoff: &Cell<f64>, consider: &mut impl FnMut(Candidate)) {
        let n = self.degree;
        let dz = ray.direction.z;
        let origin_z = ray.origin.z;
        if dz == 0.0 {
            // Exact horizontal case: y(t) = O_z, then the circle–line problem.
            let mut height = [0.0; MAX_COEFFICIENTS];
            for (value, y) in height.iter_mut().zip(&self.y[..=n]) {
                *value = y - origin_z;
            }
            let error = gamma(2) * (self.height_size + origin_z.abs());
            let piece = BernsteinPiece::new(&height[..=n], error);
            roots::isolate_roots(
                &piece,
                0.0,
                1.0,
                MINIMUM_ROOT_WIDTH,
                &mut |_| false,
                &mut |_, root: IsolatedRoot| {
                    let (point, derivative) = bezier::evaluate_with_derivative(&self.points, root.t);
                    let radial = RadialSolution::new(ray, point.x, derivative.x, root.t_uncertainty, n);
                    for branch in [-1.0, 1.0] {
                        if let Some(s) = radial.parameter(branch) {
                            self.verify_and_report(ray, index, size, root, s, radial.error, consider);
                        }
                    }
                },
            );
            return;
        }
        // General case: roots of F = a² − D_z² (x² − δ²), with pieces sized
        // to the degree (they are copied at every split).
        match n + 1 {
            ..=4 => self.intersect_general::<4>(ray, index, size, cutoff, consider),
            5..=8 => self.intersect_general::<8>(ray, index, size, cutoff, consider),
            _ => self.intersect_general::<MAX_CONTROL_POINTS>(ray, index, size, cutoff, consider),
        }
    }

    /// `intersect` for `D_z ≠ 0`, with pieces of `N ≥ degree + 1` coefficients.
    fn intersect_general<const N: usize>(
        &self,
        ray: &LocalRay,
        index: usize,
        size: f64,
        cutoff: &Cell<f64>,
        consider: &mut impl FnMut(Candidate),
    ) {
        let n = self.degree;
        let dz = ray.direction.z;
        let h = ray.horizontal_speed;
        let origin_z = ray.origin.z;
        let mut a = [0.0; N];
        let mut x = [0.0; N];
        for i in 0..=n {
            a[i] = h * (self.y[i] - origin_z) + dz * ray.along;
            x[i] = self.x[i];
        }
        let piece = RayProfilePiece {
            a,
            x,
            count: n + 1,
            a_range: range(&a[..=n]),
            x_range: range(&x[..=n]),
            dz_squared: dz * dz,
            across: ray.across,
            width: 1.0,
            a_error: 0.0,
            x_error: 0.0,
            a_rounding: gamma(4) * (h * (self.height_size + origin_z.abs()) + (dz * ray.along).abs())
                + dz.abs() * ray.frame_error,
        };
        let mut skip = |piece: &RayProfilePiece<N>| piece.nearest_parameter(ray) > cutoff.get();
        roots::isolate_roots(
            &piece,
            0.0,
            1.0,
            MINIMUM_ROOT_WIDTH,
            &mut skip,
            &mut |piece: &RayProfilePiece<N>, root| {
                let (point, derivative) = bezier::evaluate_with_derivative(&self.points, root.t);
                // Height formula s = (y − O_z)/D_z and its error bound.
                let s_height = (point.y - origin_z) / dz;
                let height_error = (derivative.y.abs() * root.t_uncertainty
                    + gamma(n as u32 + 4) * (self.height_size + origin_z.abs()))
                    / dz.abs();
                // Radial formula, its branch from the sign of a/D_z.
                let (a_value, a_slope) = bernstein::evaluate_with_derivative(&piece.a[..piece.count], root.tau);
                let a_largest = piece.a_range.0.abs().max(piece.a_range.1.abs());
                let a_error = piece.a_error + gamma(n as u32 + 2) * a_largest + a_slope.abs() / piece.width * root.t_uncertainty;
                let radial = RadialSolution::new(ray, point.x, derivative.x, root.t_uncertainty, n);
                if height_error <= radial.error || h == 0.0 {
                    self.verify_and_report(ray, index, size, root, s_height, height_error, consider);
                } else if a_value.abs() > a_error {
                    let branch = a_value.signum() * dz.signum();
                    if let Some(s) = radial.parameter(branch) {
                        self.verify_and_report(ray, index, size, root, s, radial.error, consider);
                    }
                } else {
                    // Entry and exit are not separable: both are surface points
                    // within the error bounds.
                    for branch in [-1.0, 1.0] {
                        if let Some(s) = radial.parameter(branch) {
                            self.verify_and_report(ray, index, size, root, s, radial.error, consider);
                        }
                    }
                }
            },
        );
    }

    /// Checks that the ray point at `s` lies on the profile's tangent line at
    /// the root (distance in the meridian plane, within the error bounds) and
    /// that `s` exceeds its own error bound, then reports the candidate.
    #[allow(clippy::too_many_arguments)]
    fn verify_and_report(
        &self,
        ray: &LocalRay,
        index: usize,
        size: f64,
        root: IsolatedRoot,
        s: f64,
        s_error: f64,
        consider: &mut impl FnMut(Candidate),
    ) {
        // Also rejects NaN.
        if s.is_nan() || s <= 2.0 * s_error + gamma(16) * s.abs() {
            return;
        }
        let point = ray.origin + s * ray.direction;
        let (profile, derivative) = bezier::evaluate_with_derivative(&self.points, root.t);
        let radial = point.x.hypot(point.y);
        let offset = DVec2::new(radial, point.z) - profile;
        let speed = derivative.length();
        // An origin within rounding distance u of the surface (a ray started
        // on it) crosses it again at s ≈ u / |n·D|: reject hits that close.
        if speed > 0.0 {
            let radial_velocity = if radial > 0.0 {
                (point.x * ray.direction.x + point.y * ray.direction.y) / radial
            } else {
                ray.horizontal_speed
            };
            let normal_speed = (derivative.y * radial_velocity - derivative.x * ray.direction.z).abs() / speed;
            let origin_uncertainty = gamma(32) * (ray.origin.abs().max_element() + size);
            if s * normal_speed <= origin_uncertainty {
                return;
            }
        }
        let normal_distance = if speed > 0.0 {
            (offset.x * derivative.y - offset.y * derivative.x).abs() / speed
        } else {
            offset.length()
        };
        let tolerance = 4.0 * (s_error * ray.direction.length() + speed * root.t_uncertainty)
            + gamma(32) * (size + ray.origin.abs().max_element() + (s * ray.direction).abs().max_element());
        if normal_distance <= tolerance {
            consider(Candidate {
                s,
                surface: CandidateSurface::Profile {
                    segment: index,
                    t: root.t,
                    t_uncertainty: root.t_uncertainty,
                },
            });
        }
    }
}

/// The radial equation `(o + s h)² + δ² = x²` at one root, solved for `s`
/// on either branch `s = (−o ± q) / h`, `q = √(x² − δ²)`, with an error bound.
struct RadialSolution {
    along: f64,
    horizontal_speed: f64,
    q: f64,
    error: f64,
    valid: bool,
}

impl RadialSolution {
    fn new(ray: &LocalRay, x: f64, x_slope: f64, t_uncertainty: f64, degree: usize) -> Self {
        let delta = ray.across.abs();
        let v = (x - delta) * (x + delta);
        // Error of v from x's rounding and uncertainty and δ's rounding.
        let v_error = 2.0 * x.abs() * (x_slope.abs() * t_uncertainty)
            + gamma(degree as u32 + 6) * (x * x + delta * delta)
            + 2.0 * delta * ray.frame_error;
        let q = v.max(0.0).sqrt();
        // |√(v + e) − √v| ≤ e / (√v + √e) for the worst perturbation e.
        let q_error = v_error / (q + v_error.sqrt());
        let h = ray.horizontal_speed;
        let error = if h > 0.0 {
            (q_error + ray.frame_error + gamma(4) * (ray.along.abs() + q)) / h
        } else {
            f64::INFINITY
        };
        Self {
            along: ray.along,
            horizontal_speed: h,
            q,
            error,
            valid: v >= -v_error && h > 0.0,
        }
    }

    fn parameter(&self, branch: f64) -> Option<f64> {
        self.valid.then(|| (-self.along + branch * self.q) / self.horizontal_speed)
    }
}

/// Smallest and largest of the coefficients.
fn range(coefficients: &[f64]) -> (f64, f64) {
    coefficients
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(low, high), &c| {
            (low.min(c), high.max(c))
        })
}

/// `F = a² − D_z² (x − δ)(x + δ)` on a sub-interval of `t`, as its factors'
/// Bernstein coefficients there (see the module docs for why the factors).
#[derive(Clone, Copy, Debug)]
struct RayProfilePiece<const N: usize> {
    a: [f64; N],
    x: [f64; N],
    count: usize,
    /// Smallest and largest of the `a` and of the `x` coefficients.
    a_range: (f64, f64),
    x_range: (f64, f64),
    dz_squared: f64,
    across: f64,
    /// Width of the piece in `t`.
    width: f64,
    /// Error bounds of the coefficients from subdivision.
    a_error: f64,
    x_error: f64,
    /// Bound on the rounding of the initial `a_i = h (y_i − O_z) + D_z o`.
    a_rounding: f64,
}

impl<const N: usize> RayProfilePiece<N> {
    /// `F`'s Bernstein coefficient at an end of the piece, from the factors'
    /// coefficients there (`c_0 = a_0² − D_z² x_0² + D_z² δ²`, likewise `c_2n`).
    fn end_value(&self, a: f64, x: f64) -> f64 {
        (a * a - self.dz_squared * (x * x)) + self.dz_squared * self.across * self.across
    }

    /// `a`, `da/dτ`, `x` and `dx/dτ` at `τ`, by de Casteljau's algorithm on
    /// both factors at once (as `bernstein::evaluate_with_derivative`).
    fn factors_at(&self, tau: f64) -> (f64, f64, f64, f64) {
        let count = self.count.min(N);
        if count < 2 {
            return (self.a[0], 0.0, self.x[0], 0.0);
        }
        let (mut a, mut x) = (self.a, self.x);
        let s = 1.0 - tau;
        for width in (2..count).rev() {
            for i in 0..width {
                a[i] = s * a[i] + tau * a[i + 1];
                x[i] = s * x[i] + tau * x[i + 1];
            }
        }
        let degree = (count - 1) as f64;
        (
            s * a[0] + tau * a[1],
            degree * (a[1] - a[0]),
            s * x[0] + tau * x[1],
            degree * (x[1] - x[0]),
        )
    }

    /// A lower bound on the ray parameter `s` of every surface point this
    /// piece of the profile can hold (`−∞` if none can be given), so that a
    /// piece entirely beyond the nearest hit so far can be skipped.
    ///
    /// On the surface `D_z (o + s h) = a(t)` (the ray's height is `y(t)`), so
    /// `s = (a / D_z − o) / h` ranges over the convex hull of the piece's `a`
    /// coefficients; and `|o + s h| ≤ x(t)` (the ray's distance to the axis),
    /// so `s ≥ (−o − max x) / h`. Both bounds are widened by their rounding.
    fn nearest_parameter(&self, ray: &LocalRay) -> f64 {
        let h = ray.horizontal_speed;
        if h <= 0.0 {
            return f64::NEG_INFINITY;
        }
        let dz = ray.direction.z;
        let (a_low, a_high) = self.a_range;
        let x_high = self.x_range.1;
        let a_slack = self.a_error + self.a_rounding + gamma(4) * a_low.abs().max(a_high.abs());
        let x_max = x_high + self.x_error + gamma(4) * x_high.abs();
        let o = ray.along.abs() + ray.frame_error;
        // Radial bound; its own rounding is a few ulps of the terms.
        let radial = (-ray.along - x_max) / h - gamma(4) * (o + x_max) / h;
        if dz == 0.0 {
            return radial;
        }
        let nearest_a = if dz > 0.0 { a_low - a_slack } else { a_high + a_slack };
        let a_over_dz = nearest_a / dz;
        let height = (a_over_dz - ray.along) / h - (gamma(4) * (a_over_dz.abs() + o) + ray.frame_error) / h;
        radial.max(height)
    }
}

impl<const N: usize> PolynomialPiece for RayProfilePiece<N> {
    fn coefficients(&self, out: &mut [f64; MAX_COEFFICIENTS]) -> (usize, f64) {
        let n = self.count - 1;
        // Quick exclusion from the factors' ranges (convex hull): if
        // min a² − D_z²(max x² − δ²) > 0, or max a² − D_z²(min x² − δ²) < 0,
        // F keeps one sign; report two coefficients of that sign.
        let (a_low, a_high) = self.a_range;
        let (x_low, x_high) = self.x_range;
        let a_error = self.a_error + gamma(4) * a_high.abs().max(a_low.abs());
        let x_error = self.x_error + gamma(4) * x_high.abs().max(x_low.abs());
        let a_min = if a_low > a_error {
            a_low - a_error
        } else if a_high < -a_error {
            -a_high - a_error
        } else {
            0.0
        };
        let a_max = a_high.abs().max(a_low.abs()) + a_error;
        let x_min = if x_low > x_error { x_low - x_error } else { 0.0 };
        let x_max = x_high.abs().max(x_low.abs()) + x_error;
        let delta_squared = self.across * self.across;
        let slack = gamma(16) * (a_max * a_max + self.dz_squared * (x_max * x_max + delta_squared));
        let lowest = a_min * a_min - self.dz_squared * (x_max * x_max - delta_squared);
        let highest = a_max * a_max - self.dz_squared * (x_min * x_min - delta_squared);
        if lowest > slack || highest < -slack {
            let value = if lowest > slack { lowest } else { highest };
            out[0] = value;
            out[1] = value;
            return (2, 0.0);
        }
        // Scaled factors C(n,i) a_i, then c_k = Σ_{i+j=k} (…) / C(2n,k); the
        // sum is symmetric in i and j, so each pair i < j is formed once and
        // doubled (exact in binary).
        let count = self.count.min(N);
        let mut a_scaled = [0.0; N];
        let mut x_scaled = [0.0; N];
        for ((i, &weight), (a, x)) in binomial_row(n)
            .iter()
            .enumerate()
            .take(count)
            .zip(a_scaled.iter_mut().zip(&mut x_scaled))
        {
            *a = weight * self.a[i];
            *x = weight * self.x[i];
        }
        let (a_largest, x_largest) = (a_high.abs().max(a_low.abs()), x_high.abs().max(x_low.abs()));
        out[..=2 * n].fill(0.0);
        for i in 0..count {
            out[2 * i] += a_scaled[i] * a_scaled[i] - self.dz_squared * (x_scaled[i] * x_scaled[i]);
            for j in i + 1..count {
                out[i + j] += 2.0 * (a_scaled[i] * a_scaled[j] - self.dz_squared * (x_scaled[i] * x_scaled[j]));
            }
        }
        let constant = self.dz_squared * delta_squared;
        for (value, &weight) in out[..=2 * n].iter_mut().zip(binomial_row(2 * n)) {
            *value = *value / weight + constant;
        }
        // The ends exactly as `end_values` gives them.
        out[0] = self.end_value(self.a[0], self.x[0]);
        out[2 * n] = self.end_value(self.a[n], self.x[n]);
        // The weights C(n,i)C(n,j)/C(2n,k) sum to 1 over i + j = k
        // (Vandermonde), so each coefficient is a convex combination.
        let magnitude = a_largest * a_largest + self.dz_squared * (x_largest * x_largest + delta_squared);
        let error = gamma(2 * n as u32 + 8) * magnitude
            + 2.0 * a_largest * self.a_error
            + 2.0 * self.dz_squared * x_largest * self.x_error;
        (2 * n + 1, error)
    }

    fn end_values(&self) -> (f64, f64) {
        let n = self.count - 1;
        (self.end_value(self.a[0], self.x[0]), self.end_value(self.a[n], self.x[n]))
    }

    fn split_half(&self) -> (Self, Self) {
        let mut left = *self;
        let mut right = *self;
        let count = self.count.min(N);
        // de Casteljau at ½ on both factors (as `bernstein::split`):
        // the left edge of the triangle is the left half, the right edge the
        // right half.
        let (mut a, mut x) = (self.a, self.x);
        for step in 0..count {
            let last = count - 1 - step;
            left.a[step] = a[0];
            left.x[step] = x[0];
            right.a[last] = a[last];
            right.x[last] = x[last];
            for i in 0..last {
                a[i] = 0.5 * a[i] + 0.5 * a[i + 1];
                x[i] = 0.5 * x[i] + 0.5 * x[i + 1];
            }
        }
        let a_largest = self.a_range.0.abs().max(self.a_range.1.abs());
        let x_largest = self.x_range.0.abs().max(self.x_range.1.abs());
        for half in [&mut left, &mut right] {
            half.a_range = range(&half.a[..count]);
            half.x_range = range(&half.x[..count]);
            half.width = 0.5 * self.width;
            half.a_error += gamma(count as u32) * a_largest;
            half.x_error += gamma(count as u32) * x_largest;
        }
        (left, right)
    }

    fn evaluate_with_derivative(&self, tau: f64) -> (f64, f64) {
        let (a, a_slope, x, x_slope) = self.factors_at(tau);
        let delta = self.across.abs();
        (
            a * a - self.dz_squared * ((x - delta) * (x + delta)),
            2.0 * (a * a_slope - self.dz_squared * x * x_slope),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vase() -> Revolution {
        let profile = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.2, 0.1),
            DVec2::new(0.3, 0.9),
            DVec2::new(0.9, 1.4),
            DVec2::new(0.5, 2.0),
        ];
        Revolution::new(vec![profile], false, DAffine3::IDENTITY).expect("valid vase")
    }

    fn cylinder(caps: bool) -> Revolution {
        let profile = vec![DVec2::new(1.0, -1.0), DVec2::new(1.0, 1.0)];
        Revolution::new(vec![profile], caps, DAffine3::IDENTITY).expect("valid cylinder")
    }

    #[test]
    fn rejects_invalid_profiles() {
        let identity = DAffine3::IDENTITY;
        assert!(Revolution::new(vec![], false, identity).is_err());
        assert!(Revolution::new(vec![vec![DVec2::ONE]], false, identity).is_err());
        assert!(Revolution::new(vec![vec![DVec2::ONE, DVec2::new(-1.0, 0.0)]], false, identity).is_err());
        assert!(Revolution::new(vec![vec![DVec2::ONE, DVec2::new(f64::NAN, 0.0)]], false, identity).is_err());
        assert!(Revolution::new(vec![vec![DVec2::ZERO, DVec2::Y]], false, identity).is_err());
        let squash = DAffine3::from_scale(DVec3::new(1.0, 2.0, 1.0));
        assert!(Revolution::new(vec![vec![DVec2::ONE, DVec2::X]], false, squash).is_err());
    }

    #[test]
    fn cylinder_hits_from_outside_inside_and_along_the_axis() {
        let shape = cylinder(false);
        let hit = shape
            .intersect(&Ray::new(DVec3::new(-3.0, 0.0, 0.5), DVec3::X), f64::INFINITY)
            .expect("hit");
        assert!((hit.t - 2.0).abs() < 1e-14);
        assert!((hit.geometric_normal - -DVec3::X).length() < 1e-14);
        let inside = shape
            .intersect(&Ray::new(DVec3::new(0.0, 0.0, 0.5), DVec3::Y), f64::INFINITY)
            .expect("hit");
        assert!((inside.t - 1.0).abs() < 1e-14 && (inside.geometric_normal - DVec3::Y).length() < 1e-14);
        // An open tube has nothing on its axis; with caps the axis ray hits the end disc.
        assert!(
            shape
                .intersect(&Ray::new(DVec3::new(0.0, 0.0, -5.0), DVec3::Z), f64::INFINITY)
                .is_none()
        );
        let capped = cylinder(true).intersect(&Ray::new(DVec3::new(0.0, 0.0, -5.0), DVec3::Z), f64::INFINITY);
        let capped = capped.expect("cap hit");
        assert!((capped.t - 4.0).abs() < 1e-14 && (capped.geometric_normal - -DVec3::Z).length() < 1e-14);
    }

    #[test]
    fn horizontal_rays_hit_like_their_tilted_neighbours() {
        let shape = vase();
        for dz in [0.0, 1e-12, -1e-12, 1e-16] {
            let ray = Ray::new(DVec3::new(-5.0, 0.2, 1.0), DVec3::new(1.0, 0.0, dz));
            let hit = shape.intersect(&ray, f64::INFINITY).expect("horizontal hit");
            let reference = shape.intersect(&Ray::new(DVec3::new(-5.0, 0.2, 1.0), DVec3::X), f64::INFINITY);
            assert!((hit.t - reference.expect("hit").t).abs() < 1e-9, "dz = {dz}");
        }
    }

    #[test]
    fn axis_ray_hits_the_pole_with_a_vertical_normal() {
        let shape = vase();
        let hit = shape
            .intersect(&Ray::new(DVec3::new(0.0, 0.0, -3.0), DVec3::Z), f64::INFINITY)
            .expect("pole");
        assert!((hit.t - 3.0).abs() < 1e-12, "{}", hit.t);
        assert_eq!(hit.geometric_normal, -DVec3::Z);
        // From inside, the pole is hit from above with the same outward normal.
        let inside = shape
            .intersect(&Ray::new(DVec3::new(0.0, 0.0, 0.5), -DVec3::Z), f64::INFINITY)
            .expect("pole");
        assert!((inside.t - 0.5).abs() < 1e-12 && inside.geometric_normal == -DVec3::Z);
    }

    #[test]
    fn hits_lie_on_the_surface_and_spawned_rays_leave_it() {
        let shape = vase();
        let mut hits = 0;
        for i in 0..400 {
            let angle = i as f64 * 0.7;
            let origin = DVec3::new(4.0 * angle.cos(), 4.0 * angle.sin(), 0.005 * i as f64);
            let target = DVec3::new(0.1 * (i % 7) as f64, 0.0, 0.3 + 0.003 * i as f64);
            let Some(hit) = shape.intersect(&Ray::new(origin, target - origin), f64::INFINITY) else {
                continue;
            };
            hits += 1;
            // Re-intersecting from the offset point never finds the same point.
            for direction in [hit.geometric_normal, -hit.geometric_normal, target - origin] {
                let spawned = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, direction);
                if let Some(again) = shape.intersect(&spawned, f64::INFINITY) {
                    assert!(again.t > 1e-9, "self-intersection at {} (ray {i})", again.t);
                }
            }
        }
        assert!(hits > 300);
    }

    #[test]
    fn area_matches_closed_forms() {
        // Cylinder r = 1, height 2: 4π (+ 2π for the caps).
        assert!((cylinder(false).area() - 4.0 * std::f64::consts::PI).abs() < 1e-12);
        assert!((cylinder(true).area() - 6.0 * std::f64::consts::PI).abs() < 1e-12);
        // Cone with apex on the axis, radius 1 and height 1: π r √(r² + h²).
        let cone = Revolution::new(
            vec![vec![DVec2::new(1.0, 0.0), DVec2::new(0.0, 1.0)]],
            false,
            DAffine3::IDENTITY,
        )
        .expect("cone");
        assert!((cone.area() - std::f64::consts::PI * 2.0_f64.sqrt()).abs() < 1e-12);
        // Uniform scale by 2 quadruples the area.
        let scaled = Revolution::new(
            vec![vec![DVec2::new(1.0, -1.0), DVec2::new(1.0, 1.0)]],
            false,
            DAffine3::from_scale(DVec3::splat(2.0)),
        )
        .expect("scaled");
        assert!((scaled.area() - 16.0 * std::f64::consts::PI).abs() < 1e-11);
    }

    #[test]
    fn area_samples_are_uniform_on_a_cone() {
        // On the cone x = 1 − y the area below height y is ∝ 1 − (1 − y)²,
        // so a uniform sampler gives E[(1 − y)²] = ½, and P(y < ½) = ¾.
        let cone = Revolution::new(
            vec![vec![DVec2::new(1.0, 0.0), DVec2::new(0.0, 1.0)]],
            false,
            DAffine3::IDENTITY,
        )
        .expect("cone");
        let n = 4096;
        let mut moment = 0.0;
        let mut below_half = 0;
        for i in 0..n {
            let u = DVec2::new((i as f64 + 0.5) / n as f64, (i as f64 * 0.618_033_988_7).fract());
            let sample = cone.sample_area(u);
            let y = sample.point.z;
            moment += (1.0 - y) * (1.0 - y);
            below_half += usize::from(y < 0.5);
            let expected_normal = DVec3::new(sample.point.x, sample.point.y, 1.0 - y).normalize();
            assert!((sample.normal - expected_normal).length() < 1e-9);
        }
        assert!((moment / n as f64 - 0.5).abs() < 1e-6);
        assert!((below_half as f64 / n as f64 - 0.75).abs() < 1e-3);
    }
}
