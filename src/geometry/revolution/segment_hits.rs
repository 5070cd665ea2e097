//! The hits of a ray with one segment of the profile: the roots of the
//! ray–profile polynomial (`ray_profile`), each turned into a ray parameter
//! and verified to lie on the surface. Roots are isolated arc by arc
//! (`profile::Arc`), only on the arcs whose annuli the ray passes through,
//! nearest first.
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

use super::intersect::{Candidate, CandidateSurface};
use super::local_ray::LocalRay;
use super::profile::{Arc, MAX_ARCS, Segment};
use super::ray_profile::{MAX_EXACT_SIZE, RayProfilePiece, range};
use crate::geometry::bezier::{self, MAX_CONTROL_POINTS};
use crate::math::bernstein::{self, MAX_COEFFICIENTS};
use crate::math::gamma;
use crate::math::roots::{self, BernsteinPiece, IsolatedRoot};
use glam::DVec2;
use std::cell::Cell;

/// Width in `t` below which root isolation stops splitting (≈ 2⁻⁴³).
const MINIMUM_ROOT_WIDTH: f64 = 1e-13;

impl Segment {
    /// Reports every verified candidate hit of the ray with this segment,
    /// whose bounding cylinder it is inside for `s ∈ span`.
    pub(super) fn intersect(
        &self,
        ray: &LocalRay,
        index: usize,
        size: f64,
        span: (f64, f64),
        cutoff: &Cell<f64>,
        consider: &mut impl FnMut(Candidate),
    ) {
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
                            self.verify_and_report(ray, index, size, root, (point, derivative), s, radial.error, consider);
                        }
                    }
                },
            );
            return;
        }
        // General case: roots of F = a² − D_z² (x² − δ²), with pieces sized
        // to the degree (they are copied at every split).
        // Up to `MAX_EXACT_SIZE` coefficients the size is exact.
        match n + 1 {
            2 => self.intersect_general::<2>(ray, index, size, span, cutoff, consider),
            3 => self.intersect_general::<3>(ray, index, size, span, cutoff, consider),
            4 => self.intersect_general::<4>(ray, index, size, span, cutoff, consider),
            5 => self.intersect_general::<5>(ray, index, size, span, cutoff, consider),
            6 => self.intersect_general::<6>(ray, index, size, span, cutoff, consider),
            7 => self.intersect_general::<7>(ray, index, size, span, cutoff, consider),
            8 => self.intersect_general::<8>(ray, index, size, span, cutoff, consider),
            _ => self.intersect_general::<MAX_CONTROL_POINTS>(ray, index, size, span, cutoff, consider),
        }
    }

    /// `intersect` for `D_z ≠ 0`, with pieces of `N ≥ degree + 1`
    /// coefficients (`N = degree + 1` up to `MAX_EXACT_SIZE`).
    fn intersect_general<const N: usize>(
        &self,
        ray: &LocalRay,
        index: usize,
        size: f64,
        span: (f64, f64),
        cutoff: &Cell<f64>,
        consider: &mut impl FnMut(Candidate),
    ) {
        let n = self.degree;
        debug_assert!(N > MAX_EXACT_SIZE || N == n + 1);
        let dz = ray.direction.z;
        let h = ray.horizontal_speed;
        let origin_z = ray.origin.z;
        // The arcs whose annuli the ray passes through before the nearest
        // hit so far, nearest entry first, so that an early hit prunes the
        // arcs behind it.
        let margin = 1e-9 * size;
        // First by height alone: the heights the ray passes through inside
        // the segment's cylinder, before the nearest hit so far, widened by
        // their rounding. Arcs beside that range cost two comparisons, not
        // a cylinder test's square root and divisions.
        let (near, far) = (span.0.max(0.0), span.1.min(cutoff.get()));
        let (z_near, z_far) = (origin_z + near * dz, origin_z + far * dz);
        let z_slack = margin + gamma(2) * (origin_z.abs() + (near * dz).abs().max((far * dz).abs()));
        let (z_low, z_high) = (z_near.min(z_far) - z_slack, z_near.max(z_far) + z_slack);
        let mut order = [(0.0, 0_usize); MAX_ARCS];
        let mut crossed = 0;
        for (arc_index, arc) in self.arcs.iter().enumerate() {
            if arc.z_max < z_low || arc.z_min > z_high {
                continue;
            }
            let Some(entry) = arc.entry(ray, margin) else {
                continue;
            };
            if entry >= cutoff.get() {
                continue;
            }
            let mut place = crossed;
            while place > 0 && order[place - 1].0 > entry {
                order[place] = order[place - 1];
                place -= 1;
            }
            order[place] = (entry, arc_index);
            crossed += 1;
        }
        for &(entry, arc_index) in &order[..crossed] {
            if entry >= cutoff.get() {
                break;
            }
            let arc = &self.arcs[arc_index];
            let mut a = [0.0; N];
            let mut x = [0.0; N];
            for i in 0..=n {
                a[i] = h * (arc.y[i] - origin_z) + dz * ray.along;
                x[i] = arc.x[i];
            }
            let piece = RayProfilePiece {
                a,
                x,
                count: n + 1,
                a_range: range(&a[..=n]),
                x_range: range(&x[..=n]),
                dz_squared: dz * dz,
                across: ray.across,
                width: arc.t1 - arc.t0,
                a_error: h * arc.y_error,
                x_error: arc.x_error,
                a_rounding: gamma(4) * (h * (self.height_size + arc.y_error + origin_z.abs()) + (dz * ray.along).abs())
                    + dz.abs() * ray.frame_error,
            };
            self.isolate_arc(ray, index, size, arc, &piece, cutoff, consider);
        }
    }

    /// Reports the verified hits of the ray with one arc, whose ray–profile
    /// polynomial is `piece`.
    #[allow(clippy::too_many_arguments)]
    fn isolate_arc<const N: usize>(
        &self,
        ray: &LocalRay,
        index: usize,
        size: f64,
        arc: &Arc,
        piece: &RayProfilePiece<N>,
        cutoff: &Cell<f64>,
        consider: &mut impl FnMut(Candidate),
    ) {
        let n = self.degree;
        let dz = ray.direction.z;
        let h = ray.horizontal_speed;
        let origin_z = ray.origin.z;
        let mut skip = |piece: &RayProfilePiece<N>| piece.nearest_parameter(ray) > cutoff.get();
        roots::isolate_roots(
            piece,
            arc.t0,
            arc.t1,
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
                    self.verify_and_report(ray, index, size, root, (point, derivative), s_height, height_error, consider);
                } else if a_value.abs() > a_error {
                    let branch = a_value.signum() * dz.signum();
                    if let Some(s) = radial.parameter(branch) {
                        self.verify_and_report(ray, index, size, root, (point, derivative), s, radial.error, consider);
                    }
                } else {
                    // Entry and exit are not separable: both are surface points
                    // within the error bounds.
                    for branch in [-1.0, 1.0] {
                        if let Some(s) = radial.parameter(branch) {
                            self.verify_and_report(ray, index, size, root, (point, derivative), s, radial.error, consider);
                        }
                    }
                }
            },
        );
    }

    /// Checks that the ray point at `s` lies on the profile's tangent line at
    /// the root (distance in the meridian plane, within the error bounds) and
    /// that `s` exceeds its own error bound, then reports the candidate.
    /// `profile` and `derivative` are the curve's point and tangent at the root.
    #[allow(clippy::too_many_arguments)]
    fn verify_and_report(
        &self,
        ray: &LocalRay,
        index: usize,
        size: f64,
        root: IsolatedRoot,
        (profile, derivative): (DVec2, DVec2),
        s: f64,
        s_error: f64,
        consider: &mut impl FnMut(Candidate),
    ) {
        // Also rejects NaN.
        if s.is_nan() || s <= 2.0 * s_error + gamma(16) * s.abs() {
            return;
        }
        let point = ray.origin + s * ray.direction;
        let radial = super::axis_distance(point.x, point.y);
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
