//! Caustics traced from the lights (`caustic_light_paths`, on by default): the path tracer
//! and the light tracer split path space between them, so the image they
//! make together must have the expected value of path tracing alone, region
//! by region, through a pinhole and through a lens; it must be the same
//! bits on any thread count; and farm parts must merge into the image of
//! one process.

mod common;
use common::{Job, ScratchDir, render, scene};
use prism::scene::LoadedScene;
use std::process::Command;

/// A glass ball on a diffuse floor in front of a diffuse wall, lit by a
/// quad light above and to the side: its caustic falls on the floor in
/// view, and the wall sees the caustic too. The light is large enough that
/// camera paths hit it through the ball often: with a small one their
/// estimate is heavy-tailed, its rare bright samples missing from most runs
/// of a test's size, and its mean (and spread) come out low.
fn caustic_scene(camera_extra: &str, render_extra: &str) -> String {
    format!(
        r#"
[camera]
position = [0, 2.2, -3.2]
look_at = [0, 0.3, 0]
fov_y_degrees = 45
{camera_extra}

[render]
max_depth = 8
{render_extra}

[materials.white]
type = "diffuse"
albedo = [0.8, 0.8, 0.8]

[materials.glass]
type = "glass"
ior = 1.5

[materials.light]
type = "emissive"
radiance = [4, 3, 2]

[[objects]]
type = "quad"
corner = [-2, 0, -2]
edge_u = [0, 0, 4]
edge_v = [4, 0, 0]
material = "white"

[[objects]]
type = "quad"
corner = [-2, 0, 1.5]
edge_u = [4, 0, 0]
edge_v = [0, 3, 0]
material = "white"

[[objects]]
type = "sphere"
center = [0, 0.7, 0]
radius = 0.5
material = "glass"

[[objects]]
type = "quad"
corner = [0.4, 3, -0.8]
edge_u = [1.5, 0, 0]
edge_v = [0, 0, 1.5]
material = "light"
"#
    )
}

const WIDTH: u32 = 24;
const HEIGHT: u32 = 18;
/// The image in 3 × 3 blocks of 8 × 6 pixels.
const BLOCKS: usize = 3;

/// Per-block, per-channel means over independent renders (seeds 1..=runs):
/// their mean and standard error.
fn block_means(loaded: &LoadedScene, spp: u32, runs: u64) -> Vec<([f64; 3], [f64; 3])> {
    let per_run: Vec<Vec<[f64; 3]>> = (1..=runs)
        .map(|seed| {
            let job = Job {
                width: WIDTH,
                height: HEIGHT,
                spp,
                seed,
                max_depth: 8,
                ..Job::default()
            };
            let frame = render(loaded, &job);
            let mut sums = vec![[0.0; 3]; BLOCKS * BLOCKS];
            for (i, pixel) in frame.pixels.iter().enumerate() {
                let (x, y) = (i % WIDTH as usize, i / WIDTH as usize);
                let block = (y * BLOCKS / HEIGHT as usize) * BLOCKS + x * BLOCKS / WIDTH as usize;
                for c in 0..3 {
                    sums[block][c] += pixel[c] as f64;
                }
            }
            let per_block = (WIDTH * HEIGHT) as f64 / (BLOCKS * BLOCKS) as f64;
            sums.iter().map(|s| s.map(|v| v / per_block)).collect()
        })
        .collect();
    let n = runs as f64;
    (0..BLOCKS * BLOCKS)
        .map(|block| {
            let mut mean = [0.0; 3];
            let mut error = [0.0; 3];
            for c in 0..3 {
                mean[c] = per_run.iter().map(|r| r[block][c]).sum::<f64>() / n;
                let variance = per_run.iter().map(|r| (r[block][c] - mean[c]).powi(2)).sum::<f64>() / (n - 1.0);
                error[c] = (variance / n).sqrt();
            }
            (mean, error)
        })
        .collect()
}

/// Path tracing alone and path tracing with light-traced caustics agree in
/// every block and channel within 4 combined standard errors (27
/// comparisons: a false alarm once in ~600 runs); the comparison is sharp
/// (the light-traced image's error under 5% of every block's mean), and
/// the light-traced estimate has the smaller spread in the blocks that
/// hold the caustic (it is the point of tracing it from the light).
fn assert_agrees_with_path_tracing(camera_extra: &str) {
    let plain = scene(&caustic_scene(camera_extra, "caustic_light_paths = false"));
    let traced = scene(&caustic_scene(camera_extra, ""));
    let path_tracing = block_means(&plain, 48, 10);
    let light_paths = block_means(&traced, 48, 10);
    let mut less_noisy = 0;
    for (block, ((pt, pt_error), (lt, lt_error))) in path_tracing.iter().zip(&light_paths).enumerate() {
        eprintln!("block {block}: path tracing {pt:.4?} ± {pt_error:.4?}, with light paths {lt:.4?} ± {lt_error:.4?}");
        for c in 0..3 {
            let combined = (pt_error[c].powi(2) + lt_error[c].powi(2)).sqrt();
            assert!(
                (pt[c] - lt[c]).abs() < 4.0 * combined,
                "block {block} channel {c}: path tracing {} ± {}, with light paths {} ± {}",
                pt[c],
                pt_error[c],
                lt[c],
                lt_error[c]
            );
            assert!(
                lt[c] > 0.01 && lt_error[c] < 0.05 * lt[c],
                "block {block}: {lt:?} ± {lt_error:?}"
            );
        }
        if lt_error[0] < 0.5 * pt_error[0] {
            less_noisy += 1;
        }
    }
    assert!(less_noisy >= 2, "light paths halved the spread in only {less_noisy} blocks");
}

