//! Stochastic progressive photon mapping against path tracing: on a
//! diffuse-only Cornell box both estimate the same integral, so SPPM must
//! converge to the path-traced image; and photons must not leak through a
//! wall thinner than the gather radius.

use prism::film::Frame;
use prism::integrator::sppm::SppmIntegrator;
use prism::integrator::{Integrator, path::PathIntegrator};
use prism::metrics::rmse;
use prism::render::{IntegratorKind, ProgressiveRender, RenderSettings, render_to_completion};
use prism::scene::{LoadedScene, load_scene_file, load_scene_str};
use std::ops::ControlFlow;
use std::path::Path;
use std::sync::OnceLock;
use std::sync::atomic::AtomicBool;

const PATH_SAMPLES: u32 = 1024;
const SPPM_ITERATIONS: u32 = 64;
const PHOTONS: u32 = 20_000;

/// The Cornell box with a white block instead of the mirror and glass balls:
/// everything diffuse, so the classic SPPM split (photons for all reflected
/// light) covers every path the path tracer samples.
fn cornell() -> &'static LoadedScene {
    static SCENE: OnceLock<LoadedScene> = OnceLock::new();
    SCENE.get_or_init(|| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/diffuse-cornell.toml");
        load_scene_file(&path).expect("tests/scenes/diffuse-cornell.toml loads")
    })
}

fn settings(integrator: IntegratorKind, passes: u32) -> RenderSettings {
    let mut settings = cornell().settings.clone();
    settings.integrator = integrator;
    settings.samples_per_pixel = Some(passes);
    settings.sppm.photons_per_iteration = PHOTONS;
    settings.seed = 7;
    settings
}

/// Path-traced reference, 1024 samples per pixel.
fn reference() -> &'static Frame {
    static REFERENCE: OnceLock<Frame> = OnceLock::new();
    REFERENCE.get_or_init(|| {
        let loaded = cornell();
        let settings = settings(IntegratorKind::PathTracing, PATH_SAMPLES);
        let mut integrator = PathIntegrator::new(&settings);
        let cancel = AtomicBool::new(false);
        for _ in 0..PATH_SAMPLES {
            assert!(integrator.render_pass(&loaded.scene, &loaded.camera, &cancel));
        }
        integrator.frame()
    })
}

/// SPPM snapshots after 1, 2, 4, … 64 iterations.
fn sppm_snapshots() -> &'static Vec<(u32, Frame)> {
    static SNAPSHOTS: OnceLock<Vec<(u32, Frame)>> = OnceLock::new();
    SNAPSHOTS.get_or_init(|| {
        let loaded = cornell();
        let settings = settings(IntegratorKind::Sppm, SPPM_ITERATIONS);
        let mut snapshots = Vec::new();
        let cancel = AtomicBool::new(false);
        ProgressiveRender::new(&settings).run(&loaded.scene, &loaded.camera, &cancel, |render| {
            let passes = render.progress().passes;
            if passes.is_power_of_two() {
                snapshots.push((passes, render.integrator().frame()));
            }
            ControlFlow::Continue(())
        });
        snapshots
    })
}

#[test]
fn sppm_matches_path_traced_channel_means() {
    let reference = reference().channel_means();
    let (iterations, frame) = sppm_snapshots().last().expect("at least one pass");
    assert_eq!(*iterations, SPPM_ITERATIONS);
    let sppm = frame.channel_means();
    // Tolerance 3% per channel. Noise is far below it: the image mean of
    // 1024 px × 1024 paths, or of 64 × 20 000 photons, has a relative
    // standard error under 0.5%. What remains is SPPM's bias at a finite
    // radius: gather discs that reach over a corner lose the part that lies
    // on the perpendicular wall (whose photons the normal test rejects), and
    // light is blurred across the shadow boundaries. After 64 iterations the
    // radius is still ~0.4 of its start (1.5 pixel footprints, which at 32×32
    // is ~4% of the box), which leaves the image means ~1.8% low (measured;
    // at 64×64 it is 0.7%, falling to 0.4% after 512 iterations, as a bias
    // that vanishes with the radius should). 3% is that bias plus margin.
    for c in 0..3 {
        let relative = sppm[c] / reference[c] - 1.0;
        println!(
            "channel {c}: sppm {:.5}, path tracing {:.5} ({:+.2}%)",
            sppm[c],
            reference[c],
            100.0 * relative
        );
        assert!(
            relative.abs() < 0.03,
            "channel {c}: sppm {:.4} vs path tracing {:.4} ({:+.2}%)",
            sppm[c],
            reference[c],
            100.0 * relative
        );
    }
}

