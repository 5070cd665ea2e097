//! OBJ meshes: vertex normals (smooth shading), uv, transforms, and errors.

mod common;
use common::ScratchDir;
use glam::{DVec2, DVec3};
use prism::geometry::{Mesh, Shape, Transform};
use prism::math::Ray;

/// The test's scratch directory, for its OBJ files.
fn scratch(test: &str) -> ScratchDir {
    ScratchDir::new("prism-mesh", test)
}

fn write_obj(dir: &ScratchDir, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write obj");
    path
}

/// A unit square in z = 0 made of two triangles, with uv and normals tilted
/// towards +x at x = 1: the shading normal must interpolate between them.
const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nvn 1 0 1\nvn 1 0 1\nvn 0 0 1\nf 1/1/1 2/2/2 3/3/3\nf 1/1/1 3/3/3 4/4/4\n";

#[test]
fn normals_uv_and_transform_are_applied() {
    let dir = scratch("normals_uv_and_transform_are_applied");
    let path = write_obj(&dir, "square.obj", SQUARE);
    let transform = Transform::new(DVec3::new(10.0, 0.0, 0.0), DVec3::ZERO, DVec3::splat(2.0));
    let mesh = Mesh::load_obj(&path, &transform).expect("load");
    assert_eq!(mesh.faces.len(), 2);
    assert!((mesh.positions[2] - DVec3::new(12.0, 2.0, 0.0)).length() < 1e-12);
    let triangles: Vec<_> = mesh.triangles(0).collect();
    // Hit at the square's centre, (11, 1) after the transform.
    let ray = Ray::new(DVec3::new(11.0, 1.0, 5.0), -DVec3::Z);
    let hit = triangles
        .iter()
        .find_map(|t| Shape::Triangle(*t).intersect(&ray, f64::INFINITY, std::slice::from_ref(&mesh)))
        .expect("hit");
    assert!((hit.t - 5.0).abs() < 1e-12);
    assert!((hit.uv - DVec2::new(0.5, 0.5)).length() < 1e-12, "uv {}", hit.uv);
    // Halfway between normal (0,0,1) and (1,0,1)/√2 in the barycentric sense.
    assert!(
        hit.shading_normal.x > 0.2 && hit.shading_normal.x < 0.6,
        "{}",
        hit.shading_normal
    );
    assert_eq!(hit.geometric_normal, DVec3::Z);
}

#[test]
fn broken_obj_is_an_error_not_a_panic() {
    let dir = scratch("broken_obj_is_an_error_not_a_panic");
    let path = write_obj(&dir, "broken.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7\n");
    assert!(Mesh::load_obj(&path, &Transform::default()).is_err());
    let empty = write_obj(&dir, "empty.obj", "# nothing\n");
    assert!(Mesh::load_obj(&empty, &Transform::default()).is_err());
}
