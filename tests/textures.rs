//! Textures read back through the scene loader: known texel patterns at
//! chosen points of every mapping, sRGB decoding against the standard's
//! formula, images shared between materials, and located errors for bad
//! files and misplaced keys.
//!
//! Tolerance: texels are stored as f32 (relative rounding 2^-24 ≈ 6e-8 of
//! values ≤ 1), and test points sit on texel centres, where bilinear weights
//! are 0 or 1 up to the rounding of trigonometry and intersection (~1e-15).
//! Neighbouring texels of the test patterns differ by at least 0.01, so 1e-6
//! separates a right texel from a wrong one with room to spare.

use glam::{DVec2, DVec3};
use image::{Rgb, RgbImage};
use prism::color::Color;
use prism::material::{Material, ShadingPoint, Texture};
use prism::math::Ray;
use prism::scene::{LoadedScene, Scene, load_scene_file, load_scene_str};
use std::path::{Path, PathBuf};
use std::sync::Arc;

const TOLERANCE: f64 = 1e-6;

/// A scratch folder for this test process's images and scenes (per process, so
/// two concurrent runs never read each other's half-written files).
fn scratch() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("prism-textures-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("create scratch folder");
    dir
}

/// sRGB → linear as IEC 61966-2-1 writes it, independently of `prism::color`.
fn srgb_to_linear(value: u8) -> f64 {
    let c = value as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The stored 8-bit value of texel (x, y) in the grid images: every texel distinct.
fn grid_value(x: u32, y: u32) -> [u8; 3] {
    [(10 + 25 * x) as u8, (10 + 40 * y) as u8, 200]
}

/// The linear colour the renderer should read for texel (x, y).
fn grid_texel(x: u32, y: u32) -> Color {
    let [r, g, b] = grid_value(x, y);
    Color::new(srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b))
}

/// Writes a `width × height` grid PNG into the scratch folder.
fn write_grid(name: &str, width: u32, height: u32) -> PathBuf {
    let path = scratch().join(name);
    let image = RgbImage::from_fn(width, height, |x, y| Rgb(grid_value(x, y)));
    image.save(&path).expect("write test image");
    path
}

const CAMERA: &str = "[camera]\nposition = [0, 0, 50]\nlook_at = [0, 0, 0]\n\n";

fn load(scene_text: &str) -> LoadedScene {
    let text = format!("{CAMERA}{scene_text}");
    match load_scene_str(&text, Path::new("textures.toml"), &scratch()) {
        Ok(loaded) => loaded,
        Err(e) => panic!("scene does not load: {e}"),
    }
}

fn load_error(scene_text: &str) -> String {
    let text = format!("{CAMERA}{scene_text}");
    match load_scene_str(&text, Path::new("textures.toml"), &scratch()) {
        Ok(_) => panic!("scene loaded but should not"),
        Err(e) => e.to_string(),
    }
}

/// The reflectance the first material's texture gives where a ray from
/// `origin` towards `target` first meets the scene.
fn colour_seen(scene: &Scene, origin: DVec3, target: DVec3) -> Color {
    let ray = Ray::new(origin, (target - origin).normalize());
    let hit = scene.intersect(&ray, f64::INFINITY).expect("the ray hits");
    let at = ShadingPoint {
        uv: hit.hit.uv,
        point: hit.hit.point,
    };
    texture_of(scene.material_of(hit.primitive)).evaluate(&at)
}

fn texture_of(material: &Material) -> &Texture {
    match material {
        Material::Diffuse { albedo } => albedo,
        Material::Mirror { tint } | Material::Glossy { tint, .. } => tint,
        other => panic!("{other:?} has no texture"),
    }
}

fn assert_close(found: Color, expected: Color, what: &str) {
    assert!(
        (found - expected).abs().max_element() < TOLERANCE,
        "{what}: found {found}, expected {expected}"
    );
}

#[test]
fn srgb_texels_decode_by_the_standard_formula() {
    let path = scratch().join("ramp.png");
    let ramp = RgbImage::from_fn(256, 1, |x, _| Rgb([x as u8, 255 - x as u8, (x * 7 % 256) as u8]));
    ramp.save(&path).expect("write ramp");
    let image = prism::material::texture::Image::load(&path).expect("ramp loads");
    for x in 0..256u32 {
        let expected = Color::new(
            srgb_to_linear(x as u8),
            srgb_to_linear(255 - x as u8),
            srgb_to_linear((x * 7 % 256) as u8),
        );
        // Texels are stored as f32: relative error ≤ 2^-24 of values ≤ 1.
        assert!(
            (image.texel(x as usize, 0) - expected).abs().max_element() < 1e-7,
            "value {x}"
        );
    }
    // Spot check against the standard's own table: 128 → 0.2158605.
    assert!((image.texel(128, 0).x - 0.215_860_5).abs() < 1e-6);
}

