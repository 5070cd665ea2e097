//! Clipped-sphere sampling against its density: χ² goodness-of-fit tests of
//! the directions drawn from several reference points (smallpt's light cut
//! by its ceiling and walls, a large cap, two clips that both cut, a point
//! inside the emitter, a point so close that the cone wins), the density's
//! integral, and the pair search against every pair.

use super::*;
use crate::math::Ray;
use crate::math::chi_square::{ChiSquareTest, SphericalCap, sidak_significance};
use crate::sampler::{Sampler, SamplerKind};

/// Probability that the family of χ² tests of correct code fails anywhere;
/// the seeds are fixed, so a passing run always passes.
const FAMILY_SIGNIFICANCE: f64 = 0.01;
/// Number of χ² tests in the family (for Šidák's correction).
const CHI_SQUARE_TESTS: usize = 7;

fn sphere(center: [f64; 3], radius: f64) -> Sphere {
    Sphere {
        center: DVec3::from_array(center),
        radius,
    }
}

/// smallpt's light and its six walls (the floor's sphere holds the light
/// whole, so it does not clip).
fn smallpt() -> (Sphere, Vec<Sphere>) {
    let light = sphere([50.0, 681.33, 81.6], 600.0);
    let walls = vec![
        sphere([1e5 + 1.0, 40.8, 81.6], 1e5),
        sphere([-99901.0, 40.8, 81.6], 1e5),
        sphere([50.0, 40.8, 1e5], 1e5),
        sphere([50.0, 40.8, -99830.0], 1e5),
        sphere([50.0, 1e5, 81.6], 1e5),
        sphere([50.0, -99918.4, 81.6], 1e5),
    ];
    (light, walls)
}

/// The point of the emitter a direction from `reference` meets first, with
/// its normal, if the light there faces the reference (or from inside, any).
fn first_hit(emitter: &Sphere, reference: DVec3, direction: DVec3) -> Option<(DVec3, DVec3)> {
    let hit = emitter.intersect(&Ray::new(reference, direction), f64::INFINITY)?;
    Some((hit.point, hit.geometric_normal))
}

/// Runs one χ² test and asserts it accepts at the family's Šidák level.
fn assert_accepted(what: &str, reference: DVec3, outcome: &crate::math::chi_square::ChiSquareOutcome) {
    let significance = sidak_significance(FAMILY_SIGNIFICANCE, CHI_SQUARE_TESTS);
    eprintln!("χ² of {what} from {reference}: {outcome}");
    assert!(outcome.accepts(significance), "{what} from {reference}: {outcome}");
}

/// The test both binnings share: 200 000 independent samples in 16 × 32
/// bins of equal solid angle.
fn chi_square_test(seed: u64) -> ChiSquareTest {
    ChiSquareTest {
        samples: 200_000,
        seed,
        bins: (16, 32),
    }
}

/// χ² test of the directions `clipped.sample_from(reference)` gives a
/// one-sided light seen from outside (samples facing away dropped, as
/// `Lights::sample` does), or any light from inside, against `pdf_from` at
/// the first point of the emitter each direction meets: what the path
/// tracer's MIS weights evaluate. Binned over `bins`, whose rim the
/// sampled region's rim should not cross often: the bins' expected counts
/// are integrated adaptively, and jumps across a bin cost many halvings.
fn chi_square_of_directions(clipped: &ClippedSphere, reference: DVec3, bins: SphericalCap, seed: u64) {
    let outside = (reference - clipped.sphere.center).length() > clipped.sphere.radius;
    let outcome = chi_square_test(seed).directions(
        bins,
        |sampler: &mut Sampler| {
            let sample = clipped.sample_from(reference, sampler.next_2d())?;
            let to_point = sample.point - reference;
            if outside && sample.normal.dot(to_point) >= 0.0 {
                return None;
            }
            // The sample's density is the one `pdf_from` gives its point.
            let pdf = clipped.pdf_from(reference, sample.point, sample.normal);
            assert!((sample.pdf - pdf).abs() <= 1e-9 * pdf, "sampled {} against {pdf}", sample.pdf);
            Some(to_point.normalize())
        },
        |wi| match first_hit(&clipped.sphere, reference, wi) {
            Some((point, normal)) => clipped.pdf_from(reference, point, normal),
            None => 0.0,
        },
    );
    assert_accepted("directions", reference, &outcome);
}

