//! Helpers shared by the integration tests.
#![allow(dead_code)]

use prism::film::Frame;
use prism::render::{IntegratorKind, RenderSettings, render_with_threads};
use prism::sampler::SamplerKind;
use prism::scene::{LoadedScene, load_scene_str};
use std::path::{Path, PathBuf};

/// A test's own scratch directory in the system temp dir, removed with all
/// it holds when dropped, so also when the test panics. One per test: the
/// tests of a file run in parallel threads, and a directory they shared
/// would be removed by whichever finished first.
pub struct ScratchDir(PathBuf);

impl ScratchDir {
    /// `<temp dir>/<prefix>-<process id>-<test>`, empty: the process id
    /// keeps concurrent runs apart, the test's name the tests of one run.
    pub fn new(prefix: &str, test: &str) -> Self {
        let path = std::env::temp_dir().join(format!("{prefix}-{}-{test}", std::process::id()));
        // A killed run of a process with the same id may have left it.
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path).expect("scratch directory");
        Self(path)
    }

    pub fn path(&self) -> &Path {
        &self.0
    }

    pub fn join(&self, name: impl AsRef<Path>) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

pub fn scene(text: &str) -> LoadedScene {
    match load_scene_str(text, Path::new("test.toml"), Path::new(env!("CARGO_MANIFEST_DIR"))) {
        Ok(s) => s,
        Err(e) => panic!("test scene does not load: {e}"),
    }
}

pub fn shipped_scene(name: &str) -> LoadedScene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes").join(name);
    match prism::scene::load_scene_file(&path) {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    }
}

pub struct Job {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub integrator: IntegratorKind,
    pub sampler: SamplerKind,
    pub seed: u64,
    pub max_depth: u32,
    pub threads: Option<usize>,
    /// Spectral transport (the scene's own setting also turns it on).
    pub spectral: bool,
    /// Light-traced caustics on or off; `None`: the scene's setting.
    pub caustic_light_paths: Option<bool>,
}

impl Default for Job {
    fn default() -> Self {
        Self {
            width: 32,
            height: 32,
            spp: 16,
            integrator: IntegratorKind::PathTracing,
            sampler: SamplerKind::Sobol,
            seed: 1,
            max_depth: 64,
            threads: None,
            spectral: false,
            caustic_light_paths: None,
        }
    }
}

pub fn render(loaded: &LoadedScene, job: &Job) -> Frame {
    let settings = RenderSettings {
        width: job.width,
        height: job.height,
        samples_per_pixel: Some(job.spp),
        time_limit: None,
        max_depth: job.max_depth,
        integrator: job.integrator,
        sampler: job.sampler,
        seed: job.seed,
        spectral: job.spectral || loaded.settings.spectral,
        caustic_light_paths: job.caustic_light_paths.unwrap_or(loaded.settings.caustic_light_paths),
        ..loaded.settings.clone()
    };
    match render_with_threads(&loaded.scene, &loaded.camera, &settings, job.threads) {
        Ok(integrator) => {
            assert_eq!(integrator.rejected_samples(), 0, "NaN or infinite samples");
            integrator.frame()
        }
        Err(e) => panic!("{e}"),
    }
}

/// Mean and standard error of the per-channel image mean over independent
/// renders with seeds 1..=runs.
pub fn mean_and_error(loaded: &LoadedScene, job: &Job, runs: u64) -> ([f64; 3], [f64; 3]) {
    let means: Vec<[f64; 3]> = (1..=runs)
        .map(|seed| render(loaded, &Job { seed, ..*job }).channel_means())
        .collect();
    let n = runs as f64;
    let mut mean = [0.0; 3];
    let mut error = [0.0; 3];
    for c in 0..3 {
        mean[c] = means.iter().map(|m| m[c]).sum::<f64>() / n;
        let variance = means.iter().map(|m| (m[c] - mean[c]).powi(2)).sum::<f64>() / (n - 1.0);
        error[c] = (variance / n).sqrt();
    }
    (mean, error)
}