#[test]
fn sppm_error_falls_with_iterations() {
    let reference = reference();
    let errors: Vec<(u32, f64)> = sppm_snapshots()
        .iter()
        .map(|(n, frame)| (*n, rmse(frame, reference).expect("same size")))
        .collect();
    for (n, error) in &errors {
        println!("sppm iterations {n:3}: RMSE vs path tracing ({PATH_SAMPLES} spp) {error:.5}");
    }
    // Progressive photon mapping's error falls as variance and bias both
    // shrink; over 64× the photons it must at least halve. (Noise alone would
    // fall 8×; the bias term falls much more slowly, as R shrinks.)
    let (first, last) = (errors[0].1, errors[errors.len() - 1].1);
    assert!(
        last < 0.5 * first,
        "RMSE {first} after 1 iteration, {last} after {SPPM_ITERATIONS}"
    );
    // And it keeps falling: each doubling of iterations lowers it.
    for pair in errors.windows(2) {
        assert!(
            pair[1].1 < pair[0].1,
            "RMSE rose from {} to {} iterations",
            pair[0].0,
            pair[1].0
        );
    }
}

/// A wall made of two parallel quads 1 mm apart (same winding), lit only
/// from behind: photons land on the far quad, well within the gather radius
/// of the visible points on the near one, but arrive from the other side and
/// must be rejected, so the near face stays black and its radii never shrink.
/// Seen from the light's side, the same wall is lit (the control).
#[test]
fn photons_do_not_leak_through_a_thin_wall() {
    let text = r#"
        [camera]
        position = [0, 0, -5]
        look_at = [0, 0, 0]
        fov_y_degrees = 20
        [render]
        width = 16
        height = 16
        [materials.wall]
        type = "diffuse"
        albedo = [0.8, 0.8, 0.8]
        [materials.light]
        type = "emissive"
        radiance = [5, 5, 5]
        [[objects]]
        type = "quad"
        corner = [-5, -5, 0]
        edge_u = [10, 0, 0]
        edge_v = [0, 10, 0]
        material = "wall"
        [[objects]]
        type = "quad"
        corner = [-5, -5, 0.001]
        edge_u = [10, 0, 0]
        edge_v = [0, 10, 0]
        material = "wall"
        [[objects]]
        type = "quad"   # faces -z, towards the wall; out of both views
        corner = [1.5, -1, 1]
        edge_u = [0, 2, 0]
        edge_v = [2, 0, 0]
        material = "light"
    "#;
    let loaded = load_scene_str(text, Path::new("<thin wall>"), Path::new(".")).expect("test scene parses");
    let mut settings = loaded.settings.clone();
    settings.integrator = IntegratorKind::Sppm;
    settings.sppm.photons_per_iteration = 50_000;
    settings.sppm.initial_radius = Some(0.1);
    let cancel = AtomicBool::new(false);
    let render = |camera: &prism::camera::Camera| {
        let mut sppm = SppmIntegrator::new(&settings);
        for _ in 0..4 {
            assert!(sppm.render_pass(&loaded.scene, camera, &cancel));
        }
        sppm
    };

    let dark_side = render(&loaded.camera);
    assert!(
        dark_side.frame().pixels.iter().all(|p| p == &[0.0; 3]),
        "light leaked through the wall"
    );
    assert!(
        dark_side.radii().iter().all(|&r| r == 0.1),
        "radii shrank from photons behind the wall"
    );

    let mut lit_camera = loaded.camera;
    lit_camera.position = glam::DVec3::new(0.0, 0.0, 5.0);
    lit_camera.update();
    let lit_side = render(&lit_camera);
    let mean = lit_side.frame().channel_means()[0];
    assert!(mean > 0.01, "control: the lit side should be lit, mean {mean}");
    assert!(
        lit_side.radii().iter().all(|&r| r < 0.1),
        "control: radii shrink where photons land"
    );
}

/// Throughput on the caustic scene: photons per second (photon pass only) and
/// iterations per second. A measurement, not a check; run it in release:
/// `cargo test --release --test sppm -- --ignored --nocapture`.
#[test]
#[ignore]
fn sppm_throughput_on_the_caustic_scene() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/caustic.toml");
    let loaded = prism::scene::load_scene_file(&path).expect("scenes/caustic.toml loads");
    let mut settings = loaded.settings.clone();
    settings.integrator = IntegratorKind::Sppm;
    let mut sppm = SppmIntegrator::new(&settings);
    let cancel = AtomicBool::new(false);
    for _ in 0..20 {
        assert!(sppm.render_pass(&loaded.scene, &loaded.camera, &cancel));
    }
    let (photons_per_second, iterations_per_second) = sppm.throughput();
    println!(
        "caustic.toml {}x{}, {} photons/iteration, {} threads: {:.3} Mphotons/s in the photon pass, {:.3} iterations/s; {}",
        settings.width,
        settings.height,
        settings.sppm.photons_per_iteration,
        rayon::current_num_threads(),
        photons_per_second / 1e6,
        iterations_per_second,
        sppm.status()
    );
}

