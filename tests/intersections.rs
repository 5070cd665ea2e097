//! Analytic intersections at known distances and normals (grazing rays, rays
//! from inside), and watertightness of a closed mesh under the BVH.

use glam::{DVec2, DVec3};
use prism::geometry::{AxisBox, Mesh, Quad, Sphere, Triangle};
use prism::math::{Aabb, Ray};
use prism::scene::Scene;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * (1.0 + b.abs())
}

#[test]
fn sphere_distances_normals_grazing_and_inside() {
    let sphere = Sphere {
        center: DVec3::new(1.0, 2.0, 3.0),
        radius: 2.0,
    };
    // Head-on from outside: t = distance - radius, normal facing the ray.
    let hit = sphere.intersect(&Ray::new(DVec3::new(1.0, 2.0, 13.0), -DVec3::Z), f64::INFINITY);
    assert!(hit.is_some_and(|h| close(h.t, 8.0) && (h.geometric_normal - DVec3::Z).length() < 1e-12));
    // From the inside every direction hits at exactly the radius.
    for d in [DVec3::X, -DVec3::Y, DVec3::new(1.0, 1.0, 1.0)] {
        let hit = sphere.intersect(&Ray::new(sphere.center, d), f64::INFINITY);
        assert!(hit.is_some_and(|h| close(h.t, 2.0)), "{d}");
    }
    // Grazing: a ray passing at distance r(1 - 1e-9) from the centre hits
    // twice near the tangent point; at r(1 + 1e-9) it misses.
    let inside = Ray::new(DVec3::new(-10.0, 2.0, 3.0 + 2.0 * (1.0 - 1e-9)), DVec3::X);
    let outside = Ray::new(DVec3::new(-10.0, 2.0, 3.0 + 2.0 * (1.0 + 1e-9)), DVec3::X);
    assert!(
        sphere
            .intersect(&inside, f64::INFINITY)
            .is_some_and(|h| (h.t - 11.0).abs() < 1e-3)
    );
    assert!(sphere.intersect(&outside, f64::INFINITY).is_none());
}

#[test]
fn box_faces_from_outside_inside_and_at_grazing() {
    let b = AxisBox {
        bounds: Aabb::new(DVec3::new(-1.0, -2.0, -3.0), DVec3::new(1.0, 2.0, 3.0)),
    };
    let cases = [
        (DVec3::new(5.0, 0.5, 0.5), -DVec3::X, 4.0, DVec3::X),
        (DVec3::new(0.2, -7.0, 0.5), DVec3::Y, 5.0, -DVec3::Y),
        (DVec3::ZERO, DVec3::Z, 3.0, DVec3::Z),
        (DVec3::new(0.5, 0.5, 0.5), -DVec3::Y, 2.5, -DVec3::Y),
    ];
    for (origin, direction, t, normal) in cases {
        let hit = b.intersect(&Ray::new(origin, direction), f64::INFINITY);
        assert!(
            hit.is_some_and(|h| close(h.t, t) && h.geometric_normal == normal),
            "{origin} {direction}"
        );
    }
    // Grazing along a face, just outside: miss.
    assert!(
        b.intersect(&Ray::new(DVec3::new(-5.0, 2.0 + 1e-9, 0.0), DVec3::X), f64::INFINITY)
            .is_none()
    );
}