/// χ² test of the unit normals of the points `clipped.sample_from(reference)`
/// draws (all of them, facing or not) against `pdf_from` turned into a
/// density per unit area, |cos θ| / d² times the solid-angle one, and per
/// steradian of normals, × R². Binned about the sampled cap's axis out to
/// its rim, so no jump crosses a bin.
fn chi_square_of_normals(clipped: &ClippedSphere, reference: DVec3, bins: SphericalCap, seed: u64) {
    let sphere = clipped.sphere;
    let outcome = chi_square_test(seed).directions(
        bins,
        |sampler: &mut Sampler| clipped.sample_from(reference, sampler.next_2d()).map(|sample| sample.normal),
        |normal| {
            let point = sphere.center + sphere.radius * normal;
            let to_reference = reference - point;
            let distance_squared = to_reference.length_squared();
            let cos_point = normal.dot(to_reference).abs() / distance_squared.sqrt();
            clipped.pdf_from(reference, point, normal) * cos_point / distance_squared * sphere.radius * sphere.radius
        },
    );
    assert_accepted("normals", reference, &outcome);
}

/// Directions within `degrees` of the way from `reference` to `target`.
fn cone(reference: DVec3, target: DVec3, degrees: f64) -> SphericalCap {
    SphericalCap {
        axis: (target - reference).normalize(),
        cos_theta_min: degrees.to_radians().cos(),
    }
}

/// Normals of the cap `reference` samples by area, out to its rim.
fn sampled_cap(clipped: &ClippedSphere, reference: DVec3) -> SphericalCap {
    let Some((cap, _)) = clipped.cap_to_sample(reference) else {
        panic!("{reference} samples the cone, not a cap");
    };
    SphericalCap {
        axis: cap.axis(),
        cos_theta_min: 1.0 - cap.versine,
    }
}

/// Normals of the part of the sphere in front of `reference`'s horizon
/// (what cone sampling covers): within acos(R / d) of the way to it.
fn horizon_cap(sphere: &Sphere, reference: DVec3) -> SphericalCap {
    let offset = reference - sphere.center;
    SphericalCap {
        axis: offset.normalize(),
        cos_theta_min: sphere.radius / offset.length(),
    }
}

#[test]
fn smallpt_light_under_its_ceiling_follows_its_density() {
    let (light, walls) = smallpt();
    let ceiling = walls[5];
    let Some(clipped) = ClippedSphere::new(light, [ceiling]) else {
        panic!("the ceiling crosses the light");
    };
    // From the floor, off-centre: the cap (radius 18) spans about 15°.
    let floor = DVec3::new(60.0, 0.0, 60.0);
    chi_square_of_directions(&clipped, floor, cone(floor, DVec3::new(50.0, 81.6, 81.6), 20.0), 1);
    // From the left wall just under the ceiling the cap is seen edge on,
    // part of it from behind.
    let wall = DVec3::new(1.0, 80.0, 100.0);
    chi_square_of_normals(&clipped, wall, sampled_cap(&clipped, wall), 2);
    // 0.13 under the cap's lowest point the horizon cap is smaller than
    // the clip's (and inside it), so the cone is sampled.
    let under = DVec3::new(50.0, 81.2, 81.6);
    assert!(clipped.cap_to_sample(under).is_none());
    chi_square_of_normals(&clipped, under, horizon_cap(&light, under), 3);
}

/// All six walls: the ceiling's cap is the smallest, and the four side
/// walls' caps (each about half the sphere) contain it.
#[test]
fn smallpt_light_in_its_room_samples_the_ceiling_cap() {
    let (light, walls) = smallpt();
    let Some(clipped) = ClippedSphere::new(light, walls) else {
        panic!("the walls cross the light");
    };
    assert_eq!(clipped.clip_count(), 5, "every wall but the floor");
    let floor = DVec3::new(30.0, 0.0, 120.0);
    let chosen = clipped.cap_to_sample(floor).map(|(_, area)| area);
    assert!(chosen.is_some_and(|area| (area - 1011.8).abs() < 0.1), "{chosen:?}");
    chi_square_of_directions(&clipped, floor, cone(floor, DVec3::new(50.0, 81.6, 81.6), 25.0), 4);
}

