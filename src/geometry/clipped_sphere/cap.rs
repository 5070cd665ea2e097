//! Spherical caps of an emitting sphere cut off by another sphere's surface.
//!
//! Two spheres whose surfaces cross meet in a circle, and that circle splits
//! each surface into two caps. On the emitter (centre c, radius R) with the
//! other sphere centred at c′ = c + d a (|a| = 1) with radius r, the point
//! with outward normal n lies inside the other sphere exactly when
//! |R n − d a|² < r², that is when n · a > cos α with
//! cos α = (R² + d² − r²) / (2 R d) (the law of cosines on the triangle of
//! the two centres and a point of the circle). A cap is kept as its axis and
//! its versine 1 − cos α, which for the small caps this module exists for is
//! computed without cancellation from the factored forms
//! 1 − cos α = (r − d + R)(r + d − R) / (2 R d) and
//! 1 + cos α = (R + d − r)(R + d + r) / (2 R d).

use crate::math::Frame;
use crate::math::trig::cos_sin_turns;
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// The points of a sphere whose unit normal n satisfies 1 − n · axis ≤ versine.
#[derive(Clone, Copy, Debug)]
pub struct SphereCap {
    /// 1 − cos of the cap's angular radius about the sphere's centre, in [0, 2].
    pub versine: f64,
    /// A basis whose normal is the cap's axis (the unit normal of its
    /// centre), made once: every light sample maps its normal through it,
    /// and making it takes a division.
    frame: Frame,
}

impl SphereCap {
    /// The two caps into which the surface of the sphere `other_center`,
    /// `other_radius` splits the sphere `center`, `radius`: (the part inside
    /// the other sphere, the part outside). `None` unless the two surfaces
    /// cross in a circle (|R − r| < d < R + r).
    pub fn split_by(center: DVec3, radius: f64, other_center: DVec3, other_radius: f64) -> Option<(Self, Self)> {
        let offset = other_center - center;
        let distance = offset.length();
        let (big_r, r, d) = (radius, other_radius, distance);
        if !((big_r - r).abs() < d && d < big_r + r) {
            return None;
        }
        let axis = offset / distance;
        let denominator = 2.0 * big_r * d;
        let versine_inside = ((r - d + big_r) * (r + d - big_r) / denominator).clamp(0.0, 2.0);
        let versine_outside = ((big_r + d - r) * (big_r + d + r) / denominator).clamp(0.0, 2.0);
        Some((Self::new(axis, versine_inside), Self::new(-axis, versine_outside)))
    }

    /// The cap of normals within acos(1 − `versine`) of the unit `axis`.
    pub fn new(axis: DVec3, versine: f64) -> Self {
        Self {
            versine,
            frame: Frame::from_normal(axis),
        }
    }

    /// Unit normal of the cap's centre.
    pub fn axis(&self) -> DVec3 {
        self.frame.n
    }

    /// Area of the cap on a sphere of radius `radius`: 2π R² (1 − cos α).
    pub fn area(&self, radius: f64) -> f64 {
        2.0 * PI * radius * radius * self.versine
    }

    /// Whether the point with unit outward normal `normal` lies on the cap.
    pub fn contains(&self, normal: DVec3) -> bool {
        1.0 - normal.dot(self.axis()) <= self.versine
    }

    /// The unit normal of a point uniform by area on the cap. Area on a
    /// sphere is solid angle of normals, which is uniform in cos θ about the
    /// axis (Archimedes): 1 − cos θ = u.x · versine, φ = 2π u.y.
    pub fn sample_normal(&self, u: DVec2) -> DVec3 {
        let versine = u.x * self.versine;
        let cos_theta = 1.0 - versine;
        // sin²θ = (1 − cos θ)(1 + cos θ), exact for the small θ of a small cap.
        let sin_theta = (versine * (2.0 - versine)).max(0.0).sqrt();
        let (cos_phi, sin_phi) = cos_sin_turns(u.y);
        let local = DVec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta);
        self.frame.to_world(local).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// smallpt's light (radius 600 at height 681.33) and ceiling (radius 1e5
    /// below it): the cap inside the ceiling sphere is bounded by the circle
    /// where both surfaces meet, and its area and that of the rest add up to
    /// the sphere's.
    #[test]
    fn caps_of_smallpt_light_meet_the_ceiling_on_its_surface() {
        let (light, radius) = (DVec3::new(50.0, 681.33, 81.6), 600.0);
        let (ceiling, ceiling_radius) = (DVec3::new(50.0, -99918.4, 81.6), 1e5);
        let Some((inside, outside)) = SphereCap::split_by(light, radius, ceiling, ceiling_radius) else {
            panic!("the light pokes through the ceiling");
        };
        assert!((inside.axis() - DVec3::NEG_Y).length() < 1e-15 && (outside.axis() - DVec3::Y).length() < 1e-15);
        // A point on the rim lies on both spheres: to 1e-9 of the ceiling's
        // radius, the rounding of its 1e5-sized coordinates.
        let sin_alpha = (inside.versine * (2.0 - inside.versine)).sqrt();
        let rim_normal = DVec3::new(sin_alpha, -(1.0 - inside.versine), 0.0);
        let rim = light + radius * rim_normal;
        assert!(((rim - ceiling).length() - ceiling_radius).abs() < 1e-9, "{rim}");
        // The rim circle has radius ≈ 17.94 (the hole the light makes).
        assert!((radius * sin_alpha - 17.944).abs() < 1e-3, "{}", radius * sin_alpha);
        let total = inside.area(radius) + outside.area(radius);
        assert!((total - 4.0 * PI * radius * radius).abs() < 1e-9 * total);
        // The lowest point is inside the ceiling sphere, the top outside.
        assert!(inside.contains(DVec3::NEG_Y) && !inside.contains(DVec3::Y));
        assert!(outside.contains(DVec3::Y) && !outside.contains(DVec3::NEG_Y));
        let lowest = light - DVec3::new(0.0, radius, 0.0);
        assert!((lowest - ceiling).length() < ceiling_radius);
    }

    /// Spheres that are apart, nested or tangent do not split each other.
    #[test]
    fn only_crossing_surfaces_split() {
        let unit = |x: f64, r: f64| SphereCap::split_by(DVec3::ZERO, 1.0, DVec3::new(x, 0.0, 0.0), r);
        assert!(unit(3.0, 1.0).is_none(), "apart");
        assert!(unit(2.0, 1.0).is_none(), "tangent outside");
        assert!(unit(0.2, 0.5).is_none(), "nested inside");
        assert!(unit(0.0, 1.0).is_none(), "the same sphere");
        assert!(unit(1.0, 5.0).is_none(), "inside the other");
        assert!(unit(1.0, 1.0).is_some(), "crossing");
    }

    /// Sampled normals stay on the cap, and their mean cos θ about the axis
    /// is the cap's centroid, 1 − versine / 2, as uniform area requires.
    #[test]
    fn sampled_normals_fill_the_cap_uniformly_in_cos_theta() {
        let cap = SphereCap::new(DVec3::new(0.3, -0.8, 0.2).normalize(), 0.4);
        let n = 64;
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let u = DVec2::new((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                let normal = cap.sample_normal(u);
                assert!((normal.length() - 1.0).abs() < 1e-12 && cap.contains(normal));
                sum += normal.dot(cap.axis());
            }
        }
        // A midpoint rule in u.x of a function linear in u.x is exact.
        assert!((sum / (n * n) as f64 - 0.8).abs() < 1e-12);
    }
}
