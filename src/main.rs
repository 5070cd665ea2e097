//! The `prism` command: subcommands over the library. `anyhow` lives only here.

mod bench_command;
mod interrupt;
mod merge_command;

use anyhow::{Context, Result, bail};
use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use prism::farm::file::PendingFilm;
use prism::farm::{FilmHeader, PartRequest, content_hash, is_film_path, plan_share};
use prism::film::ToneMap;
use prism::integrator::{self, Share};
use prism::output::PendingImage;
use prism::render::{IntegratorKind, ProgressiveRender, RenderSettings};
use prism::sampler::SamplerKind;
use prism::scene::{self, LoadedScene};
use prism::settings::validate::{self, available_memory};
use prism::settings::{RadiusSchedule, Setting, SettingsPatch};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::LazyLock;
use std::sync::atomic::AtomicBool;

#[derive(Parser)]
#[command(name = "prism", version, about = "A physically based renderer you watch converge")]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene headless to an image file (PNG, BMP, PPM or EXR), or a
    /// part of it to a film file (.film) for `prism merge` (see docs/farm.md).
    Render(RenderArgs),
    /// Merge film files (parts of one render) into an image or a film file.
    Merge(merge_command::MergeArgs),
    /// Measure error against time, rays and samples per second, scaling, or numerical stress
    /// (see docs/benchmarks.md and docs/performance.md).
    Bench(bench_command::BenchArgs),
    /// Open the interactive viewer on a scene (the default scene if omitted).
    View {
        /// Scene file (TOML).
        scene: Option<PathBuf>,
        /// Instead of rendering, show the merge of the film files in this
        /// folder as a farm writes them (parts done, samples, noise).
        #[arg(long, value_name = "DIR", conflicts_with = "scene")]
        watch: Option<PathBuf>,
    },
}

/// Numbers may be negative (`--radius -1`), so a bad value gets Prism's range
/// message rather than clap's "unexpected argument" tip.
#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
struct RenderArgs {
    /// Scene file (TOML); the embedded default scene if omitted.
    scene: Option<PathBuf>,
    /// Output image; the format follows the extension (.png .bmp .ppm .exr),
    /// or .film for a film file (exact sums, for `prism merge`).
    #[arg(short, long, default_value = "prism.png")]
    output: PathBuf,
    /// Samples per pixel (path tracing) or iterations (SPPM).
    #[arg(long, conflicts_with = "time", visible_alias = "iterations")]
    spp: Option<u32>,
    /// Render part K of N (K/N, 0-based) of the --spp samples to a .film
    /// file; `auto` takes K and N from a Slurm job array, `auto/N` takes K
    /// from a Kubernetes Indexed Job (docs/farm.md).
    #[arg(long, value_name = "K/N", conflicts_with_all = ["time", "samples"])]
    part: Option<String>,
    /// Render sample indices (SPPM: iterations) A..B to a .film file.
    #[arg(long, value_name = "A..B", conflicts_with = "time")]
    samples: Option<String>,
    /// Render for this many seconds instead of a sample count.
    #[arg(long)]
    time: Option<f64>,
    /// Image width in pixels (default: the scene's).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (default: the scene's).
    #[arg(long)]
    height: Option<u32>,
    /// Worker threads, 1 to 256 (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// The same scene, seed and sample count give the same image on any thread count.
    #[arg(long)]
    seed: Option<u64>,
    /// sobol (Owen-scrambled Sobol', default) or random (independent).
    #[arg(long, value_parser = parse_sampler)]
    sampler: Option<SamplerKind>,
    /// pt (NEE + MIS), pt-bsdf (BSDF sampling only) or sppm.
    #[arg(long, value_parser = parse_integrator)]
    integrator: Option<IntegratorKind>,
    /// Maximum number of bounces, 1 to 1024.
    #[arg(long)]
    max_depth: Option<u32>,
    /// Adaptive sampling: stop sampling a pixel once its standard error /
    /// max(mean luminance, 0.01) is below this (e.g. 0.02).
    #[arg(long)]
    adaptive_threshold: Option<f64>,
    /// Spectral transport: 4 hero wavelengths per path instead of RGB
    /// (scenes with dispersive glass are spectral anyway).
    #[arg(long)]
    spectral: bool,
    /// Path tracing: trace caustics (light focused by mirrors and glass onto
    /// what the camera sees) from the lights and connect them to the lens,
    /// and reach lights seen in mirror balls from the lens too (`true`, the
    /// default), or leave them to camera paths (`false`).
    #[arg(long, value_name = "true|false")]
    caustic_light_paths: Option<bool>,
    /// SPPM: photons traced per iteration.
    #[arg(long)]
    photons: Option<u32>,
    /// SPPM: initial gather radius in scene units (default: from the pixel footprint).
    #[arg(long)]
    radius: Option<f64>,
    /// SPPM: fraction of each iteration's photons kept, in (0, 1) (default 2/3).
    #[arg(long)]
    alpha: Option<f64>,
    /// SPPM: per-pixel (default) or global (Knaus & Zwicker; splittable across machines).
    #[arg(long, value_parser = parse_radius_schedule)]
    radius_schedule: Option<RadiusSchedule>,
    /// Exposure in stops, -64 to 64 (display only; EXR output is scaled too).
    #[arg(long, default_value_t = 0.0)]
    exposure: f64,
    /// clamp, reinhard or filmic (8-bit outputs only).
    #[arg(long, default_value = "clamp", value_parser = parse_tone_map)]
    tone_map: ToneMap,
    /// Do not draw a progress bar.
    #[arg(long)]
    quiet: bool,
}

