//! Spectral transport (hero-wavelength sampling) checked through the whole
//! renderer: a furnace whose answer is 1, a white wall that must stay
//! neutral, agreement with the RGB renderer where the two must agree, the
//! two path-tracing estimators agreeing, and determinism across threads.

mod common;
use common::{Job, assert_estimators_agree, paired, render, scene, shipped_scene, wall};
use prism::render::IntegratorKind;
use prism::spectrum::sensor::{D65_CHROMATICITY, chromaticity};

/// The same furnace as tests/physics.rs: a diffuse sphere of albedo 1 inside
/// a two-sided emitter of radiance 1 reflects exactly 1 at every pixel.
const WHITE_FURNACE: &str = r#"
[camera]
position = [0, 0, 8]
look_at = [0, 0, 0]
fov_y_degrees = 50

[render]
spectral = true

[materials.sky]
type = "emissive"
radiance = [1, 1, 1]
two_sided = true
[materials.white]
type = "diffuse"
albedo = [1, 1, 1]

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 20
material = "sky"
[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 3
material = "white"
"#;

/// Spectral white furnace: every path carries the constant spectrum 1, and
/// the film's estimator (1/N) Σ L(λᵢ) x̄ᵢ/p(λᵢ) averages to the white
/// (1, 1, 1). The tolerance is the issue's 0.5% on the image mean; the
/// wavelength noise of 32×32×64 samples (each a 4-wavelength estimate of a
/// flat spectrum, Sobol'-stratified over the hero) is far below it.
#[test]
fn spectral_white_furnace_is_one() {
    let loaded = scene(WHITE_FURNACE);
    assert!(loaded.settings.spectral, "[render] spectral = true is read");
    for integrator in [IntegratorKind::PathTracing, IntegratorKind::BsdfOnly] {
        let frame = render(
            &loaded,
            &Job {
                spp: 64,
                integrator,
                ..Job::default()
            },
        );
        let means = frame.channel_means();
        eprintln!("{integrator}: {means:?}");
        for (c, mean) in means.into_iter().enumerate() {
            assert!((mean - 1.0).abs() < 0.005, "{integrator}: channel {c} mean {mean}");
        }
    }
}

/// Under an RGB-white light a white wall must come out neutral: the image's
/// mean colour lies within 0.002 of the film's white point (D65, RGB
/// (1, 1, 1)) in CIE xy, the issue's tolerance. Colour noise from the
/// wavelength sampling is what could move it; at 24×24×32 samples its
/// effect on the mean chromaticity is about 10⁻⁴.
#[test]
fn a_white_wall_under_a_white_light_is_neutral() {
    let loaded = wall("[0.8, 0.8, 0.8]", "radiance = [5, 5, 5]");
    let frame = render(
        &loaded,
        &Job {
            width: 24,
            height: 24,
            spp: 32,
            spectral: true,
            ..Job::default()
        },
    );
    let mean = frame.channel_means();
    let [x, y] = chromaticity(glam::DVec3::from(mean));
    eprintln!(
        "mean {mean:?}: xy ({x:.5}, {y:.5}), white ({}, {})",
        D65_CHROMATICITY[0], D65_CHROMATICITY[1]
    );
    assert!(mean[1] > 0.05, "the wall is lit: {mean:?}");
    let distance = ((x - D65_CHROMATICITY[0]).powi(2) + (y - D65_CHROMATICITY[1]).powi(2)).sqrt();
    assert!(distance < 0.002, "chromaticity ({x}, {y}) is {distance} from the white point");
}

/// Per-channel relative difference of spectral from RGB image means, with
/// its standard error, over `runs` seeds. Both modes use the same seeds and, as
/// spectral paths draw their wavelengths from a side stream, the same path
/// samples, so the paired difference is far less noisy than either image.
fn spectral_minus_rgb(loaded: &prism::scene::LoadedScene, runs: u64) -> [(f64, f64); 3] {
    let job = Job {
        width: 16,
        height: 16,
        spp: 256,
        max_depth: 16,
        // Light-traced caustics run in RGB only: without them both draw
        // the same camera paths, which is what makes the pairs tell.
        caustic_light_paths: Some(false),
        ..Job::default()
    };
    paired(loaded, job, runs, |spectral, rgb| spectral / rgb - 1.0)
}

/// Spectral against RGB on the Cornell box (mirror and glass balls, no
/// dispersion): per-channel image means within 1.5%.
///
/// Where differences come from: the RGB → spectrum → RGB round trip is
/// exact here (the uplift's basis is corrected to this film, residual below
/// 10⁻¹⁴ on every shipped colour: `spectrum::uplift` tests), and a grey
/// times anything is exact too. What differs is that the RGB of a product
/// of two coloured spectra is not the product of their RGBs. The shipped
/// light is warm, (17, 12, 4): its spectrum times the red wall's is a red
/// deeper than sRGB can show, with less blue than the RGB product. With
/// Smits' basis spectra that cost the image 3.5% of its blue (−3.46% ±
/// 0.29%, same statistic); the fitted basis, which multiplies nearly as RGB
/// does (`spectrum::uplift` module doc), leaves about 1% in the blue under
/// the shipped light: −0.89% ± 0.34%, and −1.04% ± 0.36% once Russian
/// roulette stopped counting glass's 1/η² (which changes which paths the
/// two draw, not what either converges to). Hence 1.5%, still well short
/// of Smits' 3.5%.
/// Under a white light only the red and green walls seen in each other are
/// such products; with grey walls under the warm light every path meets one
/// coloured spectrum, the light's, and the two must agree within noise.
///
/// The statistic: 32 paired seeds (spectral and RGB draw the same paths);
/// the spread between seeds is mostly the directly seen light's colour
/// noise, so fewer seeds give an unreliable standard error.
#[test]
fn spectral_and_rgb_agree_on_the_cornell_box() {
    let shipped = shipped_scene("cornell.toml");
    let text =
        std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.toml")).unwrap_or_default();
    assert!(
        text.contains("radiance = [17, 12, 4]"),
        "the Cornell box's light changed: update this test"
    );
    let white_light = scene(&text.replace("radiance = [17, 12, 4]", "radiance = [11, 11, 11]"));
    // The control: the warm light, grey walls. Every path now meets one
    // coloured spectrum (the light's) times greys, which is exact.
    let grey_walls = scene(
        &text
            .replace("albedo = [0.65, 0.05, 0.05]", "albedo = [0.4, 0.4, 0.4]")
            .replace("albedo = [0.12, 0.45, 0.15]", "albedo = [0.3, 0.3, 0.3]"),
    );
    for (name, loaded) in [
        ("white light", &white_light),
        ("shipped light", &shipped),
        ("shipped light, grey walls", &grey_walls),
    ] {
        for (c, (mean, error)) in spectral_minus_rgb(loaded, 32).into_iter().enumerate() {
            eprintln!(
                "{name}, channel {c}: spectral/RGB − 1 = {:+.3}% ± {:.3}%",
                100.0 * mean,
                100.0 * error
            );
            assert!(
                mean.abs() < 0.015,
                "{name}, channel {c}: spectral differs from RGB by {:.3}%",
                100.0 * mean
            );
            // Teeth: the comparison resolves a 1.5% difference at three
            // standard errors (measured 0.14–0.34% per channel).
            assert!(
                3.0 * error < 0.015,
                "{name}, channel {c}: too noisy to test ({:.3}%)",
                100.0 * error
            );
        }
    }
}

/// In spectral mode, next-event estimation with MIS and BSDF-only sampling
/// estimate the same integral: per-channel means over 8 independent runs
/// each agree within three combined standard errors.
#[test]
fn spectral_light_sampling_and_bsdf_sampling_agree() {
    let loaded = shipped_scene("cornell.toml");
    let job = Job {
        width: 16,
        height: 16,
        spp: 32,
        max_depth: 32,
        spectral: true,
        ..Job::default()
    };
    // Teeth: every channel well above zero, errors under 10% of the mean.
    assert_estimators_agree(&loaded, job, 0.01, 0.1);
}

/// Spectral path tracing draws its wavelengths from the pixel sample's own
/// stream, so the image is the same on any thread count.
#[test]
fn spectral_images_are_identical_on_one_and_two_threads() {
    let loaded = shipped_scene("cornell.toml");
    let job = Job {
        width: 20,
        height: 16,
        spp: 4,
        seed: 7,
        spectral: true,
        ..Job::default()
    };
    let one = render(&loaded, &Job { threads: Some(1), ..job });
    let two = render(&loaded, &Job { threads: Some(2), ..job });
    assert!(one == two, "spectral images differ between 1 and 2 threads");
    let rgb = render(
        &loaded,
        &Job {
            threads: Some(2),
            spectral: false,
            ..job
        },
    );
    assert!(one != rgb, "the spectral flag has no effect");
}
