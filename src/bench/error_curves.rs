//! Error against wall time: render progressively and, each time the render
//! clock passes the next rung of a doubling ladder (1, 2, 4 … s), compare the
//! current estimate with a converged reference. Only time spent in
//! `render_pass` is counted: measuring the error does not eat into the budget.
//!
//! Metrics (`metrics::error_metrics`): RMSE, relMSE and the mean bias per
//! channel, which stays near 0 for unbiased estimators and reveals the
//! consistent-but-biased ones (SPPM) and leaks.

use super::plot::{LinePlot, Series};
use super::{BenchError, Csv, format_number};
use crate::camera::Camera;
use crate::film::{Frame, ToneMap};
use crate::metrics::{ErrorMetrics, error_metrics};
use crate::output::save_frame;
use crate::render::{ProgressiveRender, render_to_completion};
use crate::sampler::SamplerKind;
use crate::scene::{LoadedScene, Scene};
use crate::settings::{IntegratorKind, RenderSettings};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Duration;

/// One way of rendering that the curves compare.
#[derive(Clone, Debug, PartialEq)]
pub struct Configuration {
    /// Label in tables and plot legends, e.g. `pt/sobol+adaptive0.01`.
    pub name: String,
    /// The integrator to render with.
    pub integrator: IntegratorKind,
    /// The sample generator.
    pub sampler: SamplerKind,
    /// Relative-error threshold of adaptive sampling; `None` renders every
    /// pixel every pass.
    pub adaptive_threshold: Option<f64>,
}

impl Configuration {
    /// A configuration named after its choices.
    pub fn new(integrator: IntegratorKind, sampler: SamplerKind, adaptive_threshold: Option<f64>) -> Self {
        let adaptive = adaptive_threshold.map_or(String::new(), |t| format!("+adaptive{t}"));
        Self {
            name: format!("{integrator}/{sampler}{adaptive}"),
            integrator,
            sampler,
            adaptive_threshold,
        }
    }

    /// The configurations that matter: NEE+MIS with Sobol' (the default), with
    /// independent samples, and adaptive at each of `adaptive_thresholds`;
    /// BSDF sampling only; SPPM.
    pub fn standard(adaptive_thresholds: &[f64]) -> Vec<Configuration> {
        let mut configurations = vec![
            Configuration::new(IntegratorKind::PathTracing, SamplerKind::Sobol, None),
            Configuration::new(IntegratorKind::PathTracing, SamplerKind::Random, None),
        ];
        for &threshold in adaptive_thresholds {
            configurations.push(Configuration::new(
                IntegratorKind::PathTracing,
                SamplerKind::Sobol,
                Some(threshold),
            ));
        }
        configurations.push(Configuration::new(IntegratorKind::BsdfOnly, SamplerKind::Sobol, None));
        configurations.push(Configuration::new(IntegratorKind::Sppm, SamplerKind::Sobol, None));
        configurations
    }

    /// `settings` with this configuration's choices applied, at `width`×`height`.
    pub fn apply(&self, settings: &RenderSettings, width: u32, height: u32) -> RenderSettings {
        RenderSettings {
            width,
            height,
            samples_per_pixel: None,
            time_limit: None,
            integrator: self.integrator,
            sampler: self.sampler,
            adaptive_threshold: self.adaptive_threshold,
            ..settings.clone()
        }
    }
}

/// Wall times `first, 2·first, 4·first …` up to and including `last`.
pub fn time_ladder(first_seconds: f64, last_seconds: f64) -> Vec<f64> {
    let mut ladder = Vec::new();
    let mut t = first_seconds.max(1e-3);
    while t <= last_seconds * (1.0 + 1e-9) {
        ladder.push(t);
        t *= 2.0;
    }
    ladder
}

/// The error of one configuration at one rung of the ladder.
#[derive(Clone, Debug)]
pub struct CurvePoint {
    /// The rung of the ladder, in seconds of render time.
    pub target_seconds: f64,
    /// Render time actually spent: the first pass boundary past the target.
    pub elapsed_seconds: f64,
    /// Passes completed: samples per pixel, or SPPM iterations.
    pub passes: u32,
    /// The integrator's status then (e.g. the share of pixels adaptive sampling keeps active).
    pub status: String,
    /// Error of the estimate against the reference.
    pub metrics: ErrorMetrics,
    /// Samples dropped as NaN or infinite so far (should be 0).
    pub rejected_samples: u64,
}

