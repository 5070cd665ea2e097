//! `prism merge`: argument handling and messages only; the checks and the
//! merge itself live in the library's `farm` module.

use anyhow::Result;
use clap::Args;
use prism::farm::file::PendingFilm;
use prism::farm::{MergeOptions, is_film_path, merge_files};
use prism::film::ToneMap;
use prism::output::PendingImage;
use prism::settings::validate;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Film files written by `prism render --part` or `--samples` (or by earlier merges).
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// Output: an image (.png .bmp .ppm .exr) or a film file (.film) to merge again later.
    #[arg(short, long)]
    output: PathBuf,
    /// Merge the parts that are there even if samples are missing, saying how many it holds.
    #[arg(long)]
    allow_missing: bool,
    /// Exposure in stops, -64 to 64 (images only).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    exposure: f64,
    /// clamp, reinhard or filmic (8-bit images only).
    #[arg(long, default_value = "clamp", value_parser = super::parse_tone_map)]
    tone_map: ToneMap,
    /// Print nothing on success.
    #[arg(long)]
    quiet: bool,
}

pub fn merge_command(args: MergeArgs) -> Result<()> {
    validate::exposure(args.exposure)?;
    // The output is checked (and its temporary file made) before any reading;
    // on any error below it is removed, so nothing is written.
    enum Output {
        Image(PendingImage),
        Film(PendingFilm),
    }
    let output = if is_film_path(&args.output) {
        Output::Film(PendingFilm::create(&args.output)?)
    } else {
        Output::Image(PendingImage::create(&args.output)?)
    };
    let started = std::time::Instant::now();
    let merged = merge_files(
        &args.parts,
        MergeOptions {
            allow_missing: args.allow_missing,
        },
    )?;
    match output {
        Output::Film(pending) => pending.save(&merged.header, &merged.film)?,
        Output::Image(pending) => {
            let image = &merged.header.image;
            let mut metadata = vec![
                ("Software".to_string(), format!("prism {}", env!("CARGO_PKG_VERSION"))),
                ("Scene".to_string(), merged.header.scene.clone()),
                ("Samples".to_string(), merged.samples_held.to_string()),
            ];
            for (name, key) in [
                ("Integrator", "integrator"),
                ("Sampler", "sampler"),
                ("Seed", "seed"),
                ("SceneHash", "scene_hash"),
            ] {
                if let Some(value) = image.get(key) {
                    metadata.push((name.to_string(), value.clone()));
                }
            }
            pending.save(&merged.film.frame(), args.exposure, args.tone_map, &metadata)?;
        }
    }
    let percent = 100.0 * merged.samples_held as f64 / merged.samples_expected.max(1) as f64;
    if !merged.missing.is_empty() {
        eprintln!(
            "merged {} parts into {}: {} of {} samples ({percent:.1}%); missing: {}",
            args.parts.len(),
            args.output.display(),
            merged.samples_held,
            merged.samples_expected,
            merged.missing
        );
    } else if !args.quiet {
        eprintln!(
            "merged {} parts into {} ({}x{}, {} samples, {:.2} s)",
            args.parts.len(),
            args.output.display(),
            merged.film.width,
            merged.film.height,
            merged.samples_held,
            started.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
