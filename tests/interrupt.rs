//! Interrupts through the real binary (signals sent with `kill`): the first
//! SIGINT or SIGTERM finishes the pass in flight and saves the image so far,
//! with its real pass count in the metadata; a second one exits at once and
//! leaves no file behind.

mod common;
use common::ScratchDir;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The test's scratch directory, for the render's image.
fn scratch(test: &str) -> ScratchDir {
    ScratchDir::new("prism-interrupt", test)
}

/// Starts a long render of the default scene into `dir/out.png`.
fn start(dir: &Path, size: &str) -> Child {
    Command::new(env!("CARGO_BIN_EXE_prism"))
        .args([
            "render",
            "--quiet",
            "--time",
            "600",
            "--threads",
            "2",
            "--width",
            size,
            "--height",
            size,
        ])
        .arg("-o")
        .arg(dir.join("out.png"))
        .stderr(Stdio::piped())
        .spawn()
        .expect("start prism")
}

/// Files in `dir` (the image and any temporary file).
fn files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

/// Waits until the render's temporary output file exists (the signal
/// handler is installed right after it is made), then `settle` longer.
fn wait_until_rendering(dir: &Path, settle: Duration) {
    let deadline = Instant::now() + Duration::from_secs(60);
    while !files(dir).iter().any(|f| f.ends_with(".tmp")) {
        assert!(Instant::now() < deadline, "the render never started");
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(settle);
}

fn kill(child: &Child, signal: &str) {
    let status = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(status.success());
}

/// Waits for exit (at most 2 minutes); returns (exit code, stderr).
fn finish(child: Child) -> (Option<i32>, String) {
    let output = child.wait_with_output().expect("wait");
    (output.status.code(), String::from_utf8_lossy(&output.stderr).into_owned())
}

fn png_text(path: &Path) -> Vec<(String, String)> {
    let file = std::fs::File::open(path).expect("image");
    let reader = png::Decoder::new(std::io::BufReader::new(file)).read_info().expect("png");
    reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .map(|t| (t.keyword.clone(), t.text.clone()))
        .collect()
}

#[test]
fn a_first_sigint_saves_the_passes_so_far() {
    let scratch_dir = scratch("a_first_sigint_saves_the_passes_so_far");
    let dir = scratch_dir.path();
    let child = start(dir, "48");
    wait_until_rendering(dir, Duration::from_millis(1500));
    kill(&child, "-INT");
    let (code, stderr) = finish(child);
    assert_eq!(code, Some(130), "{stderr}");
    assert_eq!(files(dir), vec!["out.png".to_string()], "{stderr}");
    let text = png_text(&dir.join("out.png"));
    let passes: u32 = text
        .iter()
        .find(|(k, _)| k == "Passes")
        .and_then(|(_, v)| v.parse().ok())
        .expect("Passes in the metadata");
    assert!(passes >= 1, "{text:?}");
    assert!(text.contains(&("Interrupted".into(), "SIGINT".into())), "{text:?}");
    assert!(
        stderr.contains(&format!(
            "interrupted by SIGINT: wrote {} with the {passes} passes completed",
            dir.join("out.png").display()
        )),
        "{stderr}"
    );
}

#[test]
fn a_first_sigterm_saves_too() {
    let scratch_dir = scratch("a_first_sigterm_saves_too");
    let dir = scratch_dir.path();
    let child = start(dir, "48");
    wait_until_rendering(dir, Duration::from_millis(1500));
    kill(&child, "-TERM");
    let (code, stderr) = finish(child);
    assert_eq!(code, Some(143), "{stderr}");
    assert_eq!(files(dir), vec!["out.png".to_string()], "{stderr}");
    assert!(png_text(&dir.join("out.png")).contains(&("Interrupted".into(), "SIGTERM".into())));
}

/// The second signal lands while a long pass (a 1200×1200 image) is in
/// flight: the process ends at once, without an image or a temporary file.
#[test]
fn a_second_signal_exits_at_once_leaving_nothing() {
    let scratch_dir = scratch("a_second_signal_exits_at_once_leaving_nothing");
    let dir = scratch_dir.path();
    let child = start(dir, "1200");
    wait_until_rendering(dir, Duration::from_millis(300));
    kill(&child, "-INT");
    std::thread::sleep(Duration::from_millis(300));
    let sent = Instant::now();
    kill(&child, "-INT");
    let (code, stderr) = finish(child);
    assert!(sent.elapsed() < Duration::from_secs(2), "took {:?} to exit", sent.elapsed());
    assert_eq!(code, Some(130), "{stderr}");
    assert!(stderr.contains("quitting without saving"), "{stderr}");
    assert_eq!(files(dir), Vec::<String>::new(), "{stderr}");
}