/// Renders with `settings` until the last rung of `ladder` and measures the
/// error against `reference` at each rung. Runs on the current rayon pool.
pub fn measure_curve(
    scene: &Scene,
    camera: &Camera,
    settings: &RenderSettings,
    reference: &Frame,
    ladder: &[f64],
) -> Result<Vec<CurvePoint>, BenchError> {
    // No target: the ladder ends the render.
    let mut render = ProgressiveRender::new(&RenderSettings {
        samples_per_pixel: None,
        time_limit: None,
        ..settings.clone()
    });
    let cancel = AtomicBool::new(false);
    let mut points = Vec::with_capacity(ladder.len());
    let mut next = 0;
    let mut failure = None;
    render.run(scene, camera, &cancel, |render| {
        let integrator = render.integrator();
        let render_seconds = render.progress().elapsed.as_secs_f64();
        // Once adaptive sampling has stopped every pixel the estimate is
        // final: the remaining rungs get it, at the time actually spent.
        let converged = integrator.converged();
        if render_seconds < ladder[next] && !converged {
            return ControlFlow::Continue(());
        }
        let metrics = match error_metrics(&integrator.frame(), reference) {
            Ok(metrics) => metrics,
            Err(error) => {
                failure = Some(error);
                return ControlFlow::Break(());
            }
        };
        let status = integrator.status();
        // One slow pass can cross several rungs; each gets the same estimate.
        while next < ladder.len() && (render_seconds >= ladder[next] || converged) {
            points.push(CurvePoint {
                target_seconds: ladder[next],
                elapsed_seconds: render_seconds,
                passes: integrator.passes(),
                status: status.clone(),
                metrics,
                rejected_samples: integrator.rejected_samples(),
            });
            next += 1;
        }
        if next < ladder.len() {
            ControlFlow::Continue(())
        } else {
            ControlFlow::Break(())
        }
    });
    if let Some(mismatch) = failure {
        return Err(mismatch.into());
    }
    Ok(points)
}

/// Where the small reference of a scene file lives: `<directory>/<stem>.exr`.
pub fn reference_path(directory: &Path, scene_file: &Path) -> PathBuf {
    let stem = scene_file
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().to_string());
    directory.join(format!("{stem}.exr"))
}

/// The settings of a reference render: path tracing with NEE+MIS and Sobol'
/// samples, `width` pixels wide at the scene's aspect, for `seconds`, with a
/// seed no benchmark run uses (so reference noise is independent of theirs).
pub fn reference_settings(settings: &RenderSettings, width: u32, seconds: f64) -> RenderSettings {
    let height = ((width as f64 / settings.aspect()).round() as u32).max(1);
    RenderSettings {
        width,
        height,
        samples_per_pixel: None,
        time_limit: Some(Duration::from_secs_f64(seconds)),
        integrator: IntegratorKind::PathTracing,
        sampler: SamplerKind::Sobol,
        seed: REFERENCE_SEED,
        adaptive_threshold: None,
        ..settings.clone()
    }
}

/// Seed of reference renders; benchmark runs use the scene's seed (0 by default).
pub const REFERENCE_SEED: u64 = 0x0005_EED0_F2EF;

/// Renders a reference for `loaded` and writes it as EXR at `path`, with how
/// it was made in the file's metadata; returns the passes rendered.
pub fn make_reference(loaded: &LoadedScene, settings: &RenderSettings, path: &Path) -> Result<u32, BenchError> {
    let integrator = render_to_completion(&loaded.scene, &loaded.camera, settings);
    let metadata = vec![
        ("Software".to_string(), format!("prism {}", env!("CARGO_PKG_VERSION"))),
        (
            "Scene".to_string(),
            loaded.path.as_ref().map_or("<embedded>".into(), |p| p.display().to_string()),
        ),
        ("Integrator".to_string(), settings.integrator.to_string()),
        ("Sampler".to_string(), settings.sampler.to_string()),
        ("Seed".to_string(), settings.seed.to_string()),
        ("Passes".to_string(), integrator.passes().to_string()),
    ];
    save_frame(&integrator.frame(), path, 0.0, ToneMap::Clamp, &metadata)
        .map_err(|e| BenchError::Reference(format!("{}: {e}", path.display())))?;
    if integrator.rejected_samples() > 0 {
        return Err(BenchError::Reference(format!(
            "{} samples were NaN or infinite",
            integrator.rejected_samples()
        )));
    }
    Ok(integrator.passes())
}

