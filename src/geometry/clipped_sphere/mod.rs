//! An emitting sphere cut by the closed opaque spheres whose surfaces cross
//! its own, sampled only where a reference point might see it.
//!
//! The rule: a straight segment from a point strictly inside a sphere to a
//! point strictly outside it crosses its surface, so if that surface is
//! opaque no light travels along it. From a reference point p inside a
//! clipping sphere, the emitter's part outside it is hidden, and from p
//! outside, its part inside. Each part is a spherical cap ([`SphereCap`]),
//! so where several clipping spheres apply, what p can see lies in every
//! one of their caps at once.
//!
//! Sampling at p: the smallest applicable cap, uniformly by area (its
//! density d² / (|cos θ| A) per unit solid angle), when it is smaller than
//! the part the sphere's own sampling covers (the cap in front of p's
//! horizon, sampled by cone, or the whole sphere from inside); otherwise the
//! sphere's own sampling. A point outside any applicable cap is then
//! dropped, and `pdf_from` is 0 there; elsewhere `pdf_from` is the density
//! of the same choice, which depends on p alone. So the density is positive
//! wherever a segment from p can reach the emitter, and sampling and `pdf_from`
//! agree, which is all that unbiased light sampling and its MIS weights need.
//!
//! A reference point on a clipping sphere's surface (within 10⁻⁹ of the
//! coordinates' size: far beyond a hit point's error bound, a few 10⁻¹⁶ of
//! them by pbrt's γₙ analysis, and beyond the offset of the rays spawned
//! there) cannot be placed on a side, and that sphere then clips nothing
//! for it: smallpt's ceiling, seen from its own points. Exact solid-angle
//! sampling of a cap seen from p has no closed form (the rim seen from p is
//! an elliptic cone, Guillén et al. 2017 need numerical inversion), so caps
//! are sampled by area, which for a cap small against its distance from p
//! is nearly uniform in solid angle.

mod cap;

pub use cap::SphereCap;

use super::hit::AreaSample;
use super::sampling::{self, ShapeSample};
use super::sphere::Sphere;
use glam::{DVec2, DVec3};

/// Relative width of the band around a clipping sphere's surface within
/// which a reference point is taken to lie on it (see the module docs).
const SURFACE_BAND: f64 = 1e-9;

/// One clipping sphere and the two caps its surface cuts from the emitter.
#[derive(Clone, Debug)]
struct Clip {
    center: DVec3,
    radius: f64,
    /// radius + largest |centre coordinate|: the size its rounding scales with.
    size: f64,
    /// The emitter's part inside the clipping sphere, and its area.
    inside: SphereCap,
    inside_area: f64,
    /// The emitter's part outside, and its area.
    outside: SphereCap,
    outside_area: f64,
}

impl Clip {
    /// The cap a reference point can see through this sphere (with its
    /// area), or `None` if the point lies on the sphere's surface;
    /// `reference_size` is the point's largest |coordinate|.
    #[inline]
    fn visible_cap(&self, reference: DVec3, reference_size: f64) -> Option<(&SphereCap, f64)> {
        let band = SURFACE_BAND * (self.size + reference_size);
        let distance_squared = (reference - self.center).length_squared();
        let inner = (self.radius - band).max(0.0);
        let outer = self.radius + band;
        if distance_squared < inner * inner {
            Some((&self.inside, self.inside_area))
        } else if distance_squared > outer * outer {
            Some((&self.outside, self.outside_area))
        } else {
            None
        }
    }
}

/// An emitting sphere with the opaque spheres whose surfaces cross it.
#[derive(Clone, Debug)]
pub struct ClippedSphere {
    /// The emitting sphere.
    pub sphere: Sphere,
    clips: Vec<Clip>,
}

impl ClippedSphere {
    /// The emitter `sphere` clipped by those of `opaque` whose surfaces cross
    /// its own; `None` if none does (the sphere samples itself as before).
    /// The emitter itself may be among `opaque`: it does not cross itself.
    pub fn new(sphere: Sphere, opaque: impl IntoIterator<Item = Sphere>) -> Option<Self> {
        let clips: Vec<Clip> = opaque
            .into_iter()
            .filter_map(|other| {
                let (inside, outside) = SphereCap::split_by(sphere.center, sphere.radius, other.center, other.radius)?;
                Some(Clip {
                    center: other.center,
                    radius: other.radius,
                    size: other.radius + other.center.abs().max_element(),
                    inside_area: inside.area(sphere.radius),
                    inside,
                    outside_area: outside.area(sphere.radius),
                    outside,
                })
            })
            .collect();
        (!clips.is_empty()).then_some(Self { sphere, clips })
    }

    /// Number of clipping spheres.
    pub fn clip_count(&self) -> usize {
        self.clips.len()
    }

    /// The smallest cap visible from `reference` if it is smaller than what
    /// the sphere's own sampling covers there: the cap to sample by area.
    #[inline]
    fn cap_to_sample(&self, reference: DVec3) -> Option<(&SphereCap, f64)> {
        let reference_size = reference.abs().max_element();
        let smallest = self
            .clips
            .iter()
            .filter_map(|clip| clip.visible_cap(reference, reference_size))
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        (smallest.1 < self.sphere.sampled_area_from(reference)).then_some(smallest)
    }

