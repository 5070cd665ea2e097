//! The viewer's denoised preview (`prism::denoise`): its quality and its cost.
//!
//! Quality, printed before timing: the Cornell box at 16 samples per pixel
//! (path tracing, 256 × 256 like `references/cornell.exr`, seeds 1 to 4)
//! against that reference, relMSE of the raw render and of the denoised one
//! (the metric of `prism bench`: mean over pixels and channels of
//! (x − r)² / (r² + 0.01)), and their ratio.
//!
//! Cost: `denoise` on a 512 × 512 Cornell frame (4 samples per pixel) on a
//! single worker thread, and the first-hit guide pass at that size.
//!
//! Run with `cargo bench --bench denoise`.

use criterion::{Criterion, criterion_group, criterion_main};
use prism::denoise::{DenoiseSettings, Guides, denoise};
use prism::film::Frame;
use prism::metrics::error_metrics;
use prism::render::{RenderSettings, render_with_threads};
use prism::scene::{LoadedScene, load_scene_file};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

const QUALITY_SAMPLES: u32 = 16;
const QUALITY_SEEDS: [u64; 4] = [1, 2, 3, 4];
const TIMING_SIZE: u32 = 512;

fn cornell() -> LoadedScene {
    load_scene_file(Path::new("scenes/cornell.toml")).expect("scenes/cornell.toml loads")
}

fn render(loaded: &LoadedScene, width: u32, height: u32, samples: u32, seed: u64) -> Frame {
    let settings = RenderSettings {
        width,
        height,
        samples_per_pixel: Some(samples),
        time_limit: None,
        adaptive_threshold: None,
        seed,
        ..loaded.settings.clone()
    };
    render_with_threads(&loaded.scene, &loaded.camera, &settings, None)
        .expect("worker threads")
        .frame()
}

fn report_quality(loaded: &LoadedScene) {
    let reference = prism::output::load_frame(Path::new("references/cornell.exr")).expect("references/cornell.exr");
    let guides = Guides::first_hit(&loaded.scene, &loaded.camera, reference.width, reference.height);
    let settings = DenoiseSettings::default();
    let (mut raw_sum, mut denoised_sum) = (0.0, 0.0);
    for seed in QUALITY_SEEDS {
        let frame = render(loaded, reference.width, reference.height, QUALITY_SAMPLES, seed);
        let denoised = denoise(&frame, &guides, &settings).expect("guides of the frame's size");
        let raw = error_metrics(&frame, &reference).expect("same size").relative_mse;
        let filtered = error_metrics(&denoised, &reference).expect("same size").relative_mse;
        println!(
            "denoise quality: seed {seed}: relMSE raw {raw:.5}, denoised {filtered:.5}, ratio {:.3}",
            filtered / raw
        );
        raw_sum += raw;
        denoised_sum += filtered;
    }
    println!(
        "denoise quality: Cornell box {}x{} at {QUALITY_SAMPLES} spp, mean over {} seeds: relMSE raw {:.5}, denoised {:.5}, ratio {:.3} (target ≤ 0.5)",
        reference.width,
        reference.height,
        QUALITY_SEEDS.len(),
        raw_sum / QUALITY_SEEDS.len() as f64,
        denoised_sum / QUALITY_SEEDS.len() as f64,
        denoised_sum / raw_sum
    );
}

fn bench_denoise(c: &mut Criterion) {
    let loaded = cornell();
    report_quality(&loaded);

    let frame = render(&loaded, TIMING_SIZE, TIMING_SIZE, 4, 1);
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a worker thread");
    let guides = one_thread.install(|| Guides::first_hit(&loaded.scene, &loaded.camera, TIMING_SIZE, TIMING_SIZE));
    let settings = DenoiseSettings::default();
    let mut group = c.benchmark_group("denoise");
    group.sample_size(10).measurement_time(Duration::from_secs(3));
    group.bench_function("a-trous 512x512, one thread", |b| {
        b.iter(|| one_thread.install(|| denoise(black_box(&frame), &guides, &settings)))
    });
    group.bench_function("first-hit guides 512x512, one thread", |b| {
        b.iter(|| one_thread.install(|| Guides::first_hit(&loaded.scene, &loaded.camera, TIMING_SIZE, TIMING_SIZE)))
    });
    group.finish();
}

criterion_group!(benches, bench_denoise);
criterion_main!(benches);