#[test]
fn triangle_and_quad_known_hits() {
    let tri = Triangle {
        vertices: [
            DVec3::new(0.0, 0.0, -5.0),
            DVec3::new(4.0, 0.0, -5.0),
            DVec3::new(0.0, 4.0, -5.0),
        ],
        mesh: 0,
        face: 0,
    };
    let hit = tri.intersect_raw(&Ray::new(DVec3::new(1.0, 1.0, 0.0), -DVec3::Z), f64::INFINITY);
    assert!(hit.is_some_and(|h| close(h.t, 5.0) && (h.barycentric[1] - 0.25).abs() < 1e-12));
    // Oblique.
    let d = DVec3::new(1.0, 1.0, -5.0);
    let hit = tri.intersect_raw(&Ray::new(DVec3::ZERO, d), f64::INFINITY);
    assert!(hit.is_some_and(|h| close(h.t, d.length())));
    // Through the hypotenuse's midpoint: on the edge, still a hit.
    let hit = tri.intersect_raw(&Ray::new(DVec3::new(2.0, 2.0, 1.0), -DVec3::Z), f64::INFINITY);
    assert!(hit.is_some());
    // Parallel to the plane: miss.
    assert!(
        tri.intersect_raw(&Ray::new(DVec3::new(1.0, 1.0, -5.0), DVec3::X), f64::INFINITY)
            .is_none()
    );

    let quad = Quad::new(
        DVec3::new(-1.0, -1.0, 2.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 2.0, 0.0),
    );
    let hit = quad.intersect(&Ray::new(DVec3::new(0.5, -0.5, -3.0), DVec3::Z), f64::INFINITY);
    assert!(
        hit.is_some_and(|h| close(h.t, 5.0)
            && h.geometric_normal == DVec3::Z
            && (h.uv - DVec2::new(0.75, 0.25)).length() < 1e-12)
    );
    assert!(
        quad.intersect(&Ray::new(DVec3::new(1.5, 0.0, -3.0), DVec3::Z), f64::INFINITY)
            .is_none()
    );
}

/// An icosphere: closed, every edge shared by exactly two faces.
fn icosphere(subdivisions: u32) -> Vec<[DVec3; 3]> {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let v: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let faces = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut triangles: Vec<[DVec3; 3]> = faces.iter().map(|f| f.map(|i: usize| v[i])).collect();
    for _ in 0..subdivisions {
        // Midpoints are computed identically for both faces sharing an edge,
        // so the result stays watertight in floating point.
        let mid = |a: DVec3, b: DVec3| {
            let (lo, hi) = if (a.x, a.y, a.z) < (b.x, b.y, b.z) { (a, b) } else { (b, a) };
            ((lo + hi) * 0.5).normalize()
        };
        triangles = triangles
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    triangles
}

/// Uniform numbers in [0, 1) from a fixed xorshift64 stream (Marsaglia
/// 2003): the same rays on every run.
fn uniform_stream() -> impl FnMut() -> f64 {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// 10⁶ rays from inside a closed mesh, aimed exactly at its vertices and at
/// points on its edges: every one must hit (a miss is a leak). The
/// watertight test guarantees this; a naive Möller–Trumbore does not.
#[test]
fn closed_mesh_has_no_leaks_at_edges_and_vertices() {
    let triangles = icosphere(3);
    let scene = Scene::from_mesh(Mesh::from_triangles(&triangles));

    let mut next = uniform_stream();
    let mut leaks = 0;
    let mut rays = 0;
    let target_count = 1_000_000;
    while rays < target_count {
        for tri in &triangles {
            if rays >= target_count {
                break;
            }
            // Aim at a vertex or at a point on an edge.
            let k = (next() * 3.0) as usize % 3;
            let target = if next() < 0.3 {
                tri[k]
            } else {
                tri[k].lerp(tri[(k + 1) % 3], next())
            };
            let origin = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 0.8;
            if scene.intersect(&Ray::new(origin, target - origin), f64::INFINITY).is_none() {
                leaks += 1;
            }
            rays += 1;
        }
    }
    assert_eq!(leaks, 0, "{leaks} of {rays} rays escaped the closed mesh");
}

/// A ray spawned on a quad may skip that quad (`Scene::leaving`), and a ray
/// spawned on anything else may not: on the Cornell box (quad walls and
/// light, a mirror ball and a glass ball), rays spawned from hits into both
/// hemispheres, through the surface included, find the same nearest hit,
/// bit for bit, and the same occlusion whether or not they skip. Rays into a
/// ball from its own surface must find its far side, so were a ball ever
/// skipped this would fail. Shadow rays to points on the quad light may
/// skip that quad too.
#[test]
fn skipping_the_quad_a_ray_leaves_changes_no_answer() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.toml");
    let scene = prism::scene::load_scene_file(&path).expect("scenes/cornell.toml loads").scene;
    let mut next = uniform_stream();
    // A uniform direction, by rejection from the cube.
    let direction = |next: &mut dyn FnMut() -> f64| loop {
        let d = DVec3::new(2.0 * next() - 1.0, 2.0 * next() - 1.0, 2.0 * next() - 1.0);
        if d.length_squared() > 1e-6 && d.length_squared() <= 1.0 {
            break d;
        }
    };
    let (mut from_quads, mut back_into_spheres, mut to_quad_lights) = (0, 0, 0);
    for _ in 0..20_000 {
        // From inside the room towards anything.
        let origin = DVec3::new(5.0 + 545.0 * next(), 5.0 + 540.0 * next(), 5.0 + 545.0 * next());
        let Some(found) = scene.intersect(&Ray::new(origin, direction(&mut next)), f64::INFINITY) else {
            continue;
        };
        let hit = found.hit;
        let leaving = scene.leaving(found.primitive);
        if leaving != prism::scene::Leaving::Nothing {
            from_quads += 1;
        }
        for _ in 0..4 {
            let spawned = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, direction(&mut next));
            let all = scene.intersect(&spawned, f64::INFINITY);
            let skipping = scene.intersect_leaving(&spawned, f64::INFINITY, leaving);
            assert_eq!(
                all.map(|f| (f.primitive, f.hit.t.to_bits())),
                skipping.map(|f| (f.primitive, f.hit.t.to_bits())),
                "ray leaving primitive {}",
                found.primitive
            );
            back_into_spheres +=
                usize::from(leaving == prism::scene::Leaving::Nothing && all.is_some_and(|f| f.primitive == found.primitive));
            let t_max = 600.0 * next();
            let nothing = prism::scene::Leaving::Nothing;
            assert_eq!(
                scene.occluded(&spawned, t_max),
                scene.occluded_between(&spawned, t_max, leaving, nothing)
            );
        }
        // Shadow rays to the light, built as the path tracer builds them,
        // may skip the light's quad as well.
        let u = glam::DVec2::new(next(), next());
        if let Some(light) = scene.lights.sample(&scene, hit.point, 0.5, u) {
            let shadow = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, light.wi);
            let t_max = (light.point - shadow.origin).length() * (1.0 - 1e-9) - light.point_error.length();
            let target = scene.leaving(light.primitive);
            to_quad_lights += usize::from(target != prism::scene::Leaving::Nothing);
            assert_eq!(
                scene.occluded(&shadow, t_max),
                scene.occluded_between(&shadow, t_max, leaving, target)
            );
        }
    }
    assert!(from_quads > 10_000, "{from_quads} hits on quads");
    assert!(
        back_into_spheres > 100,
        "{back_into_spheres} rays from a ball into the same ball"
    );
    assert!(to_quad_lights > 10_000, "{to_quad_lights} shadow rays to the quad light");
}