/// A sky-lit convex object: a diffuse sphere of albedo ρ alone under a
/// constant background L sees the whole sky from every point, so it reflects
/// exactly ρ·L (irradiance π L, Lambertian BRDF ρ/π); the camera sees only
/// the sphere. SPPM must get this from photons emitted by the sky, which
/// once emitted none (the image was black). The sphere is also the case
/// where the gather disc has no curvature bias: the area of a sphere within
/// distance r of one of its points is exactly π r² (Archimedes).
#[test]
fn the_sky_lights_a_diffuse_sphere_through_photons() {
    let text = r#"
        background = [1.0, 0.5, 0.25]
        [camera]
        position = [0, 0, -3]
        look_at = [0, 0, 0]
        fov_y_degrees = 30
        [render]
        width = 16
        height = 16
        [materials.grey]
        type = "diffuse"
        albedo = [0.5, 0.5, 0.5]
        [[objects]]
        type = "sphere"
        center = [0, 0, 0]
        radius = 1
        material = "grey"
    "#;
    let loaded = load_scene_str(text, Path::new("<sky-lit sphere>"), Path::new(".")).expect("test scene parses");
    let mut settings = loaded.settings.clone();
    settings.integrator = IntegratorKind::Sppm;
    settings.sppm.photons_per_iteration = 20_000;
    settings.samples_per_pixel = Some(32);
    settings.seed = 3;
    let sppm = render_to_completion(&loaded.scene, &loaded.camera, &settings);
    let means = sppm.frame().channel_means();
    // The view (half-angle 15°, inside the sphere's 19.5°) holds a cap of
    // about 30% of the sphere, and a third of the 32 × 20 000 photons reach
    // the sphere. Over seeds 1–8 the image mean was off by +0.57% on
    // average with a standard deviation of 0.55% (measured), so 3% is over
    // 4σ; the old SPPM, whose sky emitted no photons, gives 0.
    for (c, expected) in [0.5, 0.25, 0.125].into_iter().enumerate() {
        let relative = means[c] / expected - 1.0;
        println!(
            "channel {c}: sppm {:.5}, exact {expected} ({:+.2}%)",
            means[c],
            100.0 * relative
        );
        assert!(relative.abs() < 0.03, "channel {c}: {:.4} vs exact {expected}", means[c]);
    }
}

/// The emitted term stays unbiased where a pixel traces one camera path for
/// it instead of several: a light whose image is a disc of half a pixel's
/// radius centred on a pixel corner covers no pixel centre, so the probes
/// that choose the pixels with extra paths find nothing, and every pixel
/// traces one. The image must still hold the disc's full light: its area
/// in pixels times the radiance (dividing by the usual path count instead
/// would give a quarter of it).
#[test]
fn a_light_between_the_probes_is_counted_in_full() {
    use prism::integrator::sppm::{RadiusSchedule, emission_paths::pixels_that_may_see_emission};
    // On the axis, a sphere of radius r at distance d is seen as a disc of
    // angular radius asin(r/d): tan of it over tan(fov/2) is its radius in
    // half image heights.
    let (distance, half_fov, size) = (10.0f64, 10.0f64.to_radians(), 16.0);
    let radius_pixels = 0.5;
    let tan_angular_radius = radius_pixels * half_fov.tan() / (size / 2.0);
    let radius = distance * tan_angular_radius.atan().sin();
    let text = format!(
        r#"
        [camera]
        position = [0, 0, -{distance}]
        look_at = [0, 0, 0]
        fov_y_degrees = {fov}
        [render]
        width = {size}
        height = {size}
        [materials.light]
        type = "emissive"
        radiance = [4, 4, 4]
        [[objects]]
        type = "sphere"
        center = [0, 0, 0]
        radius = {radius}
        material = "light"
    "#,
        fov = 2.0 * half_fov.to_degrees()
    );
    let loaded = load_scene_str(&text, Path::new("<sub-pixel light>"), Path::new(".")).expect("test scene parses");
    let settings = &loaded.settings;
    let flagged = pixels_that_may_see_emission(
        &loaded.scene,
        &loaded.camera,
        (settings.width, settings.height),
        settings.sampled_pixels(),
        settings.max_depth,
    );
    assert!(flagged.iter().all(|&f| !f), "the probes should miss the light");

    let expected_sum = std::f64::consts::PI * radius_pixels * radius_pixels * 4.0;
    for schedule in [RadiusSchedule::PerPixel, RadiusSchedule::Global] {
        let mut settings = settings.clone();
        settings.integrator = IntegratorKind::Sppm;
        settings.sppm.radius_schedule = schedule;
        settings.sppm.photons_per_iteration = 100;
        settings.samples_per_pixel = Some(256);
        settings.seed = 5;
        let sppm = render_to_completion(&loaded.scene, &loaded.camera, &settings);
        let sum: f64 = sppm.frame().pixels.iter().map(|p| f64::from(p[0])).sum();
        println!("{schedule:?}: image sum {sum:.4}, exact {expected_sum:.4}");
        // 256 stratified samples of each of the four pixels' coverage: the
        // sum was within 1% over seeds 1–5 (measured); a quarter of it fails.
        assert!(
            (sum / expected_sum - 1.0).abs() < 0.05,
            "{schedule:?}: {sum} vs {expected_sum}"
        );
    }
}
