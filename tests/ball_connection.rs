//! Next-event estimation through glass balls (src/integrator/path/ball_connection.rs)
//! against BSDF sampling, which finds the same light only when a sampled
//! direction happens to pass through the ball to the light.

mod common;
use common::{Job, assert_estimators_agree, scene, shipped_scene};
use glam::DVec3;
use prism::color::luminance;
use prism::integrator::path::PathTracer;
use prism::math::Ray;
use prism::sampler::{Sampler, SamplerKind};
use prism::scene::LoadedScene;

/// A glass ball on a white floor under a small square light, seen from
/// above and in front, so most pixels look through the ball at the floor
/// and the caustic the ball focuses on it: paths camera → ball → floor →
/// ball → light, which only the connection through the ball samples by
/// light, and a floor seen directly, whose caustic light paths bring in.
const BALL_ON_A_FLOOR: &str = r#"
[camera]
position = [0, 3.2, 2.4]
look_at = [0, 0.8, 0]
fov_y_degrees = 36

[materials.floor]
type = "diffuse"
albedo = [0.8, 0.7, 0.6]

[materials.glass]
type = "glass"
ior = 1.5

[materials.light]
type = "emissive"
radiance = [20, 20, 20]

[[objects]]
type = "quad"
corner = [-10, 0, -10]
edge_u = [0, 0, 20]
edge_v = [20, 0, 0]
material = "floor"

[[objects]]
type = "sphere"
center = [0, 1, 0]
radius = 1
material = "glass"

[[objects]]
type = "quad"
corner = [-0.6, 4, -0.6]
edge_u = [1.2, 0, 0]
edge_v = [0, 0, 1.2]
material = "light"
"#;

/// The two estimators' image means agree within three standard errors:
/// counting a path through the ball twice (connection and BSDF sample), or
/// not at all, would show as a difference of a sizeable part of the mean.
#[test]
fn connections_through_a_glass_ball_agree_with_bsdf_sampling() {
    let loaded = scene(BALL_ON_A_FLOOR);
    assert_eq!(loaded.scene.specular_balls().len(), 1);
    let job = Job {
        width: 24,
        height: 24,
        spp: 32,
        max_depth: 24,
        ..Job::default()
    };
    assert_estimators_agree(&loaded, job, 0.05, 0.03);
}

/// A mirror ball on a white floor, lit from the side by a small upright
/// light: the floor between the ball and the light gets, besides the
/// light's own, the light the ball reflects back onto it.
const MIRROR_BALL_ON_A_FLOOR: &str = r#"
[camera]
position = [0, 3, 6]
look_at = [0, 1, 0]

[materials.floor]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]

[materials.mirror]
type = "mirror"
tint = [0.9, 0.9, 0.9]

[materials.light]
type = "emissive"
radiance = [20, 20, 20]

[[objects]]
type = "quad"
corner = [-10, 0, -10]
edge_u = [0, 0, 20]
edge_v = [20, 0, 0]
material = "floor"

[[objects]]
type = "sphere"
center = [0, 1, 0]
radius = 1
material = "mirror"

[[objects]]
type = "quad"
corner = [3, 0.5, -0.5]
edge_u = [0, 0, 1]
edge_v = [0, 1, 0]
material = "light"
"#;

/// Mean and standard error of the luminance the path tracer finds along
/// `n` straight-down rays from the points `origin(i)`, with light sampling
/// (the connections by way of the balls included; light paths' caustics
/// off, so the connections are made at the first surface) or without.
fn luminance_down(loaded: &LoadedScene, light_sampling: bool, origin: impl Fn(u64) -> DVec3) -> (f64, f64) {
    let tracer = PathTracer {
        max_depth: 24,
        light_sampling,
        caustics_by_light_paths: false,
        lens_connections: None,
    };
    let n = 200_000;
    let (mut sum, mut sum_squares) = (0.0, 0.0);
    for i in 0..n {
        let mut sampler = Sampler::new(SamplerKind::Random, i, 0, 11);
        let value = luminance(tracer.radiance(&loaded.scene, Ray::new(origin(i), DVec3::NEG_Y), &mut sampler));
        sum += value;
        sum_squares += value * value;
    }
    let mean = sum / n as f64;
    (mean, ((sum_squares / n as f64 - mean * mean) / (n as f64 - 1.0)).sqrt())
}

/// The two estimates agree within three standard errors, are sharp to 2%
/// (a path counted twice or not at all would differ by many errors: checked
/// by breaking the partition), and the connection's error is at most
/// `error_ratio` times BSDF sampling's.
fn assert_connection_agrees(loaded: &LoadedScene, error_ratio: f64, origin: impl Fn(u64) -> DVec3 + Copy) {
    let (connected, connected_error) = luminance_down(loaded, true, origin);
    let (sampled, sampled_error) = luminance_down(loaded, false, origin);
    eprintln!("connection {connected} ± {connected_error}, BSDF {sampled} ± {sampled_error}");
    let combined = connected_error.hypot(sampled_error);
    assert!(
        (connected - sampled).abs() < 3.0 * combined,
        "{connected} ± {connected_error} vs {sampled} ± {sampled_error}"
    );
    assert!(combined < 0.02 * sampled, "{sampled} ± {combined}");
    assert!(
        connected_error < error_ratio * sampled_error,
        "{connected_error} vs {sampled_error}"
    );
}

