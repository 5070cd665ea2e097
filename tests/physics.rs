//! Physics checks run through the whole renderer: furnaces whose answer is
//! known exactly, and estimators that must agree in the mean.

mod common;
use common::{Job, assert_estimators_agree, mean_and_error, render, scene, shipped_scene};
use glam::DVec3;
use prism::integrator::path::PathTracer;
use prism::math::Ray;
use prism::render::IntegratorKind;
use prism::sampler::{Sampler, SamplerKind};

/// A lossless glass material and a ball of it at the origin, for [`furnace`].
const GLASS: &str = "[materials.glass]\ntype = \"glass\"\nior = 1.5";
const GLASS_BALL: &str = "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 3\nmaterial = \"glass\"";

/// A uniformly emitting enclosure (radiance 1, seen from inside, so two-sided)
/// around `inner` objects; the camera sits inside looking at the origin.
fn furnace(materials: &str, objects: &str) -> String {
    format!(
        r#"
[camera]
position = [0, 0, 8]
look_at = [0, 0, 0]
fov_y_degrees = 50

[materials.sky]
type = "emissive"
radiance = [1, 1, 1]
two_sided = true
{materials}

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 20
material = "sky"
{objects}
"#
    )
}

/// White furnace (Nori's test): a diffuse sphere of albedo 1 inside a uniform
/// emitter of radiance 1 reflects exactly radiance 1, so every pixel's
/// expected value is 1. Tolerance 0.5% on the image mean, as the issue asks;
/// at 32×32×64 samples the standard error of the NEE estimate is below 0.1%.
#[test]
fn white_furnace_is_one_with_light_sampling_and_without() {
    let loaded = scene(&furnace(
        "[materials.white]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]",
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 3\nmaterial = \"white\"",
    ));
    for integrator in [IntegratorKind::PathTracing, IntegratorKind::BsdfOnly] {
        let frame = render(
            &loaded,
            &Job {
                spp: 64,
                integrator,
                ..Job::default()
            },
        );
        for (c, mean) in frame.channel_means().into_iter().enumerate() {
            assert!((mean - 1.0).abs() < 0.005, "{integrator}: channel {c} mean {mean}");
        }
    }
}

/// A glass sphere without absorption in the same furnace: every path leaves
/// the glass eventually and sees radiance 1; the 1/η² radiance scaling on
/// entry is undone on exit. Tolerance: 1% on the image mean, over 3 standard
/// errors measured from 6 independent runs (truncation at depth 64 removes
/// well under 0.1% at these Fresnel weights).
#[test]
fn glass_neither_gains_nor_loses_energy() {
    let loaded = scene(&furnace(GLASS, GLASS_BALL));
    let (mean, error) = mean_and_error(
        &loaded,
        &Job {
            spp: 16,
            ..Job::default()
        },
        6,
    );
    for c in 0..3 {
        assert!(3.0 * error[c] < 0.01, "estimate too noisy to test: {error:?}");
        assert!((mean[c] - 1.0).abs() < 0.01, "channel {c}: mean {} ± {}", mean[c], error[c]);
    }
}

/// A lossless glass ball inside a uniform emitter of radiance 1: every
/// path that leaves the glass sees radiance 1, so its estimate is the
/// product of Russian roulette's 1/survival alone, at most 1/0.95 per
/// bounce. Roulette that read the 1/η² compression inside the glass as
/// lost energy would kill paths there and return the rest heavier, by η =
/// 1.5 per entry under the square-root rule (its mean stays 1:
/// `glass_neither_gains_nor_loses_energy`).
#[test]
fn roulette_inside_glass_does_not_inflate_the_weights() {
    let loaded = scene(&furnace(GLASS, GLASS_BALL));
    let tracer = PathTracer {
        max_depth: 8,
        light_sampling: true,
        caustics_by_light_paths: false,
        lens_connections: None,
    };
    let bound = (1.0 / 0.95_f64).powi(8) * (1.0 + 1e-9);
    let (mut sum, mut largest) = (0.0, 0.0_f64);
    let n = 20_000;
    for i in 0..n {
        let mut sampler = Sampler::new(SamplerKind::Random, i, 0, 7);
        // Rays spread over the ball, so many refract at steep angles.
        let target = DVec3::new(
            2.9 * (i as f64 * 0.618).fract() - 1.45,
            2.9 * (i as f64 * 0.377).fract() - 1.45,
            0.0,
        );
        let ray = Ray::new(DVec3::new(0.0, 0.0, 8.0), target - DVec3::new(0.0, 0.0, 8.0));
        let value = tracer.radiance(&loaded.scene, ray, &mut sampler).max_element();
        sum += value;
        largest = largest.max(value);
    }
    assert!(largest <= bound, "a sample of {largest} (bound {bound})");
    // Teeth: paths do pass through the glass and leave it (the mean is
    // near 1, less what depth 8 truncates).
    let mean = sum / n as f64;
    assert!((mean - 1.0).abs() < 0.05, "mean {mean}");
}

