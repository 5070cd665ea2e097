//! Bad scenes give one clear line naming file, line, column and the full
//! field path, a non-zero exit code, no panic and no image. One test per
//! category of error, each asserting the exact location and path.

mod common;
use common::ScratchDir;
use std::path::{Path, PathBuf};
use std::process::Command;

const GOOD: &str = r#"[camera]
position = [0, 0, 5]
look_at = [0, 0, 0]

[materials.white]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
"#;

/// GOOD plus one sphere whose lines (9 to 13) are `type`, `center`, `radius`
/// and `material`, with `replace` applied to the sphere's text.
fn sphere_scene(from: &str, to: &str) -> String {
    let sphere = "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"white\"\n";
    assert!(sphere.contains(from), "{from}");
    format!("{GOOD}\n{}", sphere.replace(from, to))
}

/// The test's scratch directory, for its scenes and meshes.
fn scratch(test: &str) -> ScratchDir {
    ScratchDir::new("prism-scene-errors", test)
}

fn write_scene(dir: &ScratchDir, name: &str, text: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write scene");
    path
}

/// Runs `prism render` with `args` on the scene; returns (exit success, stderr).
fn run_with(path: &Path, args: &[&str]) -> (bool, String) {
    let out_image = path.with_extension("png");
    let output = Command::new(env!("CARGO_BIN_EXE_prism"))
        .args(["render", "--quiet", "--spp", "1", "--width", "8", "--height", "8", "-o"])
        .arg(&out_image)
        .args(args)
        .arg(path)
        .output()
        .expect("run prism");
    assert!(!out_image.exists(), "an image was written for a bad scene");
    (output.status.success(), String::from_utf8_lossy(&output.stderr).into_owned())
}

/// The error for `text` is exactly `file:line:column: field: message...`
/// (`field` empty when the error has none), on one line, with `words` in
/// the message.
fn check(dir: &ScratchDir, name: &str, text: impl AsRef<[u8]>, line: usize, column: usize, field: &str, words: &str) {
    let path = write_scene(dir, name, text);
    let (success, stderr) = run_with(&path, &[]);
    assert!(!success, "{name}: exit code was 0");
    assert!(!stderr.contains("panicked"), "{name}: panicked: {stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{name}: expected one line, got {stderr:?}");
    let field = if field.is_empty() {
        String::new()
    } else {
        format!("{field}: ")
    };
    let expected = format!("error: {}:{line}:{column}: {field}", path.display());
    assert!(
        lines[0].starts_with(&expected),
        "{name}: expected {expected:?}…, got {:?}",
        lines[0]
    );
    assert!(lines[0].contains(words), "{name}: no '{words}' in {stderr:?}");
}

#[test]
fn syntax_error() {
    let dir = scratch("syntax_error");
    let text = sphere_scene("center = [0, 0, 0]", "center = [0, 0, 0");
    // The parser notices the unclosed array where the next line begins.
    check(&dir, "syntax.toml", text, 12, 1, "objects[0].center", "expected `,`");
}

#[test]
fn type_error_inside_an_object_is_placed_at_the_value() {
    let dir = scratch("type_error_inside_an_object_is_placed_at_the_value");
    // Not at the first [[objects]] header: the value itself, with its index.
    let text = format!(
        "{}{}",
        sphere_scene("radius = 1", "radius = 1"),
        "\n[[objects]]\ntype = \"sphere\"\ncenter = [0, \"up\", 0]\nradius = 1\nmaterial = \"white\"\n"
    );
    check(
        &dir,
        "type.toml",
        text,
        17,
        14,
        "objects[1].center[1]",
        "invalid type: string \"up\"",
    );
}

#[test]
fn unknown_key() {
    let dir = scratch("unknown_key");
    let text = sphere_scene("material = \"white\"", "material = \"white\"\ncolour = [1, 0, 0]");
    check(&dir, "field.toml", text, 14, 1, "objects[0].colour", "colour");
}

#[test]
fn unknown_key_in_a_texture_table() {
    let dir = scratch("unknown_key_in_a_texture_table");
    let text = GOOD.replace(
        "albedo = [0.5, 0.5, 0.5]",
        "albedo = { checker = [[0, 0, 0], [1, 1, 1]], scael = 2 }",
    );
    check(
        &dir,
        "texture.toml",
        text,
        7,
        46,
        "materials.white.albedo.scael",
        "unknown field `scael`",
    );
}

#[test]
fn missing_key_names_the_table_it_is_missing_from() {
    let dir = scratch("missing_key_names_the_table_it_is_missing_from");
    let text = GOOD.replace("position = [0, 0, 5]\n", "");
    check(
        &dir,
        "missing.toml",
        text,
        1,
        1,
        "camera.position",
        "missing field `position`",
    );
    let text = sphere_scene("radius = 1\n", "");
    check(
        &dir,
        "missing-radius.toml",
        text,
        9,
        1,
        "objects[0].radius",
        "missing field `radius`",
    );
}

