//! `prism render --part` and `prism merge` as a farm runs them: parts from
//! separate processes merge into the image of one process, `--part auto`
//! reads Slurm's and Kubernetes' variables, and every bad merge (another
//! scene, other settings, overlapping parts, a gap, a truncated, corrupt or
//! foreign file, a folder or a named pipe) fails with an error naming the
//! file and writes nothing.

mod common;
use common::ScratchDir;
use prism::output::load_frame;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Small enough for a debug build: 16×16 pixels, 6 samples, 3 parts.
const SIZE: [&str; 6] = ["--width", "16", "--height", "16", "--spp", "6"];

/// The test's scratch directory, where `prism` runs and writes.
fn scratch(test: &str) -> ScratchDir {
    ScratchDir::new("prism-farm-cli", test)
}

fn prism(folder: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_prism"));
    command.args(args).current_dir(folder);
    // The test's own environment must not choose a part.
    for name in [
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_COUNT",
        "SLURM_ARRAY_TASK_MIN",
        "JOB_COMPLETION_INDEX",
    ] {
        command.env_remove(name);
    }
    command.envs(env.iter().copied()).output().expect("run prism")
}

fn succeeds(folder: &Path, args: &[&str], env: &[(&str, &str)]) {
    let output = prism(folder, args, env);
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// Renders part `part` of the default scene to `name` with `extra` flags
/// (seed 4 unless they give one).
fn part(folder: &Path, name: &str, part: &str, extra: &[&str]) {
    let mut args = vec!["render", "--quiet", "--part", part, "-o", name];
    args.extend(SIZE);
    args.extend(extra);
    if !extra.contains(&"--seed") {
        args.extend(["--seed", "4"]);
    }
    succeeds(folder, &args, &[]);
}

/// The three parts, in the test's own folder.
fn parts(folder: &Path) {
    for k in 0..3 {
        part(folder, &format!("part-{k}.film"), &format!("{k}/3"), &[]);
    }
}

/// Temporary files of outputs named `output` left in the folder.
fn leftovers(folder: &Path, output: &str) -> Vec<String> {
    std::fs::read_dir(folder)
        .expect("folder")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(&format!(".{output}")))
        .collect()
}

