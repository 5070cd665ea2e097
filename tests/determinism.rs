//! The same scene, seed and sample count give the same image whatever the
//! thread count: every sample is a pure function of (pixel, index, seed).

mod common;
use common::{Job, render, shipped_scene};
use prism::sampler::SamplerKind;

#[test]
fn one_and_two_threads_give_identical_images() {
    let loaded = shipped_scene("cornell.toml");
    for sampler in [SamplerKind::Sobol, SamplerKind::Random] {
        let job = Job {
            width: 40,
            height: 30,
            spp: 4,
            sampler,
            seed: 42,
            ..Job::default()
        };
        let one = render(&loaded, &Job { threads: Some(1), ..job });
        let two = render(&loaded, &Job { threads: Some(2), ..job });
        assert_eq!(one, two, "{sampler}: images differ between 1 and 2 threads");
        let other_seed = render(
            &loaded,
            &Job {
                threads: Some(2),
                seed: 43,
                ..job
            },
        );
        assert_ne!(one, other_seed, "{sampler}: the seed has no effect");
    }
}

/// Photon mapping too: photons land on visible points from both threads in
/// any order, and the image must not care.
#[test]
fn sppm_is_identical_on_one_and_two_threads() {
    let mut loaded = shipped_scene("caustic.toml");
    loaded.settings.sppm.photons_per_iteration = 20_000;
    let job = Job {
        width: 40,
        height: 30,
        spp: 3,
        integrator: prism::render::IntegratorKind::Sppm,
        ..Job::default()
    };
    let one = render(&loaded, &Job { threads: Some(1), ..job });
    let two = render(&loaded, &Job { threads: Some(2), ..job });
    assert_eq!(one, two, "SPPM images differ between 1 and 2 threads");
}