/// A unit emitter cut by a unit sphere 1.2 away: a large cap (a fifth of the
/// sphere), sampled by area from a point inside the clip and far enough from
/// the emitter that its horizon cap is larger.
#[test]
fn large_caps_follow_their_density() {
    let emitter = sphere([0.0, 0.0, 0.0], 1.0);
    let Some(clipped) = ClippedSphere::new(emitter, [sphere([1.2, 0.0, 0.0], 1.0)]) else {
        panic!("the spheres cross");
    };
    let inside_clip = DVec3::new(2.0, 0.3, 0.1);
    chi_square_of_normals(&clipped, inside_clip, sampled_cap(&clipped, inside_clip), 5);
}

/// Two clips whose caps overlap in a lens. Close to the emitter the cone is
/// sampled and points outside either cap dropped; from inside a larger
/// emitter (emitting inwards: two-sided) the first cap is sampled by area
/// and points outside the second dropped.
#[test]
fn overlapping_clips_and_inner_points_follow_their_density() {
    let emitter = sphere([0.0, 0.0, 0.0], 1.0);
    let clips = [sphere([1.5, 0.0, 0.0], 1.3), sphere([0.0, 1.5, 0.0], 1.3)];
    let Some(clipped) = ClippedSphere::new(emitter, clips) else {
        panic!("the spheres cross");
    };
    let near = DVec3::new(0.8, 0.8, 0.0);
    assert!(clipped.cap_to_sample(near).is_none());
    chi_square_of_directions(&clipped, near, SphericalCap::SPHERE, 6);
    // Inside the larger emitter each clip's cap spans 40°: 45° apart, they overlap.
    let closer = [sphere([1.5, 0.0, 0.0], 1.3), sphere([1.0607, 1.0607, 0.0], 1.3)];
    let Some(two_sided) = ClippedSphere::new(sphere([0.0, 0.0, 0.0], 2.0), closer) else {
        panic!("the spheres cross");
    };
    let inner = DVec3::new(0.9, 0.45, 0.0);
    assert!(two_sided.cap_to_sample(inner).is_some());
    chi_square_of_directions(&two_sided, inner, SphericalCap::SPHERE, 7);
    // Exactly the points `pdf_from` gives no density are dropped.
    for (clipped, reference) in [(&clipped, near), (&two_sided, inner)] {
        let (mut kept, mut dropped) = (0, 0);
        for index in 0..4000 {
            let u = Sampler::new(SamplerKind::Random, 0, index, 8).next_2d();
            let Some(drawn) = clipped.sample_before_clipping(reference, u) else {
                continue;
            };
            let pdf = clipped.pdf_from(reference, drawn.point, drawn.normal);
            match clipped.sample_from(reference, u) {
                Some(sample) => {
                    assert!(pdf > 0.0 && sample.point == drawn.point);
                    kept += 1;
                }
                None => {
                    assert_eq!(pdf, 0.0);
                    dropped += 1;
                }
            }
        }
        assert!(
            kept > 100 && dropped > 100,
            "the test needs both: {kept} kept, {dropped} dropped"
        );
    }
}

