//! OBJ `.mtl` materials mapped onto Prism's (docs/scene-format.md, "OBJ
//! materials"): emission, glass, glossy and diffuse (constant or textured),
//! with a warning naming every key that is ignored; the scene's own material
//! wins over the library.

mod common;
use common::ScratchDir;
use glam::DVec3;
use prism::material::Material;
use prism::material::texture::Texture;
use prism::scene::{LoadedScene, load_scene_str};
use std::path::{Path, PathBuf};

/// The test's scratch directory, for its OBJ, MTL and image files.
fn scratch(test: &str) -> ScratchDir {
    ScratchDir::new("prism-mtl", test)
}

/// Five triangles in groups using materials `lamp`, `water`, `chrome`,
/// `clay` and `painted` (in that face order).
fn write_obj(dir: &Path) -> PathBuf {
    let mtl = "\
newmtl lamp
Ke 4 3 2
Kd 0.5 0.5 0.5

newmtl water
Kd 0.1 0.2 0.3
Ni 1.33
d 0.4
Tf 0.9 1 0.95

newmtl chrome
Kd 0.1 0.1 0.1
Ks 0.9 0.8 0.7
Ns 98

newmtl clay
Ka 0.2 0.2 0.2
Kd 0.7 0.6 1.5
map_Bump bumps.png

newmtl painted
Kd 1 1 1
map_Kd paint.png
";
    std::fs::write(dir.join("things.mtl"), mtl).expect("mtl");
    let image = image::RgbImage::from_pixel(2, 2, image::Rgb([200, 100, 50]));
    image.save(dir.join("paint.png")).expect("png");
    let mut obj = String::from("mtllib things.mtl\n");
    for (i, name) in ["lamp", "water", "chrome", "clay", "painted"].iter().enumerate() {
        let x = 2.0 * i as f64;
        obj += &format!("v {x} 0 0\nv {} 0 0\nv {x} 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n", x + 1.0);
        obj += &format!("usemtl {name}\nf {0}/{0} {1}/{1} {2}/{2}\n", 3 * i + 1, 3 * i + 2, 3 * i + 3);
    }
    let path = dir.join("things.obj");
    std::fs::write(&path, obj).expect("obj");
    path
}

fn scene_with_mesh(obj: &Path, material: Option<&str>) -> Result<LoadedScene, String> {
    let material = material.map_or(String::new(), |m| format!("material = \"{m}\"\n"));
    let text = format!(
        "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n\n[materials.white]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\n[[objects]]\ntype = \"mesh\"\nfile = {:?}\n{material}",
        obj.display().to_string()
    );
    load_scene_str(&text, Path::new("mtl.toml"), Path::new(".")).map_err(|e| e.to_string())
}

/// The material of the triangle made from OBJ face `face`.
fn material_of_face(loaded: &LoadedScene, face: u32) -> &Material {
    let scene = &loaded.scene;
    let primitive = (0..scene.primitive_count() as u32)
        .find(|&p| scene.triangle_source(p).is_some_and(|source| source.face == face))
        .expect("face present");
    scene.material_of(primitive)
}

#[test]
fn mtl_materials_map_onto_prism_materials() {
    let dir = scratch("mtl_materials_map_onto_prism_materials");
    let obj = write_obj(dir.path());
    let loaded = scene_with_mesh(&obj, None).expect("loads");
    match material_of_face(&loaded, 0) {
        Material::Emissive {
            radiance,
            two_sided,
            spectrum,
        } => {
            assert_eq!((*radiance, *two_sided), (DVec3::new(4.0, 3.0, 2.0), false));
            assert!(spectrum.is_none(), "an .mtl light is RGB");
        }
        other => panic!("lamp: {other:?}"),
    }
    match material_of_face(&loaded, 1) {
        Material::Glass { ior, tint, .. } => {
            // f32 in the .mtl: compare to f32 precision.
            assert!((ior - 1.33).abs() < 1e-6 && (*tint - DVec3::new(0.9, 1.0, 0.95)).abs().max_element() < 1e-6);
        }
        other => panic!("water: {other:?}"),
    }
    match material_of_face(&loaded, 2) {
        Material::Glossy { tint, roughness } => {
            // α = √(2 / (Ns + 2)) = √(2 / 100).
            assert!((roughness - 0.02f64.sqrt()).abs() < 1e-12, "{roughness}");
            assert!(matches!(tint, Texture::Constant(c) if (*c - DVec3::new(0.9, 0.8, 0.7)).abs().max_element() < 1e-6));
        }
        other => panic!("chrome: {other:?}"),
    }
    match material_of_face(&loaded, 3) {
        // Kd's blue of 1.5 is clamped to 1: an albedo above 1 creates energy.
        Material::Diffuse {
            albedo: Texture::Constant(c),
        } => assert!((*c - DVec3::new(0.7, 0.6, 1.0)).abs().max_element() < 1e-6, "{c}"),
        other => panic!("clay: {other:?}"),
    }
    assert!(matches!(
        material_of_face(&loaded, 4),
        Material::Diffuse {
            albedo: Texture::Image { .. }
        }
    ));
    // The lamp is a light.
    assert_eq!(loaded.scene.lights.lights.len(), 1);

    let warnings = loaded.warnings.join("\n");
    let expect = [
        "objects[0]: .mtl material \"lamp\"",
        "ignored Kd",
        ".mtl material \"water\"",
        ".mtl material \"chrome\"",
        ".mtl material \"clay\"",
        "ignored Ka, map_Bump",
        "Kd [0.699999988079071, 0.6000000238418579, 1.5] clamped to 1",
        ".mtl material \"painted\"",
    ];
    for words in expect {
        assert!(warnings.contains(words), "no {words:?} in:\n{warnings}");
    }
}

#[test]
fn the_scene_material_wins_with_a_warning() {
    let dir = scratch("the_scene_material_wins_with_a_warning");
    let obj = write_obj(dir.path());
    let loaded = scene_with_mesh(&obj, Some("white")).expect("loads");
    for face in 0..5 {
        assert!(matches!(material_of_face(&loaded, face), Material::Diffuse { .. }));
    }
    assert_eq!(loaded.scene.lights.lights.len(), 0);
    let warnings = loaded.warnings.join("\n");
    assert!(
        warnings.contains("objects[0]: the scene's material replaces the .mtl materials of")
            && warnings.contains("(lamp, water, chrome, clay, painted)"),
        "{warnings}"
    );
}

#[test]
fn a_mesh_without_materials_needs_a_scene_material() {
    let dir = scratch("a_mesh_without_materials_needs_a_scene_material");
    let plain = dir.join("plain.obj");
    std::fs::write(&plain, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("obj");
    let error = scene_with_mesh(&plain, None).err().unwrap_or_default();
    assert!(
        error.starts_with("mtl.toml:9:1: objects[0].material: ")
            && error.ends_with("needs a scene material: it has no .mtl materials"),
        "{error}"
    );
    let missing_library = dir.join("lost.obj");
    std::fs::write(
        &missing_library,
        "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n",
    )
    .expect("obj");
    let error = scene_with_mesh(&missing_library, None).err().unwrap_or_default();
    assert!(
        error.contains("its material library could not be read") && error.contains("nowhere.mtl: no such file"),
        "{error}"
    );
}