impl Clone for Job {
    fn clone(&self) -> Self {
        *self
    }
}
impl Copy for Job {}

/// Runs NEE+MIS and BSDF-only path tracing over 8 seeds each and checks
/// that their per-channel means agree within three combined standard
/// errors; `min_mean` and `max_relative_error` make sure the comparison is
/// sharp enough to mean something.
pub fn assert_estimators_agree(loaded: &LoadedScene, job: Job, min_mean: f64, max_relative_error: f64) {
    let (nee, nee_error) = mean_and_error(
        loaded,
        &Job {
            integrator: IntegratorKind::PathTracing,
            ..job
        },
        8,
    );
    let (bsdf, bsdf_error) = mean_and_error(
        loaded,
        &Job {
            integrator: IntegratorKind::BsdfOnly,
            ..job
        },
        8,
    );
    eprintln!("NEE {nee:?} ± {nee_error:?}, BSDF {bsdf:?} ± {bsdf_error:?}");
    for c in 0..3 {
        let combined = (nee_error[c].powi(2) + bsdf_error[c].powi(2)).sqrt();
        assert!(
            (nee[c] - bsdf[c]).abs() < 3.0 * combined,
            "channel {c}: NEE {} ± {}, BSDF {} ± {}",
            nee[c],
            nee_error[c],
            bsdf[c],
            bsdf_error[c]
        );
        assert!(
            nee[c] > min_mean && combined < max_relative_error * nee[c],
            "channel {c}: {nee:?} ± {combined}"
        );
    }
}

/// A diffuse wall (at z = 0, facing the camera, filling the view) under a
/// square light above and in front of it; `ALBEDO` and `LIGHT` are replaced.
/// Every path is one bounce: off the wall to the light, or out.
pub const WALL: &str = r#"
[camera]
position = [0, 0, 3]
look_at = [0, 0, 0]
fov_y_degrees = 30

[materials.wall]
type = "diffuse"
albedo = ALBEDO
[materials.light]
type = "emissive"
LIGHT

[[objects]]
type = "quad"
corner = [-2, -2, 0]
edge_u = [4, 0, 0]
edge_v = [0, 4, 0]
material = "wall"
[[objects]]
type = "quad"
corner = [-0.5, 2, 0.5]
edge_u = [1, 0, 0]
edge_v = [0, 0, 1]
material = "light"
"#;

/// The wall scene with its albedo (`[r, g, b]`) and light (a `radiance = …` or spectrum line).
pub fn wall(albedo: &str, light: &str) -> LoadedScene {
    scene(&WALL.replace("ALBEDO", albedo).replace("LIGHT", light))
}

/// Per channel, the mean and standard error over seeds 1..=runs of
/// `statistic(spectral image means, RGB image means)`, the two renders
/// paired by seed. Spectral paths take their wavelengths from a side stream,
/// so a pair traces the same paths and differs only by what the
/// wavelengths carry: the paired statistic is far less noisy than either.
pub fn paired(loaded: &LoadedScene, job: Job, runs: u64, statistic: fn(f64, f64) -> f64) -> [(f64, f64); 3] {
    let values: Vec<[f64; 3]> = (1..=runs)
        .map(|seed| {
            let rgb = render(loaded, &Job { seed, ..job }).channel_means();
            let spectral = render(
                loaded,
                &Job {
                    seed,
                    spectral: true,
                    ..job
                },
            )
            .channel_means();
            std::array::from_fn(|c| statistic(spectral[c], rgb[c]))
        })
        .collect();
    let n = runs as f64;
    std::array::from_fn(|c| {
        let mean = values.iter().map(|v| v[c]).sum::<f64>() / n;
        let variance = values.iter().map(|v| (v[c] - mean).powi(2)).sum::<f64>() / (n - 1.0);
        (mean, (variance / n).sqrt())
    })
}