/// Rays from just above the glass ball, aimed down at it, see the floor
/// under the ball through it: the ball's shadow, lit by the caustic it
/// focuses there (with the partition broken, the connection's mean came
/// out 3.64 against BSDF sampling's 1.87 ± 0.01).
#[test]
fn the_caustic_seen_through_a_glass_ball_agrees_with_bsdf_sampling() {
    assert_connection_agrees(&scene(BALL_ON_A_FLOOR), 0.5, |i| {
        let (r, phi) = (0.8 * ((i as f64 + 0.5) / 200_000.0).sqrt(), i as f64 * 2.399_963);
        DVec3::new(r * phi.cos(), 2.5, r * phi.sin())
    });
}

/// Rays straight down onto the floor between a mirror ball and the light,
/// lit by the light and by its reflection in the ball.
#[test]
fn the_light_a_mirror_ball_reflects_agrees_with_bsdf_sampling() {
    assert_connection_agrees(&scene(MIRROR_BALL_ON_A_FLOOR), 0.5, |i| {
        let (a, b) = ((i as f64 * 0.618_034).fract(), (i as f64 * 0.414_214).fract());
        DVec3::new(1.0 + 1.8 * a, 3.0, 1.6 * b - 0.8)
    });
}

/// smallpt's floor under its glass ball, seen through the ball from above:
/// lit by the sliver of the radius-600 light that pokes through the
/// ceiling, focused by the ball. The connection draws its light points on
/// that sliver alone, a cap of 1/4400 of the sphere's area: the error came
/// out 0.66 times BSDF sampling's (the rest of it is the floor's other
/// light); drawn over the whole sphere, 27 times.
#[test]
fn smallpts_caustic_through_its_glass_ball_agrees_with_bsdf_sampling() {
    let loaded = shipped_scene("smallpt.toml");
    assert_eq!(loaded.scene.specular_balls().len(), 2);
    assert_connection_agrees(&loaded, 0.8, |i| {
        let (r, phi) = (12.0 * ((i as f64 + 0.5) / 200_000.0).sqrt(), i as f64 * 2.399_963);
        DVec3::new(73.0 + r * phi.cos(), 34.0, 78.0 + r * phi.sin())
    });
}

/// Only glass denser than the air around it (a bubble can reflect light
/// totally on the way in) and untextured mirrors are connected through.
#[test]
fn bubbles_and_textured_mirrors_are_not_connected_through() {
    let with = |material: &str| {
        scene(&format!(
            r#"
            [camera]
            position = [0, 0, 5]
            look_at = [0, 0, 0]
            [materials.ball]
            {material}
            [materials.light]
            type = "emissive"
            radiance = [1, 1, 1]
            [[objects]]
            type = "sphere"
            center = [0, 0, 0]
            radius = 1
            material = "ball"
            [[objects]]
            type = "sphere"
            center = [0, 3, 0]
            radius = 0.5
            material = "light"
            "#
        ))
        .scene
        .specular_balls()
        .len()
    };
    assert_eq!(with("type = \"glass\"\nior = 1.33"), 1);
    assert_eq!(with("type = \"glass\"\nior = 0.75"), 0);
    assert_eq!(with("type = \"mirror\""), 1);
    assert_eq!(
        with("type = \"mirror\"\ntint = { checker = [[1, 1, 1], [0, 0, 0]], scale = 4 }"),
        0
    );
}

/// A ball resting on a floor is hollow (nothing can block a path across
/// it, so the connection tests no shadow ray along the chord); one with a
/// pebble inside it is not.
#[test]
fn only_balls_with_nothing_inside_skip_the_chords_shadow_ray() {
    let hollow = |pebble: &str| {
        let loaded = scene(&format!(
            r#"
            [camera]
            position = [0, 1, 5]
            look_at = [0, 1, 0]
            [materials.glass]
            type = "glass"
            [materials.white]
            type = "diffuse"
            albedo = [0.5, 0.5, 0.5]
            [materials.light]
            type = "emissive"
            radiance = [1, 1, 1]
            [[objects]]
            type = "quad"
            corner = [-5, 0, -5]
            edge_u = [0, 0, 10]
            edge_v = [10, 0, 0]
            material = "white"
            [[objects]]
            type = "sphere"
            center = [0, 1, 0]
            radius = 1
            material = "glass"
            [[objects]]
            type = "sphere"
            center = [0, 4, 0]
            radius = 0.5
            material = "light"
            {pebble}
            "#
        ));
        let balls = loaded.scene.specular_balls();
        assert_eq!(balls.len(), 1);
        balls[0].hollow
    };
    assert!(hollow(""));
    assert!(!hollow(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0.3, 1.2, 0]\nradius = 0.1\nmaterial = \"white\""
    ));
}

/// The same caustic with an opaque pebble in the ball's centre, which
/// shades part of it: the connection must test the chord across the ball
/// (without that test it came out 1.067 against BSDF sampling's 0.436).
#[test]
fn a_pebble_inside_the_glass_ball_shades_its_caustic_alike() {
    let with_pebble =
        format!("{BALL_ON_A_FLOOR}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 1, 0]\nradius = 0.4\nmaterial = \"floor\"\n");
    let loaded = scene(&with_pebble);
    assert!(!loaded.scene.specular_balls()[0].hollow);
    assert_connection_agrees(&loaded, 0.9, |i| {
        let (r, phi) = (0.8 * ((i as f64 + 0.5) / 200_000.0).sqrt(), i as f64 * 2.399_963);
        DVec3::new(r * phi.cos(), 2.5, r * phi.sin())
    });
}