#[test]
fn light_traced_caustics_agree_with_path_tracing_through_a_pinhole() {
    assert_agrees_with_path_tracing("");
}

#[test]
fn light_traced_caustics_agree_with_path_tracing_through_a_lens() {
    assert_agrees_with_path_tracing("aperture_radius = 0.15\nfocal_distance = 2.5");
}

#[test]
fn light_traced_caustics_are_the_same_on_any_thread_count() {
    let traced = scene(&caustic_scene("", ""));
    let job = |threads| Job {
        width: 40,
        height: 30,
        spp: 3,
        threads: Some(threads),
        ..Job::default()
    };
    let one = render(&traced, &job(1));
    let three = render(&traced, &job(3));
    assert_eq!(one.pixels, three.pixels);
    // And the light paths did something: the image differs from path tracing's.
    let plain = render(&scene(&caustic_scene("", "caustic_light_paths = false")), &job(1));
    assert_ne!(one.pixels, plain.pixels);
}

/// `prism render --part K/N` with light-traced caustics, merged, is the
/// image of one process, bit for bit; a part without them does not merge
/// with parts that have them.
#[test]
fn farm_parts_with_light_traced_caustics_merge_into_the_single_process_image() {
    let dir = ScratchDir::new(
        "prism-caustic-farm",
        "farm_parts_with_light_traced_caustics_merge_into_the_single_process_image",
    );
    let folder = dir.path();
    let scene_path = folder.join("caustic.toml");
    std::fs::write(&scene_path, caustic_scene("", "")).expect("scene written");
    let run = |args: &[&str]| {
        let output = Command::new(env!("CARGO_BIN_EXE_prism"))
            .args(args)
            .current_dir(folder)
            .output()
            .expect("prism runs");
        (output.status.success(), String::from_utf8_lossy(&output.stderr).to_string())
    };
    let scene_arg = scene_path.to_str().expect("UTF-8 path");
    let common = ["--width", "20", "--height", "16", "--spp", "5", "--seed", "3", "--quiet"];
    let traced = "--caustic-light-paths=true";
    let render_to = |output: &str, extra: &[&str]| {
        let mut args = vec!["render", scene_arg, "-o", output];
        args.extend(common);
        args.extend(extra);
        let (ok, stderr) = run(&args);
        assert!(ok, "{args:?}: {stderr}");
    };
    render_to("single.exr", &[traced]);
    for k in 0..3 {
        render_to(&format!("part-{k}.film"), &[traced, "--part", &format!("{k}/3")]);
    }
    let (ok, stderr) = run(&["merge", "part-2.film", "part-0.film", "part-1.film", "-o", "merged.exr"]);
    assert!(ok, "{stderr}");
    let single = prism::output::load_frame(&folder.join("single.exr")).expect("single image");
    let merged = prism::output::load_frame(&folder.join("merged.exr")).expect("merged image");
    assert_eq!(merged.pixels, single.pixels, "merged parts differ from one process");

    // A part rendered without light paths is a part of another image.
    render_to("plain.film", &["--caustic-light-paths=false", "--part", "0/3"]);
    let (ok, stderr) = run(&["merge", "plain.film", "part-1.film", "-o", "bad.exr"]);
    assert!(!ok, "parts with and without light paths merged");
    assert!(stderr.contains("caustic_light_paths"), "{stderr}");
}

/// Where light paths can find nothing, nothing changes: the bunny and the
/// earth scenes have no mirror or glass, and render the same bits either way.
#[test]
fn scenes_without_caustics_to_trace_are_unchanged() {
    for name in ["earth.toml", "bunny.toml"] {
        let loaded = common::shipped_scene(name);
        let job = |caustic_light_paths| Job {
            width: 24,
            height: 18,
            spp: 2,
            caustic_light_paths: Some(caustic_light_paths),
            ..Job::default()
        };
        assert_eq!(
            render(&loaded, &job(true)).pixels,
            render(&loaded, &job(false)).pixels,
            "{name}"
        );
    }
}
