//! Emissive primitives as lights: chosen in proportion to their power, then
//! sampled by solid angle (spheres seen from outside: the cone they subtend,
//! pbrt-v3 §14.2.2) or by area (everything else), with densities that the
//! path tracer's MIS weights can recompute for BSDF-sampled hits.

use crate::color::{Color, luminance};
use crate::geometry::{Shape, SurfaceHit};
use crate::math::{Frame, gamma, warp};
use glam::{DVec2, DVec3};

/// One emissive primitive.
#[derive(Clone, Debug)]
pub struct Light {
    /// Index into the scene's primitives.
    pub primitive: u32,
    pub radiance: Color,
    pub two_sided: bool,
}

/// A point chosen on a light, seen from a reference point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the reference point to the light point.
    pub wi: DVec3,
    pub distance: f64,
    pub point: DVec3,
    pub point_error: DVec3,
    pub normal: DVec3,
    pub radiance: Color,
    /// Solid-angle density, including the probability of choosing this light.
    pub pdf: f64,
}

/// All lights with their selection distribution.
#[derive(Clone, Debug, Default)]
pub struct Lights {
    pub lights: Vec<Light>,
    /// Cumulative selection probabilities, last = 1.
    cdf: Vec<f64>,
    /// Selection probability per light.
    probability: Vec<f64>,
    /// Light index per primitive (None when the primitive does not emit).
    by_primitive: Vec<Option<u32>>,
    pub total_power: f64,
}

impl Lights {
    /// `shapes[i]` is primitive i; weights are power = π · area · luminance (· 2 if two-sided).
    pub fn new(lights: Vec<Light>, shapes: &[impl AsShape]) -> Self {
        let powers: Vec<f64> = lights
            .iter()
            .map(|l| {
                let sides = if l.two_sided { 2.0 } else { 1.0 };
                std::f64::consts::PI * shapes[l.primitive as usize].shape().area() * luminance(l.radiance).max(1e-12) * sides
            })
            .collect();
        let total: f64 = powers.iter().sum();
        let mut cdf = Vec::with_capacity(lights.len());
        let mut acc = 0.0;
        for p in &powers {
            acc += p / total;
            cdf.push(acc);
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        let mut by_primitive = vec![None; shapes.len()];
        for (i, l) in lights.iter().enumerate() {
            by_primitive[l.primitive as usize] = Some(i as u32);
        }
        Self {
            probability: powers.iter().map(|p| p / total).collect(),
            lights,
            cdf,
            by_primitive,
            total_power: total,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    pub fn light_of_primitive(&self, primitive: usize) -> Option<u32> {
        self.by_primitive.get(primitive).copied().flatten()
    }

    pub fn selection_probability(&self, light: u32) -> f64 {
        self.probability[light as usize]
    }

    /// Picks a light by power: index and probability.
    pub fn choose(&self, u: f64) -> Option<(u32, f64)> {
        if self.lights.is_empty() {
            return None;
        }
        let index = self.cdf.partition_point(|&c| c <= u).min(self.lights.len() - 1);
        Some((index as u32, self.probability[index]))
    }

    /// Samples a point on a light as seen from `reference`.
    pub fn sample(&self, shapes: &[impl AsShape], reference: DVec3, u_select: f64, u: DVec2) -> Option<LightSample> {
        let (index, selection) = self.choose(u_select)?;
        let light = &self.lights[index as usize];
        let shape = shapes[light.primitive as usize].shape();
        let (point, point_error, normal, pdf) = match shape {
            Shape::Sphere(sphere)
                if (reference - sphere.center).length_squared() > sphere.radius * sphere.radius * (1.0 + 1e-9) =>
            {
                sample_sphere_cone(sphere.center, sphere.radius, reference, u)?
            }
            _ => {
                let s = shape.sample_area(u);
                let to_light = s.point - reference;
                let distance_sq = to_light.length_squared();
                let cos_light = s.normal.dot(-to_light.normalize()).abs();
                if cos_light == 0.0 || distance_sq == 0.0 {
                    return None;
                }
                (s.point, s.point_error, s.normal, distance_sq / (cos_light * shape.area()))
            }
        };
        let to_light = point - reference;
        let distance = to_light.length();
        let wi = to_light / distance;
        let facing = normal.dot(-wi) > 0.0;
        if !(facing || light.two_sided) || !pdf.is_finite() || pdf <= 0.0 {
            return None;
        }
        Some(LightSample {
            wi,
            distance,
            point,
            point_error,
            normal,
            radiance: light.radiance,
            pdf: pdf * selection,
        })
    }

    /// Solid-angle density with which `sample` would have produced `hit` on
    /// light `index` from `reference` (selection probability included).
    pub fn pdf(&self, shapes: &[impl AsShape], index: u32, reference: DVec3, hit: &SurfaceHit) -> f64 {
        let light = &self.lights[index as usize];
        let shape = shapes[light.primitive as usize].shape();
        let selection = self.probability[index as usize];
        match shape {
            Shape::Sphere(sphere)
                if (reference - sphere.center).length_squared() > sphere.radius * sphere.radius * (1.0 + 1e-9) =>
            {
                let sin2_max = sphere.radius * sphere.radius / (reference - sphere.center).length_squared();
                let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
                warp::uniform_cone_pdf(cos_max) * selection
            }
            _ => {
                let to_light = hit.point - reference;
                let distance_sq = to_light.length_squared();
                let cos_light = hit.geometric_normal.dot(to_light.normalize()).abs();
                if cos_light == 0.0 {
                    return 0.0;
                }
                distance_sq / (cos_light * shape.area()) * selection
            }
        }
    }
}

/// Uniform direction in the cone a sphere subtends, mapped to the visible
/// surface point it passes through. Returns point, error, normal, pdf.
fn sample_sphere_cone(center: DVec3, radius: f64, reference: DVec3, u: DVec2) -> Option<(DVec3, DVec3, DVec3, f64)> {
    let distance_sq = (center - reference).length_squared();
    let distance = distance_sq.sqrt();
    let sin2_max = radius * radius / distance_sq;
    let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
    let cos_theta = (1.0 - u.x) + u.x * cos_max;
    let sin2_theta = (1.0 - cos_theta * cos_theta).max(0.0);
    let phi = 2.0 * std::f64::consts::PI * u.y;
    // Angle α at the centre between the axis and the surface point
    // (law of cosines on the triangle reference–centre–point).
    let hit_distance = distance * cos_theta - (radius * radius - distance_sq * sin2_theta).max(0.0).sqrt();
    let cos_alpha = ((distance_sq + radius * radius - hit_distance * hit_distance) / (2.0 * distance * radius)).clamp(-1.0, 1.0);
    let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
    let frame = Frame::from_normal((reference - center) / distance);
    let normal = frame.to_world(DVec3::new(sin_alpha * phi.cos(), sin_alpha * phi.sin(), cos_alpha));
    let point = center + radius * normal;
    let point_error = gamma(5) * (point.abs() + center.abs());
    let pdf = warp::uniform_cone_pdf(cos_max);
    (pdf.is_finite() && cos_max < 1.0).then_some((point, point_error, normal, pdf))
}

/// Anything that holds a shape (the scene's primitives).
pub trait AsShape {
    fn shape(&self) -> &Shape;
}