/// An integrating sphere: inside a closed diffuse sphere (radius R, albedo
/// ρ) a black sphere of radius r and radiance Le sits at the centre. By
/// symmetry the wall's radiance L is the same everywhere, and a wall point
/// sees the light over a cone of sin²α = (r/R)² = s of its projected
/// hemisphere and the wall over the rest, so L = ρ(Le·s + L·(1 − s)), that
/// is L = ρ·Le·s / (1 − ρ(1 − s)), the sum over k of the light that reaches
/// the camera after k reflections between wall points, each a fraction
/// (ρ(1 − s))^k of the first. With ρ = 1/2 the reflections from the fourth
/// wall point on, which Russian roulette decides, carry 12% of L: a
/// survival rule whose weights do not undo its probabilities moves the
/// mean (weights of 1/q^0.9 moved it by 1.9%, 22 standard errors).
#[test]
fn an_integrating_sphere_matches_its_radiance_balance() {
    let (albedo, wall_radius, light_radius, emitted) = (0.5, 10.0, 1.0, 100.0);
    let loaded = scene(&format!(
        r#"
[camera]
position = [0, 0, 4]
look_at = [0, 0, 10]
fov_y_degrees = 40

[materials.wall]
type = "diffuse"
albedo = [{albedo}, {albedo}, {albedo}]

[materials.light]
type = "emissive"
radiance = [{emitted}, {emitted}, {emitted}]

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = {wall_radius}
material = "wall"

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = {light_radius}
material = "light"
"#
    ));
    let s = (light_radius / wall_radius) * (light_radius / wall_radius);
    let expected = albedo * emitted * s / (1.0 - albedo * (1.0 - s));
    let (mean, error) = mean_and_error(
        &loaded,
        &Job {
            width: 16,
            height: 16,
            spp: 32,
            max_depth: 64,
            ..Job::default()
        },
        6,
    );
    for c in 0..3 {
        // Teeth: the estimate is sharp enough to see a 1% bias.
        assert!(4.0 * error[c] < 0.01 * expected, "estimate too noisy to test: {error:?}");
        assert!(
            (mean[c] - expected).abs() < 4.0 * error[c],
            "channel {c}: mean {} ± {}, expected {expected}",
            mean[c],
            error[c]
        );
    }
}

/// Next-event estimation with MIS and pure BSDF sampling estimate the same
/// integral: on the Cornell box their per-channel image means must agree
/// within three combined standard errors (each from 8 independent runs).
#[test]
fn light_sampling_and_bsdf_sampling_agree_on_cornell() {
    let loaded = shipped_scene("cornell.toml");
    let job = Job {
        width: 24,
        height: 24,
        spp: 32,
        max_depth: 32,
        ..Job::default()
    };
    // Teeth: every channel well above zero, errors under 10% of the mean.
    assert_estimators_agree(&loaded, job, 0.01, 0.1);
}

/// Light sampling must lower variance where it should: on the Cornell box
/// the NEE estimate's spread over runs is smaller than BSDF-only's.
#[test]
fn light_sampling_reduces_variance() {
    let loaded = shipped_scene("cornell.toml");
    let job = Job {
        width: 16,
        height: 16,
        spp: 8,
        max_depth: 16,
        ..Job::default()
    };
    let (_, nee_error) = mean_and_error(
        &loaded,
        &Job {
            integrator: IntegratorKind::PathTracing,
            ..job
        },
        6,
    );
    let (_, bsdf_error) = mean_and_error(
        &loaded,
        &Job {
            integrator: IntegratorKind::BsdfOnly,
            ..job
        },
        6,
    );
    assert!(nee_error[1] < bsdf_error[1], "NEE {nee_error:?} vs BSDF {bsdf_error:?}");
}

