//! `prism bench`: error against time (default), `--make-references`,
//! `--scaling`, `--stress` and `--sppm-schedules`. Argument handling and progress lines only; the
//! measurements live in the library's `bench` module.

use anyhow::{Context, Result, bail};
use clap::Args;
use prism::bench::{self, error_curves, plot, rays, scaling, sppm_schedules, stress, throughput};
use prism::output::load_frame;
use prism::render::{IntegratorKind, RenderSettings};
use prism::scene::{self, LoadedScene};
use std::path::{Path, PathBuf};

/// Said instead of naming PNG files when the build cannot draw them.
const PLOTS_DISABLED: &str = "plots disabled: this prism was built without the `plots` feature";

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Scene files (default: every scenes/*.toml; those without a reference are skipped).
    scenes: Vec<PathBuf>,
    /// Directory of the small reference images (<scene stem>.exr).
    #[arg(long, default_value = "references")]
    references: PathBuf,
    /// Where the CSV tables and PNG plots (with the `plots` feature) go.
    #[arg(long, default_value = "docs")]
    output_dir: PathBuf,
    /// Last rung of the time ladder, in seconds of rendering.
    #[arg(long, default_value_t = 64.0)]
    max_seconds: f64,
    /// First rung; the ladder doubles from here up to --max-seconds.
    #[arg(long, default_value_t = 1.0)]
    min_seconds: f64,
    /// Worker threads for every render.
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Noise thresholds of the adaptive-sampling configurations (comma-separated).
    #[arg(long, value_delimiter = ',', default_values_t = [0.05])]
    adaptive_threshold: Vec<f64>,
    /// Only these configurations (comma-separated names as in the CSV, e.g. pt/sobol,pt-bsdf/sobol).
    #[arg(long, value_delimiter = ',')]
    configurations: Vec<String>,
    /// Render each scene's reference for this many seconds instead of benchmarking.
    #[arg(long, value_name = "SECONDS")]
    make_references: Option<f64>,
    /// Width of rendered references, in pixels (height follows the scene's aspect).
    #[arg(long, default_value_t = 256)]
    reference_width: u32,
    /// Integrator of rendered references: pt (unbiased, the default) or, for
    /// caustics seen only through specular paths from a tiny light, sppm.
    #[arg(long, default_value = "pt", value_parser = crate::parse_integrator)]
    reference_integrator: IntegratorKind,
    /// Measure BVH build, ray cost and render time scaling instead.
    #[arg(long)]
    scaling: bool,
    /// Largest triangle count of the scaling run (from 1024, ×4 per step).
    #[arg(long, default_value_t = 1 << 20)]
    max_triangles: u32,
    /// Run the long numerical stress test instead.
    #[arg(long)]
    stress: bool,
    /// Measure the ray core instead: closest-hit and occlusion queries on the
    /// bunny and its subdivisions, build time and memory.
    #[arg(long)]
    rays: bool,
    /// With --rays: also write meshes, rays and Prism's answers to this folder
    /// for a peer renderer to trace (benches/peers/embree_rays.py).
    #[arg(long, value_name = "DIR")]
    export_rays: Option<PathBuf>,
    /// Measure samples per second of each scene on 1 and 2 threads instead.
    #[arg(long)]
    throughput: bool,
    /// Seconds of rendering per scene and thread count in --throughput.
    #[arg(long, default_value_t = 5.0)]
    throughput_seconds: f64,
    /// Timed repetitions per measurement in --rays (the best is kept).
    #[arg(long, default_value_t = 3)]
    repetitions: usize,
    /// Passes per integrator and scene in --stress.
    #[arg(long, default_value_t = 64)]
    stress_passes: u32,
    /// Probe rays per scene or mesh in --stress.
    #[arg(long, default_value_t = 200_000)]
    stress_rays: u64,
    /// Compare SPPM's per-pixel and global radius schedules at equal
    /// iterations against each scene's reference instead (docs/farm.md).
    #[arg(long)]
    sppm_schedules: bool,
    /// Last rung of --sppm-schedules' iteration ladder (1, 2, 4 …).
    #[arg(long, default_value_t = 128)]
    max_iterations: u32,
    /// Seed of the --sppm-schedules renders.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

pub fn bench_command(args: BenchArgs) -> Result<()> {
    prism::settings::validate::thread_count(args.threads)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .context("cannot start worker threads")?;
    pool.install(|| {
        if args.rays {
            rays_command(&args)
        } else if args.throughput {
            throughput_command(&args)
        } else if args.stress {
            stress_command(&args)
        } else if args.sppm_schedules {
            sppm_schedules_command(&args)
        } else if args.scaling {
            scaling_command(&args)
        } else if let Some(seconds) = args.make_references {
            references_command(&args, seconds)
        } else {
            curves_command(&args)
        }
    })
}

/// The scene files named, or every scenes/*.toml.
fn scene_files(args: &BenchArgs) -> Result<Vec<PathBuf>> {
    if !args.scenes.is_empty() {
        return Ok(args.scenes.clone());
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir("scenes")
        .context("no scene files given and no scenes/ directory here")?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    Ok(files)
}

fn stem(path: &Path) -> String {
    path.file_stem().map_or("scene".into(), |s| s.to_string_lossy().to_string())
}

fn references_command(args: &BenchArgs, seconds: f64) -> Result<()> {
    prism::settings::validate::time_limit(seconds).context("--make-references")?;
    if !(1..=prism::settings::validate::MAX_IMAGE_SIDE).contains(&args.reference_width) {
        bail!(
            "--reference-width: must be between 1 and {} pixels",
            prism::settings::validate::MAX_IMAGE_SIDE
        );
    }
    for file in scene_files(args)? {
        let loaded = scene::load_scene_file(&file)?;
        let settings = RenderSettings {
            integrator: args.reference_integrator,
            ..error_curves::reference_settings(&loaded.settings, args.reference_width, seconds)
        };
        let path = error_curves::reference_path(&args.references, &file);
        eprintln!(
            "{}: rendering {}x{} for {seconds} s ...",
            file.display(),
            settings.width,
            settings.height
        );
        let passes = error_curves::make_reference(&loaded, &settings, &path)?;
        eprintln!(
            "wrote {} ({passes} {} of {}, seed {})",
            path.display(),
            if settings.integrator == IntegratorKind::Sppm {
                "iterations"
            } else {
                "samples per pixel"
            },
            settings.integrator,
            settings.seed
        );
    }
    Ok(())
}

fn curves_command(args: &BenchArgs) -> Result<()> {
    let max = prism::settings::validate::MAX_TIME_SECONDS;
    if !(args.min_seconds > 0.0 && args.max_seconds >= args.min_seconds && args.max_seconds <= max) {
        bail!("need 0 < --min-seconds <= --max-seconds <= {max:e}");
    }
    let ladder = error_curves::time_ladder(args.min_seconds, args.max_seconds);
    if args.adaptive_threshold.iter().any(|t| !(t.is_finite() && *t > 0.0)) {
        bail!("--adaptive-threshold values must be positive numbers");
    }
    let mut configurations = error_curves::Configuration::standard(&args.adaptive_threshold);
    if !args.configurations.is_empty() {
        configurations.retain(|c| args.configurations.contains(&c.name));
        if configurations.is_empty() {
            bail!(
                "no configuration matches; names are {:?}",
                error_curves::Configuration::standard(&args.adaptive_threshold)
                    .iter()
                    .map(|c| c.name.clone())
                    .collect::<Vec<_>>()
            );
        }
    }
    for file in scene_files(args)? {
        let name = stem(&file);
        let loaded: LoadedScene = scene::load_scene_file(&file)?;
        let reference_file = error_curves::reference_path(&args.references, &file);
        if args.scenes.is_empty() && !reference_file.exists() {
            eprintln!(
                "{name}: skipped, no reference {} (make it with --make-references)",
                reference_file.display()
            );
            continue;
        }
        let reference = load_frame(&reference_file)
            .map_err(|e| anyhow::anyhow!("{e}\n(make it with: prism bench {} --make-references 600)", file.display()))?;
        eprintln!(
            "{name}: {} configurations, ladder {ladder:?} s, {}x{}",
            configurations.len(),
            reference.width,
            reference.height
        );
        let machine_before = bench::machine_note();
        let curves = error_curves::measure_scene(
            &name,
            &loaded,
            &reference,
            &configurations,
            &ladder,
            |configuration, points| {
                let line: Vec<String> = points
                    .iter()
                    .map(|p| format!("{:.1}s:{:.4}", p.elapsed_seconds, p.metrics.rmse))
                    .collect();
                eprintln!("  {:<24} RMSE {}", configuration.name, line.join(" "));
            },
        )?;
        let machine = format!("before: {machine_before}; after: {}", bench::machine_note());
        let csv_path = args.output_dir.join(format!("error_{name}.csv"));
        let png_path = args.output_dir.join(format!("error_{name}.png"));
        curves.csv(&machine, args.threads).write(&csv_path)?;
        curves.plot().write_png(&png_path)?;
        if plot::ENABLED {
            eprintln!("wrote {} and {}", csv_path.display(), png_path.display());
        } else {
            eprintln!("wrote {} ({PLOTS_DISABLED})", csv_path.display());
        }
    }
    Ok(())
}

fn scaling_command(args: &BenchArgs) -> Result<()> {
    let mut counts = Vec::new();
    let mut n = 1024u32;
    while n <= args.max_triangles {
        counts.push(n);
        n = n.saturating_mul(4);
    }
    eprintln!("BVH: {counts:?} triangles");
    let bvh_rows = scaling::measure_bvh(&counts, 500_000, |r| {
        eprintln!(
            "  {:>8} triangles: build {:.4} s CPU ({:.4} s wall), {:.0} ns/ray CPU ({:.0} wall), {:.0}% hit",
            r.triangles,
            r.build_seconds,
            r.build_wall_seconds,
            r.ns_per_ray,
            r.wall_ns_per_ray,
            100.0 * r.hit_fraction
        )
    })?;
    scaling::write_bvh_results(&bvh_rows, &bench::machine_note(), &args.output_dir)?;

    let file = scene_files(args)?.into_iter().next();
    let loaded = match &file {
        Some(path) => scene::load_scene_file(path)?,
        None => scene::load_scene_str(scene::DEFAULT_SCENE, Path::new("<default scene>"), Path::new("."))?,
    };
    let name = file.as_deref().map_or("cornell".into(), stem);
    let threads: Vec<usize> = (1..=args.threads.min(2)).collect();
    eprintln!("render: {name}, threads {threads:?}");
    let render_rows = scaling::measure_render(
        &loaded.scene,
        &loaded.camera,
        &loaded.settings,
        &[64, 128, 256, 512],
        &threads,
        4,
        |r| {
            eprintln!(
                "  {}x{} {} thread(s): {:.3} s, {:.0} ns/sample",
                r.width, r.height, r.threads, r.seconds, r.ns_per_sample
            )
        },
    )?;
    scaling::write_render_results(&render_rows, &name, &bench::machine_note(), &args.output_dir)?;
    if plot::ENABLED {
        eprintln!(
            "wrote bvh_scaling.csv, bvh_build.png, ray_cost.png, render_scaling.csv, render_scaling.png in {}",
            args.output_dir.display()
        );
    } else {
        eprintln!(
            "wrote bvh_scaling.csv and render_scaling.csv in {} ({PLOTS_DISABLED})",
            args.output_dir.display()
        );
    }
    Ok(())
}

fn rays_command(args: &BenchArgs) -> Result<()> {
    let bunny_path = PathBuf::from("assets/bunny.obj");
    // As the scene loader does: the file's own problem first (it names the
    // path), then what the OBJ reader found, after the path.
    prism::input_file::regular_file(&bunny_path).map_err(|e| {
        anyhow::anyhow!(
            "{e} (the ray benchmark reads the bunny from the repository's assets folder: run it from the repository root)"
        )
    })?;
    let bunny = prism::geometry::Mesh::load_obj(&bunny_path, &prism::geometry::Transform::default())
        .map_err(|e| anyhow::anyhow!("{}: {e}", bunny_path.display()))?;
    let meshes = rays::benchmark_meshes(bunny);
    if let Some(directory) = &args.export_rays {
        rays::export(&meshes, directory)?;
        eprintln!("wrote meshes, rays and Prism's answers to {}", directory.display());
    }
    let (builds, rows) = rays::measure(&meshes, args.repetitions.max(1), |line| eprintln!("{line}"))?;
    rays::write_results(&builds, &rows, &bench::machine_note(), &args.output_dir)?;
    if plot::ENABLED {
        eprintln!("wrote rays.csv, rays_build.csv and rays.png in {}", args.output_dir.display());
    } else {
        eprintln!(
            "wrote rays.csv and rays_build.csv in {} ({PLOTS_DISABLED})",
            args.output_dir.display()
        );
    }
    Ok(())
}

fn throughput_command(args: &BenchArgs) -> Result<()> {
    if !(args.throughput_seconds.is_finite() && args.throughput_seconds > 0.0) {
        bail!("--throughput-seconds must be a positive number");
    }
    let mut rows = Vec::new();
    for file in scene_files(args)? {
        let name = stem(&file);
        let loaded = scene::load_scene_file(&file)?;
        for row in throughput::measure_scene(&name, &loaded, args.throughput_seconds, &[1, 2])? {
            eprintln!(
                "{:<10} {:<7} {} thread(s): {:>6.3} Msamples/s{}",
                row.scene,
                row.integrator.to_string(),
                row.threads,
                row.samples_per_second / 1e6,
                row.photons_per_second
                    .map_or(String::new(), |p| format!(", {:.3} Mphotons/s", p / 1e6))
            );
            rows.push(row);
        }
    }
    throughput::write_results(&rows, &bench::machine_note(), &args.output_dir)?;
    eprintln!("wrote throughput.csv in {}", args.output_dir.display());
    Ok(())
}

fn stress_command(args: &BenchArgs) -> Result<()> {
    let bunny = PathBuf::from("assets/bunny.obj");
    let options = stress::StressOptions {
        width: 128,
        height: 128,
        passes: args.stress_passes,
        rays: args.stress_rays,
        closed_mesh: bunny.exists().then_some(bunny),
        photons_per_iteration: 100_000,
    };
    let rows = stress::run(&options, |r| {
        eprintln!(
            "  {:<32} {:<26} {:>10} tested, {} failures",
            r.scene, r.check, r.tested, r.failures
        )
    })?;
    let path = args.output_dir.join("stress.csv");
    stress::write_results(&rows, &options, &bench::machine_note(), &path)?;
    let failures: u64 = rows.iter().map(|r| r.failures).sum();
    eprintln!("wrote {}; {failures} failures in total", path.display());
    if failures > 0 {
        bail!("{failures} stress failures");
    }
    Ok(())
}

fn sppm_schedules_command(args: &BenchArgs) -> Result<()> {
    if !(1..=1 << 20).contains(&args.max_iterations) {
        bail!("--max-iterations must be between 1 and {}", 1 << 20);
    }
    let ladder = sppm_schedules::iteration_ladder(args.max_iterations);
    let files = if args.scenes.is_empty() {
        vec![PathBuf::from("scenes/caustic.toml")]
    } else {
        args.scenes.clone()
    };
    for file in files {
        let name = stem(&file);
        let loaded = scene::load_scene_file(&file)?;
        let reference_file = error_curves::reference_path(&args.references, &file);
        let reference = load_frame(&reference_file).map_err(|e| anyhow::anyhow!("{e}"))?;
        eprintln!(
            "{name}: SPPM schedules at iterations {ladder:?}, {}x{}, {} photons per iteration",
            reference.width, reference.height, loaded.settings.sppm.photons_per_iteration
        );
        let machine_before = bench::machine_note();
        let rows = sppm_schedules::measure(&loaded, &reference, &ladder, args.seed, |row| {
            eprintln!(
                "  {:<9} {:>6} iterations: RMSE {:.5}, relMSE {:.5}, mean radius {:.4}",
                row.schedule.to_string(),
                row.iterations,
                row.metrics.rmse,
                row.metrics.relative_mse,
                row.mean_radius
            );
        })?;
        let machine = format!("before: {machine_before}; after: {}", bench::machine_note());
        let path = args.output_dir.join(format!("sppm_schedules_{name}.csv"));
        sppm_schedules::csv(&rows, &name, loaded.settings.sppm.photons_per_iteration, args.seed, &machine).write(&path)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