/// ∫ pdf dω over the directions from a floor point is 1 (every sample of the
/// cap faces the floor and none is dropped), by Monte Carlo over a cone
/// around the hole: mean of pdf / (uniform cone pdf), within 5 standard
/// errors (a correct density fails with probability 6·10⁻⁷).
#[test]
fn density_from_the_floor_integrates_to_one() {
    let (light, walls) = smallpt();
    let Some(clipped) = ClippedSphere::new(light, walls) else {
        panic!("the walls cross the light");
    };
    let floor = DVec3::new(40.0, 0.0, 90.0);
    let bins = cone(floor, DVec3::new(50.0, 81.6, 81.6), 20.0);
    let frame = crate::math::Frame::from_normal(bins.axis);
    let cone_pdf = crate::math::warp::uniform_cone_pdf(bins.cos_theta_min);
    let n = 200_000;
    let (mut sum, mut sum_squares) = (0.0, 0.0);
    for index in 0..n {
        let mut sampler = Sampler::new(SamplerKind::Random, 0, index, 11);
        let wi = frame.to_world(crate::math::warp::square_to_uniform_cone(
            sampler.next_2d(),
            bins.cos_theta_min,
        ));
        let value = first_hit(&light, floor, wi).map_or(0.0, |(point, normal)| clipped.pdf_from(floor, point, normal)) / cone_pdf;
        sum += value;
        sum_squares += value * value;
    }
    let mean = sum / n as f64;
    let standard_error = ((sum_squares / n as f64 - mean * mean) / n as f64).sqrt();
    assert!((mean - 1.0).abs() < 5.0 * standard_error, "∫ pdf = {mean} ± {standard_error}");
    // Every sample is kept: none falls outside a wall's cap.
    for index in 0..1000 {
        let mut sampler = Sampler::new(SamplerKind::Random, 0, index, 12);
        assert!(clipped.sample_from(floor, sampler.next_2d()).is_some());
    }
}

/// The sweep finds exactly the crossing pairs that testing every pair finds,
/// on spheres of mixed sizes scattered so that many overlap, touch or nest.
#[test]
fn sweep_finds_every_crossing_pair() {
    let mut sampler = Sampler::new(SamplerKind::Random, 0, 0, 5);
    let mut random_sphere = |scale: f64| {
        let u = sampler.next_2d();
        let v = sampler.next_2d();
        sphere([10.0 * u.x, 10.0 * u.y, 2.0 * v.x], scale * (0.1 + v.y))
    };
    let emitters: Vec<Sphere> = (0..40).map(|_| random_sphere(1.0)).collect();
    let mut opaque: Vec<Sphere> = (0..60).map(|i| random_sphere(if i % 10 == 0 { 8.0 } else { 1.5 })).collect();
    // The emitters themselves are among the opaque spheres, as in a scene.
    opaque.extend_from_slice(&emitters[..10]);
    let swept = clip_emitters(&emitters, &opaque);
    for (emitter, clipped) in emitters.iter().zip(&swept) {
        let brute: Vec<usize> = (0..opaque.len())
            .filter(|&j| SphereCap::split_by(emitter.center, emitter.radius, opaque[j].center, opaque[j].radius).is_some())
            .collect();
        let found: Vec<DVec3> = clipped
            .as_ref()
            .map_or(Vec::new(), |c| c.clips.iter().map(|clip| clip.center).collect());
        let expected: Vec<DVec3> = brute.iter().map(|&j| opaque[j].center).collect();
        assert_eq!(found, expected);
    }
    assert!(swept.iter().filter(|c| c.is_some()).count() > 10, "the test needs crossings");
}

/// A ball inside the room sees only the sliver of smallpt's light below the
/// ceiling (its smallest cap, which holds every light point a segment from
/// the ball can reach); a ball that pokes through a wall could see either
/// side of it, so no cap is sure to hold what it sees.
#[test]
fn a_ball_in_the_room_sees_the_light_below_the_ceiling_only() {
    let (light, walls) = smallpt();
    let clipped = ClippedSphere::new(light, walls).expect("the walls cut the light");
    let (cap, area) = clipped
        .cap_seen_by_ball(DVec3::new(73.0, 16.5, 78.0), 16.5)
        .expect("the glass ball is inside every wall");
    // The sliver about 0.27 deep: 2π R h (the ceiling's own curvature,
    // radius 10⁵, changes h by under 1% over the sliver's 18-unit radius).
    let depth: f64 = 81.6 - (681.33 - 600.0);
    let sliver = 2.0 * std::f64::consts::PI * 600.0 * depth;
    assert!((area / sliver - 1.0).abs() < 0.02, "{area} vs {sliver}");
    assert!(cap.contains(-DVec3::Y) && !cap.contains(DVec3::Y));
    // A ball through the left wall (x = 1).
    assert!(clipped.cap_seen_by_ball(DVec3::new(0.5, 16.5, 78.0), 16.5).is_none());
}
