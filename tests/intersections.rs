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

/// 10⁶ rays from inside a closed mesh, aimed exactly at its vertices and at
/// points on its edges: every one must hit (a miss is a leak). The
/// watertight test guarantees this; a naive Möller–Trumbore does not.
#[test]
fn closed_mesh_has_no_leaks_at_edges_and_vertices() {
    let triangles = icosphere(3);
    let scene = Scene::from_mesh(Mesh::from_triangles(&triangles));

    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
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