#[test]
fn unknown_kind_names_the_type_key() {
    let dir = scratch("unknown_kind_names_the_type_key");
    let text = sphere_scene("type = \"sphere\"", "type = \"spehre\"");
    check(&dir, "kind.toml", text, 10, 8, "objects[0].type", "unknown variant `spehre`");
}

#[test]
fn range_error() {
    let dir = scratch("range_error");
    let text = sphere_scene("radius = 1", "radius = -2");
    check(
        &dir,
        "radius.toml",
        text,
        12,
        10,
        "objects[0].radius",
        "must be positive (found -2)",
    );
    let text = GOOD.replace("type = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]", "type = \"glass\"\nior = -1.5");
    check(&dir, "ior.toml", text, 7, 7, "materials.white.ior", "must be positive");
}

/// An emissive material gives an RGB `radiance`, or a `spectrum` or
/// `temperature` with a `luminance`; each wrong combination or value is
/// placed at the key that is wrong.
#[test]
fn spectral_light_errors_name_the_key() {
    let dir = scratch("spectral_light_errors_name_the_key");
    let light = |keys: &str| {
        GOOD.replace(
            "type = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]",
            &format!("type = \"emissive\"\n{keys}"),
        )
    };
    check(
        &dir,
        "cold.toml",
        light("temperature = 100\nluminance = 1"),
        7,
        15,
        "materials.white.temperature",
        "must be between 500 and 1000000 kelvin (found 100)",
    );
    check(
        &dir,
        "d50.toml",
        light("spectrum = \"D50\"\nluminance = 1"),
        7,
        12,
        "materials.white.spectrum",
        "unknown illuminant \"D50\" (known: D65, A)",
    );
    check(
        &dir,
        "dark.toml",
        light("spectrum = \"A\"\nluminance = -1"),
        8,
        13,
        "materials.white.luminance",
        "must not be negative (found -1)",
    );
    check(
        &dir,
        "both.toml",
        light("spectrum = \"A\"\ntemperature = 2000\nluminance = 1"),
        8,
        15,
        "materials.white.temperature",
        "not both",
    );
    check(
        &dir,
        "scaled-rgb.toml",
        light("radiance = [1, 1, 1]\nluminance = 2"),
        8,
        13,
        "materials.white.luminance",
        "an RGB `radiance` is its own scale",
    );
    check(
        &dir,
        "rgb-and-spectrum.toml",
        light("radiance = [1, 1, 1]\nspectrum = \"D65\"\nluminance = 2"),
        7,
        12,
        "materials.white.radiance",
        "not both",
    );
    check(
        &dir,
        "unscaled.toml",
        light("temperature = 2700"),
        5,
        1,
        "materials.white.luminance",
        "missing field `luminance`",
    );
    check(
        &dir,
        "nothing.toml",
        light("two_sided = true"),
        5,
        1,
        "materials.white.radiance",
        "missing field `radiance`",
    );
}

#[test]
fn reference_error() {
    let dir = scratch("reference_error");
    let text = sphere_scene("material = \"white\"", "material = \"chrome\"");
    check(
        &dir,
        "material.toml",
        text,
        13,
        12,
        "objects[0].material",
        "unknown material \"chrome\"",
    );
}

#[test]
fn invalid_utf8_is_placed_at_the_first_bad_byte() {
    let dir = scratch("invalid_utf8_is_placed_at_the_first_bad_byte");
    let mut text = GOOD.as_bytes().to_vec();
    // Line 5 is `[materials.white]`: a Latin-1 é after "[materials.wh".
    let at = GOOD.find("ite]").expect("marker");
    text[at] = 0xE9;
    check(&dir, "latin1.toml", text, 5, 14, "", "not valid UTF-8 (byte 0xe9)");
}

#[test]
fn nan_value() {
    let dir = scratch("nan_value");
    let text = sphere_scene("center = [0, 0, 0]", "center = [0, nan, 0]");
    check(&dir, "nan.toml", text, 11, 14, "objects[0].center[1]", "finite");
}

#[test]
fn coordinates_beyond_the_documented_range() {
    let dir = scratch("coordinates_beyond_the_documented_range");
    let text = sphere_scene("center = [0, 0, 0]", "center = [0, 0, 2e12]");
    check(&dir, "far.toml", text, 11, 17, "objects[0].center[2]", "within ±1e12");
    let text = GOOD.replace("position = [0, 0, 5]", "position = [0, 0, 1e308]");
    check(&dir, "camera-far.toml", text, 2, 19, "camera.position[2]", "within ±1e12");
}

#[test]
fn missing_mesh_file() {
    let dir = scratch("missing_mesh_file");
    let text = sphere_scene(
        "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1",
        "type = \"mesh\"\nfile = \"no-such-bunny.obj\"",
    );
    check(
        &dir,
        "mesh.toml",
        text,
        11,
        8,
        "objects[0].file",
        "no-such-bunny.obj: no such file",
    );
}

