//! `prism render`'s flags go through the same validation as a scene file's
//! `[render]` table: every limit is checked before anything is allocated or
//! rendered, and the error names the flag.

mod common;
use common::ScratchDir;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// The test's scratch directory, for the image it must not write.
fn scratch(test: &str) -> ScratchDir {
    ScratchDir::new("prism-cli-limits", test)
}

/// `prism render` of the default scene with `args`.
fn render(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_prism"))
        .arg("render")
        .args(args)
        .output()
        .expect("run prism")
}

/// The command fails with exactly one line starting with `start`, and
/// writes no image.
fn refused(dir: &ScratchDir, args: &[&str], start: &str) {
    let image = dir.join("refused.png");
    let mut all = args.to_vec();
    let image_text = image.display().to_string();
    if !args.contains(&"-o") {
        all.extend(["-o", &image_text]);
    }
    let output = render(&all);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{args:?}: exit 0");
    assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
    assert!(stderr.starts_with(start), "{args:?}: expected {start:?}…, got {stderr:?}");
    assert!(!image.exists(), "{args:?}: an image was written");
}

#[test]
fn image_size_is_checked_before_allocating() {
    let dir = scratch("image_size_is_checked_before_allocating");
    refused(
        &dir,
        &["--width", "100000", "--height", "100000"],
        "error: --width: must be at most 65536 pixels",
    );
    // 15000² pixels with SPPM need ~144 GB: refused with the estimate.
    refused(
        &dir,
        &["--width", "15000", "--height", "15000", "--integrator", "sppm"],
        "error: --width: a 15000×15000 image with sppm needs about 144.0 GB of memory, more than the",
    );
}

/// The 15000×15000 path-traced image needs about 27 GB (45 GB with
/// the light-traced caustics the default scene's glass ball gets): refused
/// wherever that much is not available. Where it is, the render would run
/// (correctly), so the test does not start it.
#[test]
fn fifteen_thousand_squared_is_refused_where_it_cannot_fit() {
    use prism::settings::validate::{LIGHT_PATH_BYTES_PER_PIXEL, PATH_TRACING_BYTES_PER_PIXEL};
    let dir = scratch("fifteen_thousand_squared_is_refused_where_it_cannot_fit");
    let available = prism::settings::validate::available_memory();
    for (light_paths, bytes, size) in [
        ("false", PATH_TRACING_BYTES_PER_PIXEL, "27.0 GB"),
        ("true", PATH_TRACING_BYTES_PER_PIXEL + LIGHT_PATH_BYTES_PER_PIXEL, "45.0 GB"),
    ] {
        match available {
            Some(available) if available < 15_000u64 * 15_000 * bytes => refused(
                &dir,
                &["--width", "15000", "--height", "15000", "--caustic-light-paths", light_paths],
                &format!("error: --width: a 15000×15000 image with pt needs about {size} of memory"),
            ),
            _ => eprintln!("skipped: this machine has room for a {size} render"),
        }
    }
}

#[test]
fn thread_count_exposure_and_time_have_documented_ranges() {
    let dir = scratch("thread_count_exposure_and_time_have_documented_ranges");
    refused(
        &dir,
        &["--threads", "0"],
        "error: --threads: must be between 1 and 256 (found 0)",
    );
    refused(
        &dir,
        &["--threads", "10000"],
        "error: --threads: must be between 1 and 256 (found 10000)",
    );
    refused(
        &dir,
        &["--exposure", "nan"],
        "error: --exposure: must be a finite number of stops",
    );
    refused(
        &dir,
        &["--exposure", "inf"],
        "error: --exposure: must be a finite number of stops",
    );
    refused(
        &dir,
        &["--time", "1e30"],
        "error: --time: must be a number of seconds above 0",
    );
    refused(
        &dir,
        &["--max-depth", "2147483647"],
        "error: --max-depth: must be at most 1024",
    );
}

#[test]
fn negative_numbers_get_the_range_not_a_clap_tip() {
    let dir = scratch("negative_numbers_get_the_range_not_a_clap_tip");
    refused(
        &dir,
        &["--radius", "-1"],
        "error: --radius: must be between 1e-12 and 1e12 scene units (found -1)",
    );
    refused(
        &dir,
        &["--alpha", "-0.5"],
        "error: --alpha: must be strictly between 0 and 1 (found -0.5)",
    );
    refused(
        &dir,
        &["--adaptive-threshold", "-1"],
        "error: --adaptive-threshold: must be a positive finite number",
    );
}

/// `--time 5 -o missing/dir/x.png` used to render for 5 s, then fail.
#[test]
fn the_output_is_checked_before_rendering() {
    let dir = scratch("the_output_is_checked_before_rendering");
    let started = Instant::now();
    refused(
        &dir,
        &["--time", "5", "-o", "missing/dir/x.png"],
        "error: missing/dir/x.png: cannot write image: folder missing/dir does not exist",
    );
    refused(
        &dir,
        &["--time", "5", "-o", "x.tiff"],
        "error: x.tiff: unsupported image format",
    );
    let folder = dir.join("a-folder.png");
    std::fs::create_dir_all(&folder).expect("folder");
    let folder_text = folder.display().to_string();
    refused(
        &dir,
        &["--time", "5", "-o", &folder_text],
        &format!("error: {folder_text}: cannot write image: is a directory"),
    );
    // A folder without an image extension: the folder is the mistake.
    let folder_text = dir.path().display().to_string();
    refused(
        &dir,
        &["--time", "5", "-o", &folder_text],
        &format!("error: {folder_text}: cannot write image: is a directory"),
    );
    assert!(started.elapsed() < Duration::from_secs(4), "rendered before failing");
}

/// `--version` names the build as well as the version: a farm's operator
/// checks it to know which machines a binary runs on and how fast.
#[test]
fn the_version_names_the_build() {
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .arg("--version")
        .output()
        .expect("run prism");
    assert!(output.status.success());
    let text = String::from_utf8_lossy(&output.stdout);
    let expected = format!(
        "prism {} ({} build for ",
        env!("CARGO_PKG_VERSION"),
        if cfg!(debug_assertions) { "debug" } else { "release" }
    );
    assert!(text.starts_with(&expected), "{text:?} should start with {expected:?}");
}
