//! The Owen-scrambled Sobol' sampler must measurably lower error at equal
//! samples per pixel against independent random numbers on smallpt.

mod common;
use common::{Job, render, shipped_scene};
use prism::metrics::rmse;
use prism::sampler::SamplerKind;

/// Reference: the average of a 1024-spp Sobol' and a 1024-spp random render
/// (so neither sampler is favoured). Then 8 independent 16-spp renders per
/// sampler; Sobol's mean RMSE must be lower than random's by more than the
/// spread of the two means (the margin makes the test meaningful, not lucky).
#[test]
fn sobol_beats_random_at_equal_samples_on_smallpt() {
    let loaded = shipped_scene("smallpt.toml");
    let base = Job {
        width: 32,
        height: 24,
        max_depth: 12,
        ..Job::default()
    };
    let reference_sobol = render(
        &loaded,
        &Job {
            spp: 1024,
            seed: 1000,
            sampler: SamplerKind::Sobol,
            ..base
        },
    );
    let reference_random = render(
        &loaded,
        &Job {
            spp: 1024,
            seed: 1001,
            sampler: SamplerKind::Random,
            ..base
        },
    );
    let mut reference = reference_sobol.clone();
    for (p, q) in reference.pixels.iter_mut().zip(&reference_random.pixels) {
        for c in 0..3 {
            p[c] = 0.5 * (p[c] + q[c]);
        }
    }
    let errors = |sampler| -> Vec<f64> {
        (1..=8)
            .map(|seed| {
                rmse(
                    &render(
                        &loaded,
                        &Job {
                            spp: 16,
                            seed,
                            sampler,
                            ..base
                        },
                    ),
                    &reference,
                )
                .expect("same size")
            })
            .collect()
    };
    let stats = |e: &[f64]| {
        let n = e.len() as f64;
        let mean = e.iter().sum::<f64>() / n;
        let sd = (e.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        (mean, sd / n.sqrt())
    };
    let (sobol, sobol_error) = stats(&errors(SamplerKind::Sobol));
    let (random, random_error) = stats(&errors(SamplerKind::Random));
    eprintln!(
        "smallpt 32x24, 16 spp, 8 seeds: RMSE sobol {sobol:.4} ± {sobol_error:.4}, random {random:.4} ± {random_error:.4}, ratio {:.3}",
        sobol / random
    );
    assert!(
        sobol + 2.0 * (sobol_error + random_error) < random,
        "sobol {sobol} ± {sobol_error}, random {random} ± {random_error}"
    );
}