fn parse_sampler(s: &str) -> Result<SamplerKind, String> {
    match s {
        "sobol" => Ok(SamplerKind::Sobol),
        "random" => Ok(SamplerKind::Random),
        _ => Err("expected sobol or random".into()),
    }
}

pub(crate) fn parse_integrator(s: &str) -> Result<IntegratorKind, String> {
    IntegratorKind::ALL
        .into_iter()
        .find(|k| k.name() == s)
        .ok_or_else(|| "expected pt, pt-bsdf or sppm".into())
}

fn parse_radius_schedule(s: &str) -> Result<RadiusSchedule, String> {
    RadiusSchedule::ALL
        .into_iter()
        .find(|k| k.name() == s)
        .ok_or_else(|| "expected per-pixel or global".into())
}

fn parse_tone_map(s: &str) -> Result<ToneMap, String> {
    match s {
        "clamp" => Ok(ToneMap::Clamp),
        "reinhard" => Ok(ToneMap::Reinhard),
        "filmic" => Ok(ToneMap::Filmic),
        _ => Err("expected clamp, reinhard or filmic".into()),
    }
}

/// `prism --version`: the package version and how this binary was built
/// (instruction set, profile-guided or not), which decides its speed and
/// which machines of a farm it runs on.
static VERSION: LazyLock<String> = LazyLock::new(|| format!("{} ({})", env!("CARGO_PKG_VERSION"), prism::bench::build_note()));

fn main() -> ExitCode {
    let matches = Cli::command().version(VERSION.as_str()).get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|error| error.exit());
    let result = match cli.command {
        Some(Command::Render(args)) => render_command(args),
        Some(Command::Merge(args)) => merge_command::merge_command(args).map(|()| RenderEnd::Completed),
        Some(Command::Bench(args)) => bench_command::bench_command(args).map(|()| RenderEnd::Completed),
        Some(Command::View { watch: Some(folder), .. }) => watch_command(folder).map(|()| RenderEnd::Completed),
        Some(Command::View { scene, .. }) => view_command(scene).map(|()| RenderEnd::Completed),
        None => view_command(None).map(|()| RenderEnd::Completed),
    };
    match result {
        Ok(RenderEnd::Completed) => ExitCode::SUCCESS,
        // The shell's convention for "ended by signal N", though the image was saved.
        Ok(RenderEnd::Interrupted(signal)) => ExitCode::from(128 + signal as u8),
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}

/// How a command that ran to its end ended.
enum RenderEnd {
    Completed,
    /// Stopped early by this signal, with the image so far saved.
    Interrupted(i32),
}

/// Opens the viewer on a folder of film files.
#[cfg(feature = "viewer")]
fn watch_command(folder: PathBuf) -> Result<()> {
    if !folder.is_dir() {
        bail!("{}: no such folder", folder.display());
    }
    prism::viewer::run_watch(folder)?;
    Ok(())
}

#[cfg(not(feature = "viewer"))]
fn watch_command(_folder: PathBuf) -> Result<()> {
    bail!("this prism was built without the viewer (cargo feature `viewer`); merge the parts with `prism merge` instead")
}

/// Opens the viewer; without a display it says how to render headless instead.
#[cfg(feature = "viewer")]
fn view_command(scene: Option<PathBuf>) -> Result<()> {
    let start = prism::viewer::ViewerStart {
        scene,
        ..Default::default()
    };
    prism::viewer::run(start)?;
    Ok(())
}

/// A headless build (without the `viewer` feature) has no viewer to open.
#[cfg(not(feature = "viewer"))]
fn view_command(_scene: Option<PathBuf>) -> Result<()> {
    anyhow::bail!(
        "this prism was built without the viewer (cargo feature `viewer`); \
         render headless with `prism render`, or rebuild with the default features to get the viewer"
    )
}