/// An emissive surface of revolution as the only light: light sampling uses
/// its area and area sampling, BSDF sampling only its intersection, so the two
/// estimators agree only if the area, the sampling density and the hits are
/// all right. Same three-standard-error criterion as the Cornell test.
#[test]
fn emissive_revolution_light_sampling_agrees_with_bsdf_sampling() {
    let loaded = scene(
        r#"
[camera]
position = [0, 4, 12]
look_at = [0, 1, 0]
fov_y_degrees = 45

[materials.floor]
type = "diffuse"
albedo = [0.7, 0.7, 0.7]

[materials.lamp]
type = "emissive"
radiance = [4, 3, 2]
two_sided = true

[[objects]]
type = "quad"
corner = [-10, 0, -10]
edge_u = [0, 0, 20]
edge_v = [20, 0, 0]
material = "floor"

[[objects]]
type = "revolution"
profile = [[0.0, 0.5], [3.0, 1.0], [0.2, 2.5], [1.0, 3.5]]
material = "lamp"
"#,
    );
    let job = Job {
        width: 24,
        height: 16,
        spp: 32,
        max_depth: 8,
        ..Job::default()
    };
    assert_estimators_agree(&loaded, job, 0.05, 0.05);
}

/// smallpt's light is a radius-600 sphere poking 0.27 through the ceiling
/// sphere; only the cap inside the room is sampled (`geometry::
/// clipped_sphere`). Against the unclipped light (the cone the whole sphere
/// subtends, 95% of it hidden by the ceiling) and BSDF sampling alone, the
/// image means must agree within four combined standard errors of 8 runs
/// each, for direct light (depth 1) and full paths; four rather than three
/// because six channel comparisons per depth are made. (The noise each
/// sampling leaves is measured in docs/performance.md: an image mean mixes it
/// with that of the light seen directly and through the balls.)
#[test]
fn clipped_smallpt_light_agrees_with_unclipped_and_bsdf_sampling() {
    use prism::light::{Light, Lights};
    let clipped = shipped_scene("smallpt.toml");
    let clips = clipped.scene.lights.lights.iter().filter_map(|l| l.clipped.as_ref());
    assert_eq!(
        clips.map(|c| c.clip_count()).collect::<Vec<_>>(),
        [5],
        "the ceiling and four walls cross the light"
    );
    let mut unclipped = shipped_scene("smallpt.toml");
    let lights: Vec<Light> = unclipped
        .scene
        .lights
        .lights
        .iter()
        .map(|light| Light {
            clipped: None,
            ..light.clone()
        })
        .collect();
    unclipped.scene.lights = Lights::new(lights, &unclipped.scene);

    for max_depth in [1, 6] {
        let job = Job {
            width: 24,
            height: 18,
            spp: 16,
            max_depth,
            sampler: prism::sampler::SamplerKind::Random,
            ..Job::default()
        };
        let estimate = |loaded, integrator| mean_and_error(loaded, &Job { integrator, ..job }, 8);
        let (cap, cap_error) = estimate(&clipped, IntegratorKind::PathTracing);
        let (cone, cone_error) = estimate(&unclipped, IntegratorKind::PathTracing);
        let (bsdf, bsdf_error) = estimate(&clipped, IntegratorKind::BsdfOnly);
        eprintln!(
            "depth {max_depth}: cap {cap:?} ± {cap_error:?}, cone {cone:?} ± {cone_error:?}, BSDF {bsdf:?} ± {bsdf_error:?}"
        );
        for c in 0..3 {
            for (name, other, other_error) in [("cone", cone, cone_error), ("BSDF", bsdf, bsdf_error)] {
                let combined = (cap_error[c].powi(2) + other_error[c].powi(2)).sqrt();
                assert!(
                    (cap[c] - other[c]).abs() < 4.0 * combined,
                    "depth {max_depth}, channel {c}: cap {} ± {}, {name} {} ± {}",
                    cap[c],
                    cap_error[c],
                    other[c],
                    other_error[c]
                );
            }
            assert!(
                cap_error[c] < 0.05 * cap[c],
                "depth {max_depth}: the comparison needs teeth: {cap:?} ± {cap_error:?}"
            );
        }
    }
}

/// Only a spherical light that an opaque sphere's surface crosses is
/// clipped: no other shipped scene pays for it.
#[test]
fn only_smallpt_has_a_clipped_light() {
    let folder = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let Ok(entries) = std::fs::read_dir(&folder) else {
        panic!("cannot list {}", folder.display());
    };
    let mut names: Vec<String> = entries
        .filter_map(|entry| entry.ok()?.file_name().into_string().ok())
        .filter(|name| name.ends_with(".toml"))
        .collect();
    names.sort();
    assert!(names.len() > 5 && names.contains(&"smallpt.toml".to_string()), "{names:?}");
    for name in names {
        let loaded = shipped_scene(&name);
        let clipped = loaded.scene.lights.lights.iter().any(|l| l.clipped.is_some());
        assert_eq!(clipped, name == "smallpt.toml", "{name}");
    }
}