#[test]
fn globe_shows_equator_prime_meridian_and_north_at_the_right_texels() {
    // 9 × 5 texels: u = ½ (longitude 0) is the centre of column 4, v = ½
    // (the equator) the centre of row 2; longitude 40° is the centre of column 5.
    write_grid("globe.png", 9, 5);
    let center = DVec3::new(1.0, 2.0, -3.0);
    let scene = load(&format!(
        "[materials.globe]\ntype = \"diffuse\"\nalbedo = {{ image = \"globe.png\", mapping = \"sphere\" }}\n\n\
         [[objects]]\ntype = \"sphere\"\ncenter = [{}, {}, {}]\nradius = 2\nmaterial = \"globe\"\n",
        center.x, center.y, center.z
    ));
    let seen = |direction: DVec3| colour_seen(&scene.scene, center + 10.0 * direction, center);
    // Equator × prime meridian faces +z.
    assert_close(seen(DVec3::Z), grid_texel(4, 2), "equator at the prime meridian");
    // East is +x (a camera on +z sees it on its right): longitude 40° E is column 5.
    let forty = 40f64.to_radians();
    assert_close(
        seen(DVec3::new(forty.sin(), 0.0, forty.cos())),
        grid_texel(5, 2),
        "equator at 40° E",
    );
    // Latitude 36° N (polar angle 54° = 0.3 π) is the centre of row 1: north is up.
    let polar = 0.3 * std::f64::consts::PI;
    assert_close(
        seen(DVec3::new(0.0, polar.cos(), polar.sin())),
        grid_texel(4, 1),
        "36° N on the prime meridian",
    );
}

#[test]
fn turning_the_globe_moves_its_meridians_and_a_centre_projects_any_shape() {
    write_grid("turned.png", 9, 5);
    let center = DVec3::new(0.0, 0.0, 0.0);
    let forty = 40f64.to_radians();
    let meridian_40 = DVec3::new(forty.sin(), 0.0, forty.cos());
    for (material, ninety_east) in [
        // Turned 40° about +y: the prime meridian moves to longitude 40° E.
        (
            "{ image = \"turned.png\", mapping = \"sphere\", rotate_degrees = 40 }",
            meridian_40,
        ),
        (
            "{ image = \"turned.png\", mapping = \"sphere\", rotate_degrees = [0, 40, 0] }",
            meridian_40,
        ),
        // Projected from an explicit centre (as on a mesh), unturned.
        (
            "{ image = \"turned.png\", mapping = \"sphere\", center = [0, 0, 0] }",
            DVec3::Z,
        ),
    ] {
        let scene = load(&format!(
            "[materials.globe]\ntype = \"glossy\"\nroughness = 0.2\ntint = {material}\n\n\
             [[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 2\nmaterial = \"globe\"\n"
        ));
        let seen = colour_seen(&scene.scene, 10.0 * ninety_east, center);
        assert_close(seen, grid_texel(4, 2), material);
    }
}

#[test]
fn planar_mapping_puts_the_picture_corners_on_the_rectangle_corners() {
    // 4 × 3 texels; the rectangle is deliberately not the shape (a larger quad).
    write_grid("wall.png", 4, 3);
    let scene = load(
        "[materials.wall]\ntype = \"diffuse\"\n\
         albedo = { image = \"wall.png\", mapping = \"planar\", origin = [-2, -1, 0], edge_u = [4, 0, 0], edge_v = [0, 3, 0], wrap = \"clamp\" }\n\n\
         [[objects]]\ntype = \"quad\"\ncorner = [-10, -10, 0]\nedge_u = [20, 0, 0]\nedge_v = [0, 20, 0]\nmaterial = \"wall\"\n",
    );
    let texture = texture_of(&scene.scene.materials[0]);
    let at = |point: DVec3| texture.evaluate(&ShadingPoint { uv: DVec2::ZERO, point });
    // Exact corners, clamped: the corner texels. Row 0 is the top of the picture,
    // so the rectangle's bottom edge (origin side) shows the last row.
    assert_close(at(DVec3::new(-2.0, -1.0, 0.0)), grid_texel(0, 2), "bottom-left");
    assert_close(at(DVec3::new(2.0, -1.0, 0.0)), grid_texel(3, 2), "bottom-right");
    assert_close(at(DVec3::new(-2.0, 2.0, 0.0)), grid_texel(0, 0), "top-left");
    assert_close(at(DVec3::new(2.0, 2.0, 0.0)), grid_texel(3, 0), "top-right");
    // Through the quad by a real ray: the centre of the top-right texel.
    let seen = colour_seen(&scene.scene, DVec3::new(1.5, 1.5, 5.0), DVec3::new(1.5, 1.5, 0.0));
    assert_close(seen, grid_texel(3, 0), "top-right texel centre by ray");
}