fn load(scene: Option<&Path>) -> Result<LoadedScene> {
    Ok(match scene {
        Some(path) => scene::load_scene_file(path)?,
        None => scene::load_scene_str(scene::DEFAULT_SCENE, Path::new("<default scene>"), Path::new("."))?,
    })
}

/// The command line's settings, through the same validation as a scene
/// file's `[render]` table; errors name the flag.
fn apply_overrides(settings: &mut RenderSettings, args: &RenderArgs) -> Result<()> {
    let patch = SettingsPatch {
        width: args.width,
        height: args.height,
        spp: args.spp,
        max_depth: args.max_depth,
        integrator: args.integrator,
        sampler: args.sampler,
        seed: args.seed,
        photons_per_iteration: args.photons,
        initial_radius: args.radius,
        alpha: args.alpha,
        radius_schedule: args.radius_schedule,
        adaptive_threshold: args.adaptive_threshold,
        spectral: args.spectral.then_some(true),
        caustic_light_paths: args.caustic_light_paths,
        time_seconds: args.time,
    };
    patch.apply_to(settings)?;
    settings.check_memory(available_memory()).map_err(|mut error| {
        // Name the flag that made the image too large.
        error.setting = match (args.width, args.height, args.integrator) {
            (None, Some(_), _) => Setting::Height,
            (None, None, Some(_)) => Setting::Integrator,
            _ => Setting::Width,
        };
        error
    })?;
    Ok(())
}

/// Where `prism render` writes: an image, or a film file.
enum Output {
    Image(PendingImage),
    Film(PendingFilm),
}

impl Output {
    fn temporary_path(&self) -> &Path {
        match self {
            Output::Image(image) => image.temporary_path(),
            Output::Film(film) => film.temporary_path(),
        }
    }
}

/// What `--part` or `--samples` asked for, if anything.
fn part_request(args: &RenderArgs) -> Result<Option<PartRequest>> {
    Ok(match (&args.part, &args.samples) {
        (Some(part), _) => Some(PartRequest::parse_part(part, |name| std::env::var(name).ok())?),
        (None, Some(samples)) => Some(PartRequest::parse_samples(samples)?),
        (None, None) => None,
    })
}

