//! Spheres, intersected with the cancellation-free quadratic of Haines et al.
//! (Ray Tracing Gems, ch. 7) so that smallpt's radius-1e5 walls stay exact.

use super::hit::{AreaSample, SurfaceHit};
use super::sampling::{self, ShapeSample};
use crate::math::{Aabb, Frame, Ray, gamma, warp};
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// The hit distance h below which, as a fraction of the distance d to the
/// centre, [`Sphere::sample_from`] measures its point's distance instead of
/// taking the cone's hit distance (whose rounding error grows as h falls).
const NEAR_CONTACT: f64 = 0.25;

/// A sphere in world space; normals point outward, uv is equirectangular
/// (see [`Sphere::uv_of`]).
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    /// Centre, world space.
    pub center: DVec3,
    /// Radius in scene units (positive).
    pub radius: f64,
}

impl Sphere {
    /// The axis-aligned cube around the sphere.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(
            self.center - DVec3::splat(self.radius),
            self.center + DVec3::splat(self.radius),
        )
    }

    /// Surface area 4πr².
    pub fn area(&self) -> f64 {
        4.0 * PI * self.radius * self.radius
    }

    /// Nearest hit in `(0, t_max)`.
    #[inline(always)]
    pub fn hit_distance(&self, ray: &Ray, t_max: f64) -> Option<f64> {
        let f = ray.origin - self.center;
        let b = f.dot(ray.direction);
        let c = f.length_squared() - self.radius * self.radius;
        // r² - |f - (f·d) d|² equals b² - c but without subtracting two
        // nearly equal large numbers when the ray passes far from the centre.
        let closest = f - b * ray.direction;
        let discriminant = self.radius * self.radius - closest.length_squared();
        if discriminant < 0.0 {
            return None;
        }
        let q = -b - discriminant.sqrt().copysign(b);
        let (t0, t1) = {
            let a = c / q;
            if a < q { (a, q) } else { (q, a) }
        };
        Self::root_within(t0, t1, t_max)
    }

    /// The root a hit reports, given both roots nearer first: the nearer
    /// one in `(0, t_max)`, else the farther one there (a ray from inside).
    #[inline(always)]
    pub fn root_within(near: f64, far: f64, t_max: f64) -> Option<f64> {
        if near > 0.0 && near < t_max {
            Some(near)
        } else if far > 0.0 && far < t_max {
            Some(far)
        } else {
            None
        }
    }

    /// The nearest hit before `t_max`, with its record (normal, uv, error
    /// bounds). Shadow rays need only [`Sphere::hit_distance`], which skips
    /// the record and its two inverse trigonometric functions.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<SurfaceHit> {
        let t = self.hit_distance(ray, t_max)?;
        Some(self.hit_at(ray.at(t), t))
    }

    /// The hit record for a point near the surface, reprojected onto it.
    pub fn hit_at(&self, approximate_point: DVec3, t: f64) -> SurfaceHit {
        let hit = self.hit_at_without_uv(approximate_point, t);
        SurfaceHit {
            uv: Self::uv_of(hit.geometric_normal),
            ..hit
        }
    }

    /// The same record with uv left (0, 0), for materials that read no
    /// texture: spares the atan2 and acos of [`Sphere::uv_of`].
    #[inline]
    pub fn hit_at_without_uv(&self, approximate_point: DVec3, t: f64) -> SurfaceHit {
        let normal = (approximate_point - self.center).normalize();
        let (point, point_error) = self.point_with_normal(normal);
        SurfaceHit {
            t,
            point,
            point_error,
            geometric_normal: normal,
            shading_normal: normal,
            uv: DVec2::ZERO,
        }
    }

    /// The surface point whose outward unit normal is `normal`, with its
    /// per-axis error bound: a handful of roundings on |p| (pbrt-v4 6.8.5).
    #[inline]
    pub fn point_with_normal(&self, normal: DVec3) -> (DVec3, DVec3) {
        let point = self.center + self.radius * normal;
        (point, gamma(5) * (point.abs() + self.center.abs()))
    }

    /// Equirectangular coordinates of a unit direction from the centre:
    /// u = 0.5 + longitude / 2π with longitude 0 towards +z (so u = 0.5 faces
    /// a camera on the +z axis), v = polar angle / π, 0 at +y (north).
    pub fn uv_of(direction: DVec3) -> DVec2 {
        let longitude = direction.x.atan2(direction.z); // 0 towards +z
        let u = 0.5 + longitude / (2.0 * PI);
        let v = direction.y.clamp(-1.0, 1.0).acos() / PI;
        DVec2::new(u, v)
    }

    /// A point as seen from `reference`: from outside, a uniform direction
    /// in the cone the sphere subtends (pbrt-v3 §14.2.2), mapped to the
    /// visible surface point it passes through; from inside, a uniform
    /// point on the area.
    pub fn sample_from(&self, reference: DVec3, u: DVec2) -> Option<ShapeSample> {
        if !self.is_outside(reference) {
            return sampling::by_area(self.sample_area(u), self.area(), reference);
        }
        let distance_squared = (self.center - reference).length_squared();
        let distance = distance_squared.sqrt();
        let cos_max = self.cone_cos_max(reference);
        let (cos_theta, azimuth) = warp::square_to_uniform_cone_angles(u, cos_max);
        let sin2_theta = (1.0 - cos_theta * cos_theta).max(0.0);
        // Angle α at the centre between the axis and the surface point
        // (law of cosines on the triangle reference–centre–point).
        let radius_squared = self.radius * self.radius;
        let half_chord = (radius_squared - distance_squared * sin2_theta).max(0.0).sqrt();
        let hit_distance = distance * cos_theta - half_chord;
        // The law of cosines gives cos α = (d² + r² − h²) / 2dr, whose
        // numerator is 2d (d sin²θ + s cos θ) with s the half chord: so
        // cos α = (d sin²θ + s cos θ) / r (pbrt-v4's form, §6.2.4), a sum of
        // two non-negative terms where the first form cancels (d² − h² for a
        // small far sphere), and a product with 1/r, known early, where it
        // divided at the end of the chain.
        let cos_alpha = ((distance * sin2_theta + half_chord * cos_theta) * self.radius.recip()).clamp(-1.0, 1.0);
        let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
        let frame = Frame::from_normal((reference - self.center) / distance);
        let normal = frame.to_world(DVec3::new(sin_alpha * azimuth.x, sin_alpha * azimuth.y, cos_alpha));
        let point = self.center + self.radius * normal;
        // The point's distance is the cone's hit distance h: α came from it
        // by the law of cosines, so |point − reference| = h in exact
        // arithmetic, and after rounding they agree to within the point's
        // own error bound (at most half of it in the test below) where
        // h > d/4. Nearer the sphere, where d cos θ and the half chord
        // cancel in h, the point's measured distance is taken. Taking h
        // spares the square root and the division after it that made the
        // light sample wait for its point (caustic.toml 4–5% less time per
        // sample, docs/performance.md). A shadow ray aimed along (point − reference)/distance, as
        // the path tracer's is, reaches the point at t = distance whatever
        // the rounding, so a segment ending short of that t ends short of
        // the point.
        let point_distance = if hit_distance > distance * NEAR_CONTACT {
            hit_distance
        } else {
            (point - reference).length()
        };
        let pdf = warp::uniform_cone_pdf(cos_max);
        (pdf.is_finite() && cos_max < 1.0).then_some(ShapeSample {
            point,
            point_error: gamma(5) * (point.abs() + self.center.abs()),
            normal,
            distance: point_distance,
            pdf,
        })
    }

    /// The solid-angle density of [`Sphere::sample_from`] at `reference`
    /// for the surface point `point` with normal `normal`.
    pub fn pdf_from(&self, reference: DVec3, point: DVec3, normal: DVec3) -> f64 {
        if self.is_outside(reference) {
            warp::uniform_cone_pdf(self.cone_cos_max(reference))
        } else {
            sampling::pdf_by_area(self.area(), reference, point, normal)
        }
    }

    /// Area of the part of the surface [`Sphere::sample_from`] draws from
    /// at `reference`: from outside, the cap in front of the horizon, whose
    /// normals lie within acos(r / d) of the direction to the reference
    /// (area 2πr²(1 − r/d)); from inside, the whole sphere.
    pub fn sampled_area_from(&self, reference: DVec3) -> f64 {
        if self.is_outside(reference) {
            let distance = (reference - self.center).length();
            2.0 * PI * self.radius * self.radius * (1.0 - self.radius / distance)
        } else {
            self.area()
        }
    }

    /// Whether cone sampling applies: `reference` lies (safely) outside.
    fn is_outside(&self, reference: DVec3) -> bool {
        (reference - self.center).length_squared() > self.radius * self.radius * (1.0 + 1e-9)
    }

    /// cos θmax of the cone the sphere subtends at `reference` (outside).
    fn cone_cos_max(&self, reference: DVec3) -> f64 {
        let sin2_max = self.radius * self.radius / (reference - self.center).length_squared();
        (1.0 - sin2_max).max(0.0).sqrt()
    }

    /// Uniform point on the surface; density `1 / area`.
    pub fn sample_area(&self, u: DVec2) -> AreaSample {
        let normal = warp::square_to_uniform_sphere(u);
        // The point as `hit_at` places one (its normal renormalised from
        // the approximate point), so samples are those of earlier versions
        // bit for bit; without the hit record's uv (an atan2 and an acos).
        let on_surface = (self.center + self.radius * normal - self.center).normalize();
        let (point, point_error) = self.point_with_normal(on_surface);
        AreaSample {
            point,
            point_error,
            normal,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_at_known_distances_from_outside_and_inside() {
        let s = Sphere {
            center: DVec3::new(0.0, 0.0, 5.0),
            radius: 1.0,
        };
        let outside = s.intersect(&Ray::new(DVec3::ZERO, DVec3::Z), f64::INFINITY).map(|h| h.t);
        assert!((outside.unwrap_or(0.0) - 4.0).abs() < 1e-12);
        let inside = s.intersect(&Ray::new(s.center, DVec3::X), f64::INFINITY);
        let inside = inside.map(|h| (h.t, h.geometric_normal));
        assert!(matches!(inside, Some((t, n)) if (t - 1.0).abs() < 1e-12 && (n - DVec3::X).length() < 1e-12));
        assert!(s.intersect(&Ray::new(DVec3::ZERO, -DVec3::Z), f64::INFINITY).is_none());
        assert!(s.intersect(&Ray::new(DVec3::ZERO, DVec3::Z), 3.9).is_none());
    }

    #[test]
    fn huge_walls_are_hit_where_they_are() {
        // smallpt's left wall: centre (1e5 + 1, 40.8, 81.6), radius 1e5, surface at x = 1.
        let wall = Sphere {
            center: DVec3::new(1e5 + 1.0, 40.8, 81.6),
            radius: 1e5,
        };
        let ray = Ray::new(DVec3::new(50.0, 40.8, 81.6), -DVec3::X);
        let hit = wall.intersect(&ray, f64::INFINITY).map(|h| (h.t, h.point.x));
        assert!(matches!(hit, Some((t, x)) if (t - 49.0).abs() < 1e-9 && (x - 1.0).abs() < 1e-9));
        // A grazing ray almost parallel to the wall, 10 units off it, misses.
        let graze = Ray::new(DVec3::new(11.0, 40.8, 81.6), DVec3::new(0.0, 1.0, 0.0));
        let hit = wall.intersect(&graze, 100.0);
        assert!(hit.is_none());
    }

    /// A light sample's distance is its point's, to within the point's error
    /// bound, for references from 10⁻³ to 10⁴ radii off the surface (spheres
    /// of radius 10⁻² to 10² up to 170 units out); and a shadow segment
    /// built as the path tracer builds it (towards the point, stopped 10⁻⁹
    /// of the distance and the point's error short) never reaches the
    /// sphere it is aimed at.
    #[test]
    fn sampled_distances_are_the_points_and_shadow_segments_stop_short() {
        let mut state = 7u64;
        let mut next = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut worst, mut samples) = (0.0f64, 0);
        for _ in 0..200_000 {
            let sphere = Sphere {
                center: DVec3::new(next(), next(), next()) * 200.0 - 100.0,
                radius: 10f64.powf(4.0 * next() - 2.0),
            };
            // Gaps d − r from 10⁻³ to 10⁴ radii, log-uniform.
            let gap = sphere.radius * 10f64.powf(7.0 * next() - 3.0);
            let direction = warp::square_to_uniform_sphere(DVec2::new(next(), next()));
            let reference = sphere.center + (sphere.radius + gap) * direction;
            let Some(sample) = sphere.sample_from(reference, DVec2::new(next(), next())) else {
                continue;
            };
            samples += 1;
            let measured = (sample.point - reference).length();
            // In units of what the point is known to: its error bound, and
            // a few roundings of the distance.
            let known_to = sample.point_error.abs().element_sum() + 1e-15 * measured;
            worst = worst.max((sample.distance - measured).abs() / known_to);
            let shadow = Ray {
                origin: reference,
                direction: (sample.point - reference) / sample.distance,
            };
            let t_max = sample.distance * (1.0 - 1e-9) - sample.point_error.abs().element_sum();
            assert!(
                sphere.hit_distance(&shadow, t_max).is_none(),
                "{sphere:?} from {reference}: the segment reaches the light ({sample:?})"
            );
        }
        assert!(samples > 190_000, "{samples} samples");
        assert!(
            worst < 1.0,
            "distance and point disagree by {worst} times what the point is known to"
        );
    }
}