#[test]
fn uv_mapping_reads_a_quads_and_an_obj_meshs_uv_corners() {
    write_grid("uv.png", 4, 3);
    // A unit square at z = 0 as OBJ with uv, and the same square as a quad at z = -1.
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    std::fs::write(scratch().join("square.obj"), obj).expect("write OBJ");
    let scene = load(
        "[materials.picture]\ntype = \"mirror\"\ntint = { image = \"uv.png\" }\n\n\
         [[objects]]\ntype = \"mesh\"\nfile = \"square.obj\"\nmaterial = \"picture\"\ntransform = { translate = [10, 0, 0] }\n\n\
         [[objects]]\ntype = \"quad\"\ncorner = [0, 0, 0]\nedge_u = [1, 0, 0]\nedge_v = [0, 1, 0]\nmaterial = \"picture\"\n",
    );
    // Texel centres of the four corner texels, in (u, v) with v up.
    let corners = [
        (DVec2::new(0.125, 1.0 / 6.0), grid_texel(0, 2), "bottom-left"),
        (DVec2::new(0.875, 1.0 / 6.0), grid_texel(3, 2), "bottom-right"),
        (DVec2::new(0.125, 5.0 / 6.0), grid_texel(0, 0), "top-left"),
        (DVec2::new(0.875, 5.0 / 6.0), grid_texel(3, 0), "top-right"),
    ];
    for x_offset in [0.0, 10.0] {
        for (uv, texel, name) in corners {
            let target = DVec3::new(x_offset + uv.x, uv.y, 0.0);
            let seen = colour_seen(&scene.scene, target + DVec3::Z, target);
            assert_close(seen, texel, &format!("{name} at x offset {x_offset}"));
        }
    }
}

#[test]
fn checker_and_gradient_procedurals() {
    let scene = load(
        "[materials.checker]\ntype = \"diffuse\"\nalbedo = { checker = [[0.9, 0.9, 0.9], [0.1, 0.2, 0.3]], scale = 2 }\n\n\
         [materials.ramp]\ntype = \"diffuse\"\nalbedo = { gradient = [[1, 0, 0], [0, 0, 1]], axis = [0, 2, 0], from = 1, to = 3 }\n\n\
         [[objects]]\ntype = \"quad\"\ncorner = [0, 0, 0]\nedge_u = [1, 0, 0]\nedge_v = [0, 1, 0]\nmaterial = \"checker\"\n\n\
         [[objects]]\ntype = \"quad\"\ncorner = [10, 0, 0]\nedge_u = [1, 0, 0]\nedge_v = [0, 5, 0]\nmaterial = \"ramp\"\n",
    );
    let seen = |x: f64, y: f64| colour_seen(&scene.scene, DVec3::new(x, y, 1.0), DVec3::new(x, y, 0.0));
    // scale = 2: four squares on the unit quad.
    assert_close(seen(0.25, 0.25), Color::splat(0.9), "checker (0, 0)");
    assert_close(seen(0.75, 0.25), Color::new(0.1, 0.2, 0.3), "checker (1, 0)");
    assert_close(seen(0.75, 0.75), Color::splat(0.9), "checker (1, 1)");
    // Gradient along +y from y = 1 to y = 3: a quarter of the way at y = 1.5.
    assert_close(seen(10.5, 1.5), Color::new(0.75, 0.0, 0.25), "gradient at 1/4");
    assert_close(seen(10.5, 0.5), Color::X, "gradient before its start");
    assert_close(seen(10.5, 4.5), Color::Z, "gradient past its end");
}

#[test]
fn one_file_is_decoded_once_for_every_material_that_uses_it() {
    write_grid("shared.png", 4, 3);
    std::fs::create_dir_all(scratch().join("sub")).expect("create sub folder");
    let scene = load(
        "[materials.a]\ntype = \"diffuse\"\nalbedo = { image = \"shared.png\" }\n\n\
         [materials.b]\ntype = \"glossy\"\nroughness = 0.3\ntint = { image = \"sub/../shared.png\", mapping = \"sphere\" }\n",
    );
    let images: Vec<_> = scene
        .scene
        .materials
        .iter()
        .map(|m| match texture_of(m) {
            Texture::Image { image, .. } => Arc::clone(image),
            other => panic!("expected an image texture, found {other:?}"),
        })
        .collect();
    assert_eq!(images.len(), 2);
    assert!(
        Arc::ptr_eq(&images[0], &images[1]),
        "the same file spelt two ways must share one decoded image"
    );
}