#[test]
fn a_mesh_path_that_is_a_directory_or_a_device_says_so() {
    let dir = scratch("a_mesh_path_that_is_a_directory_or_a_device_says_so");
    let folder = dir.join("a-folder.obj");
    std::fs::create_dir_all(&folder).expect("folder");
    let text = sphere_scene(
        "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1",
        &format!("type = \"mesh\"\nfile = {:?}", folder.display().to_string()),
    );
    check(&dir, "mesh-folder.toml", text, 11, 8, "objects[0].file", "is a directory");
    let text = sphere_scene(
        "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1",
        "type = \"mesh\"\nfile = \"/dev/zero\"",
    );
    check(
        &dir,
        "mesh-zero.toml",
        text,
        11,
        8,
        "objects[0].file",
        "/dev/zero: is not a regular file",
    );
    let text = GOOD.replace("albedo = [0.5, 0.5, 0.5]", "albedo = { image = \"/dev/zero\" }");
    check(
        &dir,
        "image-zero.toml",
        text,
        7,
        20,
        "materials.white.albedo.image",
        "is not a regular file",
    );
}

#[test]
fn nan_vertex_normals_are_refused() {
    let dir = scratch("nan_vertex_normals_are_refused");
    let obj = dir.join("nan-normal.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn nan 0 1\nvn 0 0 1\nf 1//1 2//2 3//3\n",
    )
    .expect("obj");
    let text = sphere_scene(
        "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1",
        &format!("type = \"mesh\"\nfile = {:?}", obj.display().to_string()),
    );
    check(
        &dir,
        "nan-normal.toml",
        text,
        11,
        8,
        "objects[0].file",
        "a vertex normal (vn) is not finite",
    );
}

#[test]
fn mesh_vertices_are_checked_after_the_transform() {
    let dir = scratch("mesh_vertices_are_checked_after_the_transform");
    let obj = dir.join("unit.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("obj");
    let text = sphere_scene(
        "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1",
        &format!(
            "type = \"mesh\"\nfile = {:?}\ntransform = {{ scale = 1e12, translate = [1e12, 0, 0] }}",
            obj.display().to_string()
        ),
    );
    check(
        &dir,
        "mesh-far.toml",
        text,
        12,
        13,
        "objects[0].transform",
        "after the transform must lie within ±1e12",
    );
}

#[test]
fn render_settings_in_the_file_are_checked_like_the_flags() {
    let dir = scratch("render_settings_in_the_file_are_checked_like_the_flags");
    let text = format!("{GOOD}\n[render]\nmax_depth = 2147483647\n");
    check(
        &dir,
        "depth.toml",
        text,
        10,
        13,
        "render.max_depth",
        "must be at most 1024 (found 2147483647)",
    );
    let text = format!("{GOOD}\n[render]\nwidth = 100000\nheight = 100000\n");
    check(&dir, "huge.toml", text, 10, 9, "render.width", "must be at most 65536 pixels");
    let text = format!("{GOOD}\n[render]\nwidth = 60000\nheight = 60000\n");
    check(
        &dir,
        "too-much-memory.toml",
        text,
        10,
        9,
        "render.width",
        "needs about 720.0 GB of memory",
    );
}

/// The issue's reproducer 5 (SPPM, max_depth 2147483647, a glass triangle
/// with a vertex at -1e308) and each of its two bad values alone.
#[test]
fn sppm_hang_reproducers_are_refused() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/reproducers");
    for (file, location, field) in [
        ("sppm_hang.toml", "14:13", "render.max_depth"),
        ("sppm_hang_depth_only.toml", "14:13", "render.max_depth"),
        ("sppm_hang_vertex_only.toml", "39:49", "objects[1].vertices[2][0]"),
    ] {
        let path = dir.join(file);
        let started = std::time::Instant::now();
        let (success, stderr) = run_with(&path, &[]);
        assert!(!success && started.elapsed().as_secs() < 30, "{file}: {stderr}");
        let expected = format!("error: {}:{location}: {field}: ", path.display());
        assert!(stderr.starts_with(&expected), "{file}: expected {expected:?}, got {stderr:?}");
    }
}

/// A scene file that is missing, or is a folder, gets one line that names
/// it once: the file, then what is wrong with it.
#[test]
fn an_unreadable_scene_file_is_named_once() {
    let dir = scratch("an_unreadable_scene_file_is_named_once");
    let missing = dir.join("missing.toml");
    let folder = dir.join("folder.toml");
    std::fs::create_dir(&folder).expect("create folder");
    for (path, reason) in [(&missing, "no such file"), (&folder, "is a directory, not a file")] {
        let (success, stderr) = run_with(path, &[]);
        assert!(!success, "{}: exit code was 0", path.display());
        assert_eq!(stderr.trim_end(), format!("error: {}: {reason}", path.display()));
    }
}
