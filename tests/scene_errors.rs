//! Bad scenes give one clear line naming file, line and field, a non-zero
//! exit code, and no panic.

use std::path::PathBuf;
use std::process::Command;

const GOOD: &str = r#"[camera]
position = [0, 0, 5]
look_at = [0, 0, 0]

[materials.white]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
"#;

fn write_scene(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("prism-scene-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write scene");
    path
}

/// Runs `prism render` on the scene; returns (exit success, stderr).
fn run(path: &PathBuf) -> (bool, String) {
    let out_image = path.with_extension("png");
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(["render", "--quiet", "--spp", "1", "--width", "8", "--height", "8", "-o"])
        .arg(&out_image)
        .arg(path)
        .output()
        .expect("run prism");
    assert!(!out_image.exists(), "an image was written for a bad scene");
    (output.status.success(), String::from_utf8_lossy(&output.stderr).into_owned())
}

fn check(name: &str, text: &str, line: usize, field: &str, words: &str) {
    let path = write_scene(name, text);
    let (success, stderr) = run(&path);
    assert!(!success, "{name}: exit code was 0");
    assert!(!stderr.contains("panicked"), "{name}: panicked: {stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{name}: expected one line, got {stderr:?}");
    let expected_location = format!("{}:{line}:", path.display());
    assert!(
        lines[0].contains(&expected_location),
        "{name}: no {expected_location} in {stderr:?}"
    );
    assert!(lines[0].contains(field), "{name}: no field {field} in {stderr:?}");
    assert!(lines[0].contains(words), "{name}: no '{words}' in {stderr:?}");
}

#[test]
fn syntax_error() {
    let text = format!("{GOOD}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0\nradius = 1\nmaterial = \"white\"\n");
    // The parser notices the unclosed array where the next line begins.
    check("syntax.toml", &text, 12, "", "expected");
}

#[test]
fn unknown_material() {
    let text = format!("{GOOD}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"chrome\"\n");
    check(
        "material.toml",
        &text,
        13,
        "objects[0].material",
        "unknown material \"chrome\"",
    );
}

#[test]
fn negative_radius() {
    let text = format!("{GOOD}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = -2\nmaterial = \"white\"\n");
    check("radius.toml", &text, 12, "objects[0].radius", "must be positive");
}

#[test]
fn missing_mesh_file() {
    let text = format!("{GOOD}\n[[objects]]\ntype = \"mesh\"\nfile = \"no-such-bunny.obj\"\nmaterial = \"white\"\n");
    check("mesh.toml", &text, 11, "objects[0].file", "no-such-bunny.obj");
}

#[test]
fn nan_value() {
    let text = format!("{GOOD}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, nan, 0]\nradius = 1\nmaterial = \"white\"\n");
    check("nan.toml", &text, 11, "objects[0].center", "finite");
}

#[test]
fn unknown_field() {
    let text = format!(
        "{GOOD}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"white\"\ncolour = [1, 0, 0]\n"
    );
    check("field.toml", &text, 14, "", "colour");
}

#[test]
fn unwritable_output_is_a_clear_error() {
    let path = write_scene("fine.toml", GOOD);
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args([
            "render",
            "--quiet",
            "--spp",
            "1",
            "--width",
            "8",
            "--height",
            "8",
            "-o",
            "/nonexistent-folder/x.png",
        ])
        .arg(&path)
        .output()
        .expect("run prism");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && stderr.contains("/nonexistent-folder/x.png") && !stderr.contains("panicked"),
        "{stderr}"
    );
}