fn render_command(args: RenderArgs) -> Result<RenderEnd> {
    validate::exposure(args.exposure)?;
    let threads = match args.threads {
        Some(threads) => validate::thread_count(threads)?,
        None => std::thread::available_parallelism().map_or(1, |n| n.get().min(validate::MAX_THREADS)),
    };
    let request = part_request(&args)?;
    if request.is_some() && !is_film_path(&args.output) {
        bail!(
            "{}: a part is written as a film file, so that parts merge exactly: give -o NAME.film",
            args.output.display()
        );
    }
    // The output is checked, and its temporary file made, before any work.
    let output = if is_film_path(&args.output) {
        Output::Film(PendingFilm::create(&args.output)?)
    } else {
        Output::Image(PendingImage::create(&args.output)?)
    };
    let interrupt = interrupt::Interrupt::install(output.temporary_path())?;
    let loaded = load(args.scene.as_deref())?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let mut settings = loaded.settings.clone();
    apply_overrides(&mut settings, &args)?;
    let share = match &request {
        Some(request) => plan_share(&settings, request)?,
        None => Share::whole(settings.samples_per_pixel.unwrap_or(0)),
    };
    if matches!(output, Output::Film(_)) && integrator::create_share(&settings, &Share::whole(0)).film().is_none() {
        bail!(
            "{}: SPPM with the per-pixel radius update keeps no film to write; use --radius-schedule global",
            args.output.display()
        );
    }
    // The driver's target is the share's passes (a whole render's, or a part's).
    let driver_settings = RenderSettings {
        samples_per_pixel: settings.samples_per_pixel.map(|_| share.passes()),
        ..settings.clone()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("cannot start worker threads")?;

    let bar = progress_bar(&driver_settings, args.quiet);
    let pixels = settings.pixel_count() as f64;
    let cancel = AtomicBool::new(false);
    let started = std::time::Instant::now();
    let mut render = ProgressiveRender::with_integrator(integrator::create_share(&settings, &share), &driver_settings);
    if driver_settings.samples_per_pixel != Some(0) {
        pool.install(|| {
            render.run(&loaded.scene, &loaded.camera, &cancel, |render| {
                let progress = render.progress();
                let rate = pixels * progress.passes as f64 / progress.elapsed.as_secs_f64().max(1e-9);
                match settings.time_limit {
                    Some(_) => bar.set_position(progress.elapsed.as_millis() as u64),
                    None => bar.set_position(progress.passes as u64),
                }
                let status = render.integrator().status();
                bar.set_message(format!("{} passes, {:.2} Msamples/s {status}", progress.passes, rate / 1e6));
                // A first SIGINT or SIGTERM ends the render here, between passes.
                match interrupt.received() {
                    Some(_) => ControlFlow::Break(()),
                    None => ControlFlow::Continue(()),
                }
            })
        });
    } else {
        eprintln!(
            "warning: this part's share of {} samples is empty",
            settings.samples_per_pixel.unwrap_or(0)
        );
    }
    let interrupted = interrupt.received();
    let integrator = render.integrator();
    bar.finish_and_clear();

    let scene_name = args
        .scene
        .as_ref()
        .map_or("<default scene>".into(), |p| p.display().to_string());
    let (width, height, written) = match output {
        Output::Film(pending) => {
            // What the passes covered: all of the share once it is done (an
            // adaptive render that stopped early has converged: the samples
            // it skipped would have been skipped anyway); less if interrupted.
            let done = if render.is_finished() && settings.time_limit.is_none() {
                share.clone()
            } else {
                Share {
                    samples: share.samples.start..share.samples.start + integrator.passes(),
                    ..share.clone()
                }
            };
            let target = match &request {
                Some(PartRequest::Samples(_)) => None,
                _ => settings.samples_per_pixel,
            };
            let hash = content_hash::scene_hash(&loaded.scene, &loaded.camera);
            let header = FilmHeader::new(&scene_name, &settings, &hash, &done, target);
            let film = integrator.film().context("this integrator keeps no film")?;
            pending.save(&header, film)?;
            let rows = if done.rows.is_all() {
                "every row".to_string()
            } else {
                format!("every {} row from row {}", ordinal(done.rows.step), done.rows.first)
            };
            (
                film.width,
                film.height,
                format!("samples {}..{} of {rows}", done.samples.start, done.samples.end),
            )
        }
        Output::Image(pending) => {
            let frame = integrator.frame();
            let mut metadata = vec![
                ("Software".to_string(), format!("prism {}", env!("CARGO_PKG_VERSION"))),
                ("Scene".to_string(), scene_name),
                ("Integrator".to_string(), settings.integrator.to_string()),
                ("Passes".to_string(), integrator.passes().to_string()),
                ("Seed".to_string(), settings.seed.to_string()),
                ("RenderSeconds".to_string(), format!("{:.3}", started.elapsed().as_secs_f64())),
                ("Sampler".to_string(), settings.sampler.to_string()),
            ];
            if let Some(signal) = interrupted {
                metadata.push(("Interrupted".to_string(), interrupt::name(signal).to_string()));
            }
            pending.save(&frame, args.exposure, args.tone_map, &metadata)?;
            (
                frame.width,
                frame.height,
                format!("{} passes of {}", integrator.passes(), settings.integrator),
            )
        }
    };
    // From here a second signal has nothing left to protect.
    interrupt.uninstall();
    if integrator.rejected_samples() > 0 {
        eprintln!(
            "warning: {} samples were NaN, infinite or beyond {:e} and were dropped",
            integrator.rejected_samples(),
            prism::film::MAX_SAMPLE_VALUE
        );
    }
    let target = driver_settings
        .samples_per_pixel
        .map_or(String::new(), |spp| format!(" of {spp}"));
    if let Some(signal) = interrupted {
        eprintln!(
            "interrupted by {}: wrote {} with the {}{target} passes completed",
            interrupt::name(signal),
            args.output.display(),
            integrator.passes(),
        );
        return Ok(RenderEnd::Interrupted(signal));
    }
    if !args.quiet {
        eprintln!(
            "wrote {} ({width}x{height}, {written}{})",
            args.output.display(),
            if integrator.converged() {
                "; adaptive sampling stopped every pixel"
            } else {
                ""
            }
        );
    }
    Ok(RenderEnd::Completed)
}

/// "2nd", "3rd", "7th": for "every 3rd row".
fn ordinal(n: u32) -> String {
    let suffix = match (n % 10, n % 100) {
        (1, 11) | (2, 12) | (3, 13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{n}{suffix}")
}

fn progress_bar(settings: &RenderSettings, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let (length, template) = match (settings.time_limit, settings.samples_per_pixel) {
        (Some(limit), _) => (limit.as_millis() as u64, "{bar:40} {elapsed_precise} / ETA {eta} {msg}"),
        (None, Some(spp)) => (spp as u64, "{bar:40} {pos}/{len} spp, ETA {eta} {msg}"),
        (None, None) => (u64::MAX, "{elapsed_precise} {msg}"),
    };
    let bar = ProgressBar::new(length);
    if let Ok(style) = ProgressStyle::with_template(template) {
        bar.set_style(style);
    }
    bar
}