#[test]
fn a_missing_or_corrupt_image_is_a_located_error_naming_the_file() {
    let material =
        |file: &str| format!("[materials.globe]\ntype = \"diffuse\"\nalbedo = {{ image = \"{file}\", mapping = \"sphere\" }}\n");
    // The albedo line is line 7: four camera lines plus the blank, then the header and type.
    let missing = load_error(&material("no-such-earth.png"));
    assert!(
        missing.starts_with("textures.toml:7:20: materials.globe.albedo.image: cannot read image ")
            && missing.contains("no-such-earth.png"),
        "{missing}"
    );
    std::fs::write(scratch().join("corrupt.png"), b"\x89PNG\r\n\x1a\n this is not a PNG stream").expect("write corrupt file");
    let corrupt = load_error(&material("corrupt.png"));
    assert!(
        corrupt.starts_with("textures.toml:7:20: materials.globe.albedo.image: cannot decode image ")
            && corrupt.contains("corrupt.png"),
        "{corrupt}"
    );
    // Through a scene file on disk too, as the CLI loads it.
    let scene_path = scratch().join("missing-image.toml");
    std::fs::write(&scene_path, format!("{CAMERA}{}", material("gone.png"))).expect("write scene");
    let error = load_scene_file(&scene_path).err().map(|e| e.to_string()).unwrap_or_default();
    assert!(
        error.contains("missing-image.toml:7:20: materials.globe.albedo.image: cannot read image") && error.contains("gone.png"),
        "{error}"
    );
}

#[test]
fn misplaced_or_invalid_texture_keys_are_located_errors() {
    let cases = [
        (
            "{ gradient = [[1, 1, 1], [0, 0, 0]], center = [0, 0, 0] }",
            "materials.m.albedo.center: does not apply to gradient textures (only to image, checker)",
        ),
        (
            "{ checker = [[1, 1, 1], [0, 0, 0]], wrap = \"clamp\" }",
            "materials.m.albedo.wrap: does not apply to checker textures (only to image)",
        ),
        (
            "{ checker = [[1, 1, 1], [0, 0, 0]], rotate_degrees = 3 }",
            "materials.m.albedo.rotate_degrees: applies only with mapping = \"sphere\"",
        ),
        (
            "{ checker = [[1, 1, 1], [0, 0, 0]], mapping = \"planar\", origin = [0, 0, 0], edge_u = [1, 0, 0] }",
            "materials.m.albedo.mapping: planar mapping needs `edge_v`",
        ),
        (
            "{ checker = [[1, 1, 1], [0, 0, 0]], scale = 0 }",
            "materials.m.albedo.scale: must be finite and non-zero",
        ),
        (
            "{ checker = [[2, 1, 1], [0, 0, 0]] }",
            "materials.m.albedo.checker: must not exceed 1 (it would create energy)",
        ),
        (
            "{ gradient = [[1, 1, 1], [0, 0, 0]], from = 2, to = 2 }",
            "materials.m.albedo.to: needs a non-zero `axis` and finite `from` ≠ `to`",
        ),
        (
            "{ scale = 2 }",
            "materials.m.albedo: a texture table needs one of `image`, `checker` or `gradient`",
        ),
        (
            "{ image = \"a.png\", checker = [[1, 1, 1], [0, 0, 0]] }",
            "materials.m.albedo.checker: give only one of `image`, `checker` or `gradient`",
        ),
    ];
    // Each error sits at the value of the key it names (the table itself for the last but one).
    let columns = [56, 53, 63, 56, 54, 22, 62, 10, 39];
    for ((albedo, expected), column) in cases.into_iter().zip(columns) {
        let error = load_error(&format!("[materials.m]\ntype = \"diffuse\"\nalbedo = {albedo}\n"));
        assert_eq!(
            error,
            format!("textures.toml:7:{column}: {expected}"),
            "for albedo = {albedo}"
        );
    }
    // A misspelt key is named by serde, with the keys it could have meant.
    let error = load_error("[materials.m]\ntype = \"diffuse\"\nalbedo = { imag = \"a.png\" }\n");
    assert!(error.contains("unknown field `imag`") && error.contains("`image`"), "{error}");
}

#[test]
fn the_shipped_earth_scene_loads_its_two_pictures() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/earth.toml");
    let loaded = load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
    let mut sizes: Vec<(usize, usize)> = loaded
        .scene
        .materials
        .iter()
        .filter_map(|m| match m {
            Material::Diffuse {
                albedo: Texture::Image { image, .. },
            } => Some((image.width(), image.height())),
            _ => None,
        })
        .collect();
    sizes.sort();
    // assets/SOURCES.md: the astronaut photo is 512 × 512, the Natural Earth map 720 × 360.
    assert_eq!(sizes, [(512, 512), (720, 360)]);
}