/// `Scene::nearest_distance` (the query without the hit record) finds what
/// `Scene::intersect` finds, bit for bit: the same distance and primitive
/// on shipped scenes holding every kind of shape (a mesh, quads, spheres,
/// boxes, single triangles, surfaces of revolution), for rays from points
/// between the camera and the scene's middle, in random directions.
#[test]
fn nearest_distance_agrees_with_intersect_on_every_shape() {
    let mut next = uniform_stream();
    for name in [
        "bunny.toml",
        "illuminants.toml",
        "smallpt.toml",
        "vase.toml",
        "prism.toml",
        "cornell.toml",
    ] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes").join(name);
        let loaded = prism::scene::load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"));
        let scene = &loaded.scene;
        let bounds = scene.bounds();
        let middle = bounds.min.lerp(bounds.max, 0.5);
        let (mut hits, mut rays) = (0, 0);
        for _ in 0..20_000 {
            // Between the camera and the middle of the scene's bounds, so
            // rays start inside and outside the objects.
            let origin = loaded.camera.position.lerp(middle, next());
            let direction = DVec3::new(2.0 * next() - 1.0, 2.0 * next() - 1.0, 2.0 * next() - 1.0);
            if direction.length_squared() < 1e-6 {
                continue;
            }
            let ray = Ray::new(origin, direction);
            let full = scene.intersect(&ray, f64::INFINITY);
            let distance = scene.nearest_distance(&ray, f64::INFINITY);
            assert_eq!(
                full.map(|found| (found.hit.t.to_bits(), found.primitive)),
                distance.map(|(t, primitive)| (t.to_bits(), primitive)),
                "{name}: ray from {origin} along {direction}"
            );
            hits += usize::from(full.is_some());
            rays += 1;
        }
        // Enough rays must hit something for the comparison to say much.
        assert!(hits >= 2_000, "{name}: only {hits} of {rays} rays hit");
    }
}
