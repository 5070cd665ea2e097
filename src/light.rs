//! Emissive primitives as lights: a light is chosen in proportion to its
//! power, then its surface samples itself as seen from the shading point
//! (`Shape::sample_from`: the cone a sphere subtends, the area of anything
//! else; or, for a sphere cut by opaque spheres, `ClippedSphere::sample_from`:
//! the part the point might see). Lights only select and weight; the
//! densities they return are the ones the path tracer's MIS weights
//! recompute for BSDF-sampled hits.

use crate::color::{Color, luminance};
use crate::geometry::{AreaSample, ClippedSphere, Shape, ShapeSample, Triangle};
use crate::spectrum::{Emission, EmissionSpectrum};
use glam::{DVec2, DVec3};
use std::sync::Arc;

/// One emissive primitive.
#[derive(Clone, Debug)]
pub struct Light {
    /// The primitive's id in the scene.
    pub primitive: u32,
    /// Emitted radiance Le, constant over the surface and over directions,
    /// as the film's RGB (for a spectral emitter, its spectrum's RGB).
    pub radiance: Color,
    /// The light's own spectrum, if it has one (see `Material::Emissive`).
    pub spectrum: Option<Arc<EmissionSpectrum>>,
    /// Whether it emits from both faces; otherwise only towards the side its
    /// geometric normal points to.
    pub two_sided: bool,
    /// For a sphere whose surface opaque spheres cross: the sphere with
    /// them, which samples only what a point might see. `None` otherwise
    /// (the primitive's shape samples itself).
    pub clipped: Option<Box<ClippedSphere>>,
}

impl Light {
    /// What the light emits, in the form [`Radiance::emission`] takes.
    ///
    /// [`Radiance::emission`]: crate::spectrum::Radiance::emission
    pub fn emission(&self) -> Emission<'_> {
        Emission {
            rgb: self.radiance,
            spectrum: self.spectrum.as_deref(),
        }
    }
}

/// A point chosen on a light, seen from a reference point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample<'a> {
    /// Direction from the reference point to the light point:
    /// (`point` − reference) / `distance`, unit to within `point_error`
    /// over `distance`.
    pub wi: DVec3,
    /// Distance from the reference point to `point` (to within
    /// `point_error`); a ray along `wi` reaches `point` at t = `distance`.
    pub distance: f64,
    /// The chosen point on the light, world space.
    pub point: DVec3,
    /// Conservative absolute error bound of `point`, per axis (shadow rays
    /// stop short of the light by more than this).
    pub point_error: DVec3,
    /// Unit outward normal of the light at `point`.
    pub normal: DVec3,
    /// Radiance the light emits towards the reference point.
    pub emission: Emission<'a>,
    /// Solid-angle density, including the probability of choosing this light.
    pub pdf: f64,
    /// The light's primitive id in the scene.
    pub primitive: u32,
}

/// The surface of an emissive primitive: a shape, or one of the scene's triangles.
#[derive(Clone, Copy, Debug)]
pub enum Emitter<'a> {
    /// A primitive that is not a triangle (sphere, box, quad, revolution).
    Shape(&'a Shape),
    /// A triangle of the scene, in double precision.
    Triangle(Triangle),
}

impl Emitter<'_> {
    /// Surface area (one face: two-sidedness is the light's business).
    pub fn area(&self) -> f64 {
        match self {
            Emitter::Shape(shape) => shape.area(),
            Emitter::Triangle(triangle) => triangle.area(),
        }
    }

    /// Uniform point on the surface, density `1 / area()`.
    pub fn sample_area(&self, u: DVec2) -> AreaSample {
        match self {
            Emitter::Shape(shape) => shape.sample_area(u),
            Emitter::Triangle(triangle) => triangle.sample_area(u),
        }
    }

    fn sample_from(&self, reference: DVec3, u: DVec2) -> Option<ShapeSample> {
        match self {
            Emitter::Shape(shape) => shape.sample_from(reference, u),
            Emitter::Triangle(triangle) => triangle.sample_from(reference, u),
        }
    }

    fn pdf_from(&self, reference: DVec3, point: DVec3, normal: DVec3) -> f64 {
        match self {
            Emitter::Shape(shape) => shape.pdf_from(reference, point, normal),
            Emitter::Triangle(triangle) => triangle.pdf_from(reference, point, normal),
        }
    }
}