/// Results of every configuration on one scene.
pub struct SceneCurves {
    /// The scene's name, for file names and titles.
    pub scene: String,
    /// Image width in pixels (the reference's).
    pub width: u32,
    /// Image height in pixels (the reference's).
    pub height: u32,
    /// Each configuration with its points, in the order measured.
    pub curves: Vec<(Configuration, Vec<CurvePoint>)>,
}

/// Measures every configuration on one scene at the reference's resolution,
/// one after another on the current rayon pool; `progress` hears each result.
pub fn measure_scene(
    scene_name: &str,
    loaded: &LoadedScene,
    reference: &Frame,
    configurations: &[Configuration],
    ladder: &[f64],
    mut progress: impl FnMut(&Configuration, &[CurvePoint]),
) -> Result<SceneCurves, BenchError> {
    let mut curves = Vec::new();
    for configuration in configurations {
        let settings = configuration.apply(&loaded.settings, reference.width, reference.height);
        let points = measure_curve(&loaded.scene, &loaded.camera, &settings, reference, ladder)?;
        progress(configuration, &points);
        curves.push((configuration.clone(), points));
    }
    Ok(SceneCurves {
        scene: scene_name.to_string(),
        width: reference.width,
        height: reference.height,
        curves,
    })
}

impl SceneCurves {
    /// The CSV table: one row per configuration and rung.
    pub fn csv(&self, machine: &str, threads: usize) -> Csv {
        let mut csv = Csv::new(vec![
            "scene",
            "configuration",
            "integrator",
            "sampler",
            "adaptive_threshold",
            "target_seconds",
            "elapsed_seconds",
            "passes",
            "rmse",
            "relmse",
            "bias_r",
            "bias_g",
            "bias_b",
            "rejected_samples",
            "status",
        ]);
        csv.comments.push(format!(
            "prism bench: error against the reference at doubling render times, {}x{} pixels, {threads} threads",
            self.width, self.height
        ));
        csv.comments.push(machine.to_string());
        for (configuration, points) in &self.curves {
            for p in points {
                csv.rows.push(vec![
                    self.scene.clone(),
                    configuration.name.clone(),
                    configuration.integrator.to_string(),
                    configuration.sampler.to_string(),
                    configuration.adaptive_threshold.map_or(String::new(), |t| t.to_string()),
                    format!("{}", p.target_seconds),
                    format!("{:.4}", p.elapsed_seconds),
                    p.passes.to_string(),
                    format_number(p.metrics.rmse),
                    format_number(p.metrics.relative_mse),
                    format_number(p.metrics.bias[0]),
                    format_number(p.metrics.bias[1]),
                    format_number(p.metrics.bias[2]),
                    p.rejected_samples.to_string(),
                    p.status.replace(',', ";"),
                ]);
            }
        }
        csv
    }

    /// The log-log plot of RMSE against render time, one line per configuration.
    pub fn plot(&self) -> LinePlot {
        let mut series: Vec<Series> = self
            .curves
            .iter()
            .map(|(configuration, points)| Series {
                name: configuration.name.clone(),
                points: points.iter().map(|p| (p.elapsed_seconds, p.metrics.rmse)).collect(),
                guide: false,
            })
            .collect();
        // Guide: the Monte Carlo rate, RMSE ∝ t^(-1/2), through the first curve's start.
        if let Some(first) = series.first().and_then(|s| s.points.first().copied()) {
            let end = series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.0))
                .fold(first.0, f64::max);
            series.push(Series {
                name: "∝ t^-1/2".into(),
                points: vec![first, (end, first.1 * (first.0 / end).sqrt())],
                guide: true,
            });
        }
        LinePlot {
            title: format!("{}: RMSE against render time ({}x{})", self.scene, self.width, self.height),
            x_label: "render time [s]".into(),
            y_label: "RMSE".into(),
            log_x: true,
            log_y: true,
            series,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reference of the wrong size names both sizes, reference first.
    #[test]
    fn a_mismatched_reference_is_reported_with_both_sizes() {
        let error = BenchError::from(crate::metrics::SizeMismatch(1, 1, 4, 1));
        assert_eq!(error.to_string(), "reference image: size 4x1 differs from the estimate's 1x1");
    }

    #[test]
    fn ladder_doubles_up_to_the_last_rung() {
        assert_eq!(time_ladder(0.5, 8.0), vec![0.5, 1.0, 2.0, 4.0, 8.0]);
        assert_eq!(time_ladder(1.0, 64.0).len(), 7);
    }
}
