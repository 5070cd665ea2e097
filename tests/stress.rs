//! The fast part of the numerical stress test (`prism bench --stress` is the
//! long one): extreme scenes rendered briefly and probed, with counts that
//! must be exactly 0: NaN/inf samples, self-intersections, leaks. Each check
//! also gets a negative control showing it can fail.

use glam::DVec3;
use prism::bench::scaling::sphere_mesh;
use prism::bench::stress::{self, StressOptions};
use prism::math::Ray;
use prism::scene::Scene;
use std::path::Path;

fn options() -> StressOptions {
    StressOptions {
        width: 32,
        height: 32,
        passes: 4,
        rays: 5000,
        closed_mesh: Some(Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/bunny.obj")),
        photons_per_iteration: 2000,
    }
}

/// Zero is the only right count: one NaN sample, one ray re-hitting its own
/// surface or one ray slipping between triangles is a bug, not noise.
#[test]
fn extreme_scenes_have_no_nan_samples_self_intersections_or_leaks() {
    let rows = stress::run(&options(), |_| {}).expect("stress scenes load");
    // Every scene was probed by every check that applies to it.
    assert!(rows.iter().filter(|r| r.check == "self-intersections").count() == stress::stress_scenes().len());
    assert!(
        rows.iter().any(|r| r.scene == "bunny-obj"),
        "the bunny's leak test did not run"
    );
    for row in &rows {
        assert!(row.tested > 0, "{} / {}: nothing tested", row.scene, row.check);
        assert_eq!(
            row.failures, 0,
            "{} / {}: {} of {}",
            row.scene, row.check, row.failures, row.tested
        );
    }
}

/// Negative control: spawning rays at the raw hit point, without pbrt's
/// offset, must produce self-intersections on smallpt's radius-1e5 walls
/// (hit points there carry errors of ~1e-11 relative to 1e5 ≈ 1e-6 absolute).
#[test]
fn the_self_intersection_count_catches_unoffset_rays() {
    let smallpt = stress::stress_scenes()
        .into_iter()
        .find(|scene| scene.name.starts_with("smallpt"))
        .expect("smallpt scene");
    let loaded = smallpt.load().expect("loads");
    let (spawned, self_hits) = stress::self_intersections_with(&loaded.scene, &loaded.camera, 500, |hit, direction| {
        Ray::new(hit.point, direction)
    });
    assert!(spawned > 0);
    assert!(
        self_hits > 0,
        "naive spawning should re-hit its surface sometimes ({spawned} rays)"
    );
}

/// Negative control: a sphere mesh with one face removed must leak rays
/// aimed at that face's edges and vertices.
#[test]
fn the_leak_count_catches_a_hole() {
    let mut mesh = sphere_mesh(200, DVec3::ZERO, 1.0);
    let closed = stress::leaks(&mesh, Some(DVec3::ZERO), 4000);
    assert_eq!(closed.1, 0, "the closed mesh leaks");
    // Remove a quarter of the faces: aimed rays at their shared vertices and
    // edges now often pass through the gap.
    let keep = mesh.faces.len() * 3 / 4;
    mesh.faces.truncate(keep);
    let (tested, leaked) = stress::leaks(&mesh, Some(DVec3::ZERO), 4000);
    assert!(leaked > 0, "an open mesh did not leak ({tested} rays)");
    // The scene helper builds a BVH over every remaining face.
    assert_eq!(Scene::from_mesh(mesh).primitive_count(), keep);
}