/// Where lights find their surfaces (the scene's geometry).
pub trait EmitterSource {
    /// The surface of the primitive with this id (see [`Light::primitive`]).
    fn emitter(&self, primitive: u32) -> Emitter<'_>;
}

/// All lights with their selection distribution.
#[derive(Clone, Debug, Default)]
pub struct Lights {
    /// Every emissive primitive with a non-black radiance.
    pub lights: Vec<Light>,
    /// Cumulative selection probabilities, last = 1.
    cdf: Vec<f64>,
    /// Selection probability per light.
    probability: Vec<f64>,
    /// (primitive, light index), sorted by primitive.
    by_primitive: Vec<(u32, u32)>,
    /// Sum of the lights' powers π · area · luminance(Le) (· 2 if two-sided):
    /// the normaliser of the selection probabilities, and the luminance of
    /// the total emitted power (photon flux scale).
    pub total_power: f64,
}

impl Lights {
    /// Weights are power = π · area · luminance (· 2 if two-sided).
    pub fn new(lights: Vec<Light>, source: &impl EmitterSource) -> Self {
        let powers: Vec<f64> = lights
            .iter()
            .map(|l| {
                let sides = if l.two_sided { 2.0 } else { 1.0 };
                std::f64::consts::PI * source.emitter(l.primitive).area() * luminance(l.radiance).max(1e-12) * sides
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
        let mut by_primitive: Vec<(u32, u32)> = lights.iter().enumerate().map(|(i, l)| (l.primitive, i as u32)).collect();
        by_primitive.sort_unstable();
        Self {
            probability: powers.iter().map(|p| p / total).collect(),
            lights,
            cdf,
            by_primitive,
            total_power: total,
        }
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.lights.len()
    }

    /// Whether the scene has no lights.
    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// The light a primitive is, if it emits.
    pub fn light_of_primitive(&self, primitive: u32) -> Option<u32> {
        self.by_primitive
            .binary_search_by_key(&primitive, |&(p, _)| p)
            .ok()
            .map(|found| self.by_primitive[found].1)
    }

    /// Picks a light by power: index and probability.
    pub fn choose(&self, u: f64) -> Option<(u32, f64)> {
        if self.lights.is_empty() {
            return None;
        }
        let index = self.cdf.partition_point(|&c| c <= u).min(self.lights.len() - 1);
        Some((index as u32, self.probability[index]))
    }

    /// The probability that [`choose`](Self::choose) picks light `index`.
    pub fn probability(&self, index: u32) -> f64 {
        self.probability[index as usize]
    }

    /// Samples a point on a light as seen from `reference`.
    // Always inlined: compiled into each copy of the path loop (baseline,
    // AVX2: `accel::kernel`) rather than called from it in baseline code.
    #[inline(always)]
    pub fn sample(&self, source: &impl EmitterSource, reference: DVec3, u_select: f64, u: DVec2) -> Option<LightSample<'_>> {
        let (index, selection) = self.choose(u_select)?;
        let light = &self.lights[index as usize];
        let sample = match &light.clipped {
            Some(clipped) => clipped.sample_from(reference, u),
            None => source.emitter(light.primitive).sample_from(reference, u),
        }?;
        let distance = sample.distance;
        let wi = (sample.point - reference) / distance;
        let facing = sample.normal.dot(-wi) > 0.0;
        if !(facing || light.two_sided) || !sample.pdf.is_finite() || sample.pdf <= 0.0 {
            return None;
        }
        Some(LightSample {
            wi,
            distance,
            point: sample.point,
            point_error: sample.point_error,
            normal: sample.normal,
            emission: light.emission(),
            pdf: sample.pdf * selection,
            primitive: light.primitive,
        })
    }

    /// Solid-angle density with which `sample` would have produced the
    /// point `point` (normal `normal`) on light `index` from `reference`,
    /// selection probability included.
    pub fn pdf(&self, source: &impl EmitterSource, index: u32, reference: DVec3, point: DVec3, normal: DVec3) -> f64 {
        let light = &self.lights[index as usize];
        let pdf = match &light.clipped {
            Some(clipped) => clipped.pdf_from(reference, point, normal),
            None => source.emitter(light.primitive).pdf_from(reference, point, normal),
        };
        pdf * self.probability[index as usize]
    }
}
