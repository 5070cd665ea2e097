//! `prism bench --throughput`: how many samples per second each scene
//! renders, on one and on two threads, with its own settings (resolution,
//! depth) and path tracing; SPPM scenes also report photons per second.
//! The figure users feel: the rate at which the viewer's image converges.

use super::{BenchError, Csv, format_number};
use crate::render::{IntegratorKind, ProgressiveRender, RenderSettings};
use crate::scene::LoadedScene;
use std::ops::ControlFlow;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

/// One scene, integrator and thread count.
#[derive(Clone, Debug)]
pub struct ThroughputRow {
    /// The scene's name.
    pub scene: String,
    /// Path tracing, or SPPM for scenes that ask for it.
    pub integrator: IntegratorKind,
    /// Worker threads.
    pub threads: usize,
    /// Image width in pixels (the scene's own).
    pub width: u32,
    /// Image height in pixels (the scene's own).
    pub height: u32,
    /// Passes completed in the time budget.
    pub passes: u32,
    /// Render time actually spent, in seconds.
    pub seconds: f64,
    /// Pixel samples (SPPM: camera paths) per second.
    pub samples_per_second: f64,
    /// SPPM only: photons traced per second of whole iterations.
    pub photons_per_second: Option<f64>,
}

/// Renders `loaded` for about `seconds` with each thread count and with
/// path tracing (and SPPM too if the scene asks for it), counting passes.
pub fn measure_scene(
    name: &str,
    loaded: &LoadedScene,
    seconds: f64,
    thread_counts: &[usize],
) -> Result<Vec<ThroughputRow>, BenchError> {
    let mut integrators = vec![IntegratorKind::PathTracing];
    if loaded.settings.integrator == IntegratorKind::Sppm {
        integrators.push(IntegratorKind::Sppm);
    }
    let mut rows = Vec::new();
    for &threads in thread_counts {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
        for &integrator in &integrators {
            let settings = RenderSettings {
                integrator,
                samples_per_pixel: None,
                time_limit: Some(Duration::from_secs_f64(seconds)),
                adaptive_threshold: None,
                ..loaded.settings.clone()
            };
            let mut render = ProgressiveRender::new(&settings);
            let cancel = AtomicBool::new(false);
            pool.install(|| render.run(&loaded.scene, &loaded.camera, &cancel, |_| ControlFlow::Continue(())));
            let progress = render.progress();
            let elapsed = progress.elapsed.as_secs_f64().max(1e-9);
            let samples = progress.passes as f64 * settings.pixel_count() as f64;
            rows.push(ThroughputRow {
                scene: name.to_string(),
                integrator,
                threads,
                width: settings.width,
                height: settings.height,
                passes: progress.passes,
                seconds: elapsed,
                samples_per_second: samples / elapsed,
                photons_per_second: (integrator == IntegratorKind::Sppm)
                    .then(|| progress.passes as f64 * settings.sppm.photons_per_iteration as f64 / elapsed),
            });
        }
    }
    Ok(rows)
}

/// Writes the rows as `throughput.csv` in `directory`.
pub fn write_results(rows: &[ThroughputRow], machine: &str, directory: &Path) -> Result<(), BenchError> {
    let mut csv = Csv::new(vec![
        "scene",
        "integrator",
        "threads",
        "width",
        "height",
        "passes",
        "seconds",
        "samples_per_second",
        "photons_per_second",
    ]);
    csv.comments
        .push("prism bench --throughput: render passes for a fixed time per scene".into());
    csv.comments.push(machine.to_string());
    for r in rows {
        csv.rows.push(vec![
            r.scene.clone(),
            r.integrator.to_string(),
            r.threads.to_string(),
            r.width.to_string(),
            r.height.to_string(),
            r.passes.to_string(),
            format!("{:.3}", r.seconds),
            format_number(r.samples_per_second),
            r.photons_per_second.map_or(String::new(), format_number),
        ]);
    }
    csv.write(&directory.join("throughput.csv"))
}