/// `prism merge inputs -o out.exr` fails with an error starting `start`,
/// and no image (nor temporary file) is written.
fn refused(folder: &Path, inputs: &[&str], start: &str) {
    let out = format!("refused-{}.exr", std::process::id());
    let mut args = vec!["merge"];
    args.extend(inputs);
    args.extend(["-o", &out]);
    let output = prism(folder, &args, &[]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{inputs:?}: exit 0");
    assert!(stderr.starts_with(start), "{inputs:?}: expected {start:?}…, got {stderr:?}");
    assert!(!folder.join(&out).exists(), "{inputs:?}: an image was written");
    assert_eq!(
        leftovers(folder, &out),
        Vec::<String>::new(),
        "{inputs:?}: temporary files left"
    );
}

#[test]
fn parts_from_separate_processes_merge_into_the_single_process_image() {
    let dir = scratch("parts_from_separate_processes_merge_into_the_single_process_image");
    let folder = dir.path();
    parts(folder);
    let mut single = vec!["render", "--quiet", "--seed", "4", "-o", "single.exr"];
    single.extend(SIZE);
    succeeds(folder, &single, &[]);
    succeeds(
        folder,
        &[
            "merge",
            "part-2.film",
            "part-0.film",
            "part-1.film",
            "-o",
            "merged.exr",
            "--quiet",
        ],
        &[],
    );
    let merged = load_frame(&folder.join("merged.exr")).expect("merged image");
    let single = load_frame(&folder.join("single.exr")).expect("single image");
    assert_eq!(merged.pixels, single.pixels, "merged parts differ from one process");
    // A merge to a film file, merged again, gives the same image.
    succeeds(
        folder,
        &[
            "merge",
            "part-0.film",
            "part-1.film",
            "-o",
            "first-two.film",
            "--allow-missing",
        ],
        &[],
    );
    succeeds(
        folder,
        &["merge", "first-two.film", "part-2.film", "-o", "again.exr", "--quiet"],
        &[],
    );
    let again = load_frame(&folder.join("again.exr")).expect("image");
    assert_eq!(again.pixels, single.pixels, "a merge of merges differs");
}

#[test]
fn part_auto_reads_slurm_and_kubernetes_variables() {
    let dir = scratch("part_auto_reads_slurm_and_kubernetes_variables");
    let folder = dir.path();
    parts(folder);
    let mut args = vec!["render", "--quiet", "--seed", "4", "--part", "auto/3", "-o", "indexed.film"];
    args.extend(SIZE);
    succeeds(folder, &args, &[("JOB_COMPLETION_INDEX", "1")]);
    let read = |name: &str| std::fs::read(folder.join(name)).expect("film file");
    assert!(
        read("indexed.film") == read("part-1.film"),
        "JOB_COMPLETION_INDEX=1 is not part 1/3"
    );
    args[5] = "auto";
    args[7] = "array.film";
    let slurm = [
        ("SLURM_ARRAY_TASK_ID", "7"),
        ("SLURM_ARRAY_TASK_MIN", "5"),
        ("SLURM_ARRAY_TASK_COUNT", "3"),
    ];
    succeeds(folder, &args, &slurm);
    assert!(
        read("array.film") == read("part-2.film"),
        "array task 7 of 5..7 is not part 2/3"
    );
    // Kubernetes does not say how many parts there are.
    let output = prism(folder, &args, &[("JOB_COMPLETION_INDEX", "1")]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success() && stderr.contains("--part auto/N"), "{stderr}");
}

#[test]
fn bad_merges_name_the_file_and_write_nothing() {
    let dir = scratch("bad_merges_name_the_file_and_write_nothing");
    let folder = dir.path();
    parts(folder);
    refused(
        folder,
        &["part-0.film", "part-2.film"],
        "error: parts are missing: samples 2..4 of every row",
    );
    std::fs::copy(folder.join("part-1.film"), folder.join("copy.film")).expect("copy");
    refused(
        folder,
        &["part-0.film", "part-1.film", "copy.film", "part-2.film"],
        "error: copy.film: samples 2..4 of row 0 are also in part-1.film",
    );
    part(folder, "seed.film", "1/3", &["--seed", "5"]);
    refused(
        folder,
        &["part-0.film", "seed.film", "part-2.film"],
        "error: seed.film: not a part of the same image as part-0.film: seed is 4 there but 5 here",
    );
    part(folder, "depth.film", "1/3", &["--max-depth", "3"]);
    refused(
        folder,
        &["part-0.film", "depth.film"],
        "error: depth.film: not a part of the same image as part-0.film: max_depth is 16 there but 3 here",
    );
    let other_scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/diffuse-cornell.toml");
    let mut args = vec!["render", "--quiet", "--seed", "4", "--part", "1/3", "-o", "scene.film"];
    let other_scene = other_scene.display().to_string();
    args.push(&other_scene);
    args.extend(SIZE);
    succeeds(folder, &args, &[]);
    refused(
        folder,
        &["part-0.film", "scene.film", "part-2.film"],
        "error: scene.film: not a part of the same image as part-0.film: scene_hash is",
    );

    let bytes = std::fs::read(folder.join("part-1.film")).expect("part");
    std::fs::write(folder.join("short.film"), &bytes[..bytes.len() / 2]).expect("write");
    refused(
        folder,
        &["part-0.film", "short.film", "part-2.film"],
        "error: short.film: truncated: it ends after",
    );
    let mut flipped = bytes.clone();
    let middle = flipped.len() * 3 / 4;
    flipped[middle] ^= 0x10;
    std::fs::write(folder.join("flipped.film"), &flipped).expect("write");
    refused(
        folder,
        &["part-0.film", "flipped.film", "part-2.film"],
        "error: flipped.film: corrupt: the checksum does not match",
    );
    std::fs::write(folder.join("image.film"), b"\x89PNG\r\n\x1a\n not a film").expect("write");
    refused(
        folder,
        &["part-0.film", "image.film"],
        "error: image.film: not a Prism film file",
    );
    refused(folder, &["part-0.film", "absent.film"], "error: absent.film: no such file");
    std::fs::create_dir(folder.join("folder.film")).expect("create folder");
    refused(
        folder,
        &["part-0.film", "folder.film"],
        "error: folder.film: is a directory, not a file",
    );
    // A named pipe nobody writes to: opening it to read would block the
    // merge for ever, so the merge must refuse it without opening it.
    let pipe = folder.join("pipe.film");
    if Command::new("mkfifo").arg(&pipe).status().is_ok_and(|s| s.success()) {
        let mut merge = Command::new(env!("CARGO_BIN_EXE_prism"))
            .args(["merge", "part-0.film", "pipe.film", "-o", "pipe.exr"])
            .current_dir(folder)
            .stderr(Stdio::piped())
            .spawn()
            .expect("run prism merge");
        let deadline = Instant::now() + Duration::from_secs(60);
        let status = loop {
            if let Some(status) = merge.try_wait().expect("wait for prism merge") {
                break status;
            }
            if Instant::now() > deadline {
                let _ = merge.kill();
                panic!("prism merge of a named pipe did not finish within 60 s");
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        let mut stderr = String::new();
        if let Some(mut pipe_out) = merge.stderr.take() {
            std::io::Read::read_to_string(&mut pipe_out, &mut stderr).expect("read stderr");
        }
        assert!(!status.success(), "merging a named pipe exited 0");
        assert!(stderr.starts_with("error: pipe.film: is not a regular file"), "{stderr:?}");
        assert!(!folder.join("pipe.exr").exists(), "an image was written");
    }
}

#[test]
fn renders_that_cannot_be_split_are_refused_before_rendering() {
    let dir = scratch("renders_that_cannot_be_split_are_refused_before_rendering");
    let folder = dir.path();
    let cases: [(&[&str], &str); 4] = [
        (
            &["--part", "0/2", "-o", "x.png"],
            "error: x.png: a part is written as a film file",
        ),
        (
            &["--part", "0/2", "--integrator", "sppm", "-o", "x.film"],
            "error: SPPM with the per-pixel radius update cannot be split",
        ),
        (
            &["--samples", "4..8", "--adaptive-threshold", "0.1", "-o", "x.film"],
            "error: adaptive sampling cannot render samples 4..8 alone",
        ),
        (
            &["--part", "2/2", "-o", "x.film"],
            "error: --part: part 2 of 2 does not exist",
        ),
    ];
    for (flags, start) in cases {
        let mut args = vec!["render", "--quiet"];
        args.extend(flags);
        let output = prism(folder, &args, &[]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success() && stderr.starts_with(start), "{flags:?}: {stderr}");
        assert!(!folder.join("x.film").exists() && !folder.join("x.png").exists());
    }
    assert_eq!(leftovers(folder, "x."), Vec::<String>::new());
}
