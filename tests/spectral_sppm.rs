//! Spectral SPPM: photons carry their own hero wavelengths, camera paths
//! theirs, and the gathered flux enters each pixel as film RGB. Checked
//! against RGB SPPM where the two must agree (grey surfaces under a white
//! light), for neutrality, and for determinism across thread counts.

mod common;
use common::{Job, render, shipped_scene, wall};
use prism::render::IntegratorKind;
use prism::spectrum::sensor::{D65_CHROMATICITY, chromaticity};

/// With grey surfaces and a white light every spectrum is flat, so a
/// spectral photon's contribution is the RGB photon's (same seed, same
/// draws: the wavelengths come from a side stream) times the film RGB of a
/// flat spectrum at its four wavelengths, whose mean is (1, 1, 1). The
/// paired images may differ only by that colour noise. Per photon it is
/// largest in blue (z̄ spans about a quarter of the range, so one lane in
/// four lands in it): σ ≈ 100%. About a sixth of the photons land in view,
/// ≈ 10⁵ over 8 iterations of 80 000, leaving σ ≈ 0.3% on the image mean; the
/// bound is 1% (over 3σ), and the mean colour must also be neutral within
/// the 0.002 in xy.
#[test]
fn spectral_sppm_matches_rgb_sppm_on_grey_surfaces_and_stays_neutral() {
    // A grey wall facing a white square light, nothing else.
    let mut loaded = wall("[0.8, 0.8, 0.8]", "radiance = [5, 5, 5]");
    loaded.settings.sppm.photons_per_iteration = 80_000;
    let job = Job {
        width: 24,
        height: 24,
        spp: 8,
        integrator: IntegratorKind::Sppm,
        seed: 3,
        ..Job::default()
    };
    let rgb = render(&loaded, &job).channel_means();
    let spectral = render(&loaded, &Job { spectral: true, ..job }).channel_means();
    eprintln!("RGB SPPM {rgb:?}, spectral SPPM {spectral:?}");
    assert!(rgb[1] > 0.05, "the wall is lit: {rgb:?}");
    for c in 0..3 {
        let ratio = spectral[c] / rgb[c];
        assert!((ratio - 1.0).abs() < 0.01, "channel {c}: spectral / RGB = {ratio}");
    }
    let [x, y] = chromaticity(glam::DVec3::from(spectral));
    let distance = ((x - D65_CHROMATICITY[0]).powi(2) + (y - D65_CHROMATICITY[1]).powi(2)).sqrt();
    assert!(distance < 0.002, "chromaticity ({x}, {y}) is {distance} from the white point");
}

/// Every photon and camera path draws its wavelengths from its own seeded
/// stream and the tallies add in fixed point, so a spectral SPPM render of
/// the dispersive scene (spectral because of its glass) is the same on one
/// and two threads, and differs from the scene with plain glass.
#[test]
fn spectral_sppm_images_are_identical_on_one_and_two_threads() {
    let mut loaded = shipped_scene("dispersion.toml");
    assert!(loaded.scene.has_dispersion());
    loaded.settings.sppm.photons_per_iteration = 4000;
    let job = Job {
        width: 20,
        height: 16,
        spp: 2,
        integrator: IntegratorKind::Sppm,
        seed: 5,
        max_depth: 8,
        ..Job::default()
    };
    let one = render(&loaded, &Job { threads: Some(1), ..job });
    let two = render(&loaded, &Job { threads: Some(2), ..job });
    assert!(one == two, "spectral SPPM images differ between 1 and 2 threads");
    assert!(one.channel_means().iter().all(|&m| m > 0.0), "the scene is lit");
}