    /// The smallest cap of the emitter that every point of the ball
    /// (`center`, `radius`) might see, with its area: a straight segment
    /// from the ball to the emitter crosses no clipping sphere, so it ends
    /// on the ball's side of each, and the smallest of those caps holds
    /// every such end. `None` if the ball straddles a clipping sphere's
    /// surface (points of it see either side); then only the whole sphere
    /// is sure to hold them.
    pub fn cap_seen_by_ball(&self, center: DVec3, radius: f64) -> Option<(SphereCap, f64)> {
        let mut smallest: Option<(SphereCap, f64)> = None;
        for clip in &self.clips {
            let distance = (center - clip.center).length();
            // A margin far beyond rounding, as for reference points.
            let band = SURFACE_BAND * (clip.size + center.abs().max_element() + radius);
            let side = if distance + radius < clip.radius - band {
                (clip.inside, clip.inside_area)
            } else if distance - radius > clip.radius + band {
                (clip.outside, clip.outside_area)
            } else {
                return None;
            };
            if smallest.is_none_or(|(_, area)| side.1 < area) {
                smallest = Some(side);
            }
        }
        smallest
    }

    /// Whether the point with unit normal `normal` lies in every cap
    /// visible from `reference` (else a clipping sphere hides it).
    #[inline]
    fn unclipped_from(&self, reference: DVec3, normal: DVec3) -> bool {
        let reference_size = reference.abs().max_element();
        self.clips.iter().all(|clip| {
            clip.visible_cap(reference, reference_size)
                .is_none_or(|(cap, _)| cap.contains(normal))
        })
    }

    /// A point that `reference` might see, with its density per unit solid
    /// angle there; `None` if the point drawn is hidden by a clipping sphere.
    pub fn sample_from(&self, reference: DVec3, u: DVec2) -> Option<ShapeSample> {
        let sample = self.sample_before_clipping(reference, u)?;
        self.unclipped_from(reference, sample.normal).then_some(sample)
    }

    /// A point of the emitter drawn uniformly by area on one of its caps
    /// (density 1 / the cap's area).
    pub fn sample_cap(&self, cap: &SphereCap, u: DVec2) -> AreaSample {
        let normal = cap.sample_normal(u);
        let (point, point_error) = self.sphere.point_with_normal(normal);
        AreaSample {
            point,
            point_error,
            normal,
        }
    }

    /// The point [`ClippedSphere::sample_from`] draws before it drops those
    /// a clipping sphere hides.
    fn sample_before_clipping(&self, reference: DVec3, u: DVec2) -> Option<ShapeSample> {
        match self.cap_to_sample(reference) {
            Some((cap, area)) => sampling::by_area(self.sample_cap(cap, u), area, reference),
            None => self.sphere.sample_from(reference, u),
        }
    }

    /// The solid-angle density of [`ClippedSphere::sample_from`] at
    /// `reference` for the surface point `point` with normal `normal`.
    pub fn pdf_from(&self, reference: DVec3, point: DVec3, normal: DVec3) -> f64 {
        if !self.unclipped_from(reference, normal) {
            return 0.0;
        }
        match self.cap_to_sample(reference) {
            Some((_, area)) => sampling::pdf_by_area(area, reference, point, normal),
            None => self.sphere.pdf_from(reference, point, normal),
        }
    }
}

/// Each of `emitters` clipped by those of `opaque` whose surfaces cross it
/// (clips in the order of `opaque`), or `None` where none does. Candidate
/// pairs are those whose extents along x overlap, found by sweep and prune
/// (one sort of the interval ends, Baraff 1992) rather than by testing
/// every pair, so that a scene of many emitting and many opaque spheres
/// loads in O(n log n) plus the number of pairs whose x extents overlap.
pub fn clip_emitters(emitters: &[Sphere], opaque: &[Sphere]) -> Vec<Option<ClippedSphere>> {
    // Interval ends (x, is_end, is_opaque, index); at equal x starts come
    // first, so touching extents count as overlapping.
    let extent = |s: &Sphere| (s.center.x - s.radius, s.center.x + s.radius);
    let mut events: Vec<(f64, bool, bool, usize)> = Vec::with_capacity(2 * (emitters.len() + opaque.len()));
    for (is_opaque, spheres) in [(false, emitters), (true, opaque)] {
        for (index, sphere) in spheres.iter().enumerate() {
            let (low, high) = extent(sphere);
            events.push((low, false, is_opaque, index));
            events.push((high, true, is_opaque, index));
        }
    }
    events.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut candidates: Vec<Vec<usize>> = vec![Vec::new(); emitters.len()];
    let (mut open_emitters, mut open_opaque): (Vec<usize>, Vec<usize>) = (Vec::new(), Vec::new());
    for (_, is_end, is_opaque, index) in events {
        let open = if is_opaque { &mut open_opaque } else { &mut open_emitters };
        if is_end {
            open.retain(|&i| i != index);
            continue;
        }
        open.push(index);
        if is_opaque {
            for &emitter in &open_emitters {
                candidates[emitter].push(index);
            }
        } else {
            candidates[index].extend_from_slice(&open_opaque);
        }
    }
    emitters
        .iter()
        .zip(candidates)
        .map(|(emitter, mut found)| {
            found.sort_unstable();
            ClippedSphere::new(*emitter, found.into_iter().map(|j| opaque[j]))
        })
        .collect()
}

#[cfg(test)]
mod tests;
