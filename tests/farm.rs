//! A render split into parts and merged equals one run, bit for bit: path
//! tracing with Sobol' and independent samples, adaptive sampling (split by
//! rows) and SPPM with the global radius schedule, for 1, 2, 3 and 7 parts;
//! through films in memory and through film files on disk. Exact equality
//! is the only right tolerance: any dependence of a sample on which part
//! rendered it, or any rounding that depends on grouping, changes bits.

mod common;
use common::{ScratchDir, shipped_scene};
use prism::farm::file::write_film;
use prism::farm::{FilmHeader, MergeOptions, PartRequest, content_hash, merge_files, plan_share};
use prism::film::Film;
use prism::integrator::{self, Share};
use prism::render::{IntegratorKind, ProgressiveRender, RenderSettings};
use prism::sampler::SamplerKind;
use prism::scene::LoadedScene;
use prism::settings::RadiusSchedule;
use std::ops::ControlFlow;
use std::sync::atomic::AtomicBool;

const PART_COUNTS: [u32; 4] = [1, 2, 3, 7];

/// Renders `share` of `settings` to completion on `threads` threads; its film.
fn render_share(loaded: &LoadedScene, settings: &RenderSettings, share: &Share, threads: usize) -> Film {
    let driver = RenderSettings {
        samples_per_pixel: Some(share.passes()),
        ..settings.clone()
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    let mut render = ProgressiveRender::with_integrator(integrator::create_share(settings, share), &driver);
    if share.passes() > 0 {
        let cancel = AtomicBool::new(false);
        pool.install(|| render.run(&loaded.scene, &loaded.camera, &cancel, |_| ControlFlow::Continue(())));
    }
    render.integrator().film().expect("a film to merge").clone()
}

/// The merge of `parts` parts against the whole render, exactly; returns the whole film.
fn check_parts_merge_exactly(loaded: &LoadedScene, settings: &RenderSettings, what: &str) -> Film {
    let whole = render_share(loaded, settings, &Share::whole(settings.samples_per_pixel.unwrap_or(0)), 2);
    assert_eq!(whole.rejected_samples, 0, "{what}");
    for parts in PART_COUNTS {
        let mut merged = Film::new(settings.width, settings.height);
        for part in 0..parts {
            let share = plan_share(settings, &PartRequest::Part { part, parts }).expect("splits");
            // Parts on 1 thread, the whole on 2: scheduling must not matter either.
            merged.merge(&render_share(loaded, settings, &share, 1)).expect("same size");
        }
        assert!(merged == whole, "{what}: {parts} parts merged differ from one run");
        assert_eq!(merged.frame(), whole.frame(), "{what}: {parts} parts");
    }
    whole
}

fn cornell_settings(loaded: &LoadedScene) -> RenderSettings {
    RenderSettings {
        width: 20,
        height: 14,
        samples_per_pixel: Some(15),
        seed: 11,
        ..loaded.settings.clone()
    }
}

#[test]
fn path_tracing_parts_merge_into_one_run_with_both_samplers() {
    let loaded = shipped_scene("cornell.toml");
    for sampler in [SamplerKind::Sobol, SamplerKind::Random] {
        let settings = RenderSettings {
            sampler,
            ..cornell_settings(&loaded)
        };
        let whole = check_parts_merge_exactly(&loaded, &settings, &format!("pt/{sampler}"));
        assert!(whole.pixels.iter().all(|p| p.count == 15));
    }
    let bsdf_only = RenderSettings {
        integrator: IntegratorKind::BsdfOnly,
        ..cornell_settings(&loaded)
    };
    check_parts_merge_exactly(&loaded, &bsdf_only, "pt-bsdf");
}

/// Adaptive sampling splits by rows: each part renders every N-th row with
/// all samples. The threshold is chosen so that some pixels stop before the
/// target and some do not, else this would test nothing adaptive.
#[test]
fn adaptive_parts_merge_into_one_run() {
    let loaded = shipped_scene("cornell.toml");
    let settings = RenderSettings {
        samples_per_pixel: Some(48),
        adaptive_threshold: Some(0.3),
        ..cornell_settings(&loaded)
    };
    let whole = check_parts_merge_exactly(&loaded, &settings, "adaptive");
    let stopped = whole.pixels.iter().filter(|p| p.count < 48).count();
    assert!(
        stopped > 0 && stopped < whole.pixels.len(),
        "{stopped} of {} pixels stopped early",
        whole.pixels.len()
    );
}

/// A shipped scene set up for small global-schedule SPPM farm renders:
/// 16×12, 7 iterations of 4,000 photons, seed 5.
fn global_sppm(name: &str) -> (LoadedScene, RenderSettings) {
    let mut loaded = shipped_scene(name);
    loaded.settings.sppm.photons_per_iteration = 4_000;
    loaded.settings.sppm.radius_schedule = RadiusSchedule::Global;
    let settings = RenderSettings {
        width: 16,
        height: 12,
        samples_per_pixel: Some(7),
        integrator: IntegratorKind::Sppm,
        seed: 5,
        ..loaded.settings.clone()
    };
    (loaded, settings)
}

#[test]
fn global_schedule_sppm_parts_merge_into_one_run() {
    let (loaded, settings) = global_sppm("caustic.toml");
    let whole = check_parts_merge_exactly(&loaded, &settings, "sppm/global");
    // Each iteration is one sample of every pixel: the mean is of 7 estimates.
    assert!(whole.pixels.iter().all(|p| p.count == 7));
    assert!(whole.frame().channel_means().iter().all(|&m| m > 0.0), "SPPM saw no light");
}

/// The same for spectral SPPM (photons with their own wavelengths) on the
/// dispersive scene.
#[test]
fn spectral_global_schedule_sppm_parts_merge_into_one_run() {
    let (loaded, mut settings) = global_sppm("dispersion.toml");
    assert!(loaded.scene.has_dispersion());
    settings.max_depth = 8;
    let whole = check_parts_merge_exactly(&loaded, &settings, "spectral sppm/global");
    assert!(whole.frame().channel_means().iter().all(|&m| m > 0.0), "SPPM saw no light");
}

/// Explicit ranges in any order and through film files give the same bits;
/// so does a merge of merges (hierarchical), and a range starting past 0.
#[test]
fn film_files_merge_exactly_in_any_grouping() {
    let loaded = shipped_scene("cornell.toml");
    let settings = cornell_settings(&loaded);
    let whole = render_share(&loaded, &settings, &Share::whole(15), 2);
    let dir = ScratchDir::new("prism-farm", "film_files_merge_exactly_in_any_grouping");
    let hash = content_hash::scene_hash(&loaded.scene, &loaded.camera);
    let ranges = [9..15, 0..4, 4..9];
    let mut files = Vec::new();
    for range in ranges {
        let share = plan_share(&settings, &PartRequest::Samples(range.clone())).expect("splits");
        let film = render_share(&loaded, &settings, &share, 1);
        let path = dir.join(format!("{}-{}.film", range.start, range.end));
        write_film(&path, &FilmHeader::new("cornell.toml", &settings, &hash, &share, None), &film).expect("writes");
        files.push(path);
    }
    let merged = merge_files(&files, MergeOptions::default()).expect("merges");
    assert!(merged.film == whole, "three ranges merged differ from one run");
    assert!(merged.missing.is_empty());
    assert_eq!(merged.samples_held, 20 * 14 * 15);
    // Two of them merged first, then with the third.
    let pair = dir.join("pair.film");
    let first_two = merge_files(&files[..2], MergeOptions { allow_missing: true }).expect("merges with a gap");
    assert_eq!(first_two.missing.to_string(), "samples 4..9 of every row");
    write_film(&pair, &first_two.header, &first_two.film).expect("writes");
    let again = merge_files(&[pair, files[2].clone()], MergeOptions::default()).expect("merges");
    assert!(again.film == whole, "a merge of merges differs from one run");
}
