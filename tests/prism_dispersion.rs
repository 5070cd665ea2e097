//! The analytic prism: a collimated beam through a BK7 prism of apex angle
//! 60° onto a screen. For each of 8 wavelength bands, photons are traced
//! through the scene as the renderer traces them (scene intersection, the
//! dispersive glass's `sample_at_wavelength` choosing reflection or
//! refraction by its Fresnel weight) until they reach the screen; the
//! centroid of their hits must lie within 1 screen pixel of where Snell's
//! law, with the index from BK7's Sellmeier coefficients, sends the beam's
//! central ray, and the share of the beam's power arriving there must match
//! the Fresnel transmittance of the two faces within 2%.
//!
//! The prediction is computed here independently of the renderer's glass
//! code: the central ray in the prism's plane, vector Snell refraction at
//! each face, and the Fresnel equations for unpolarised light at each
//! interface (the renderer does not track polarisation, and neither does
//! this model; tracking it would change the transmittance by under 0.3% at
//! these angles).

mod common;
use common::scene;
use glam::{DVec2, DVec3};
use prism::material::{ShadingPoint, Transport};
use prism::math::{Frame, Ray};
use prism::sampler::mix64;
use prism::scene::Scene;
use prism::spectrum::dispersion::Dispersion;

/// Apex angle of the prism, degrees.
const APEX_DEGREES: f64 = 60.0;
/// Angle of incidence of the beam on the first face, degrees (near BK7's
/// minimum deviation, 48.6° at 587 nm).
const INCIDENCE_DEGREES: f64 = 50.0;
/// Distance from the prism's exit point to the screen along the 550 nm ray.
const SCREEN_DISTANCE: f64 = 1.0;
/// Width of one screen pixel, scene units (0.5 mm on a 1 m throw).
const PIXEL: f64 = 0.0005;
/// Beam width: narrow next to the prism (1 unit high) so every ray meets the same faces.
const BEAM_WIDTH: f64 = 0.01;
/// Photons per band.
const PHOTONS: u32 = 4000;

fn rotate(v: DVec2, degrees: f64) -> DVec2 {
    DVec2::from_angle(degrees.to_radians()).rotate(v)
}

/// The prism's cross-section in the x–y plane: base (−0.5, 0)–(0.5, 0) and
/// the apex above the origin.
fn prism_corners() -> [DVec2; 3] {
    let height = 0.5 / (APEX_DEGREES / 2.0).to_radians().tan();
    [DVec2::new(-0.5, 0.0), DVec2::new(0.5, 0.0), DVec2::new(0.0, height)]
}

/// Vector Snell refraction of unit `d` through a surface with unit normal
/// `n` facing the incident side, from index 1 to `eta` relative; with the
/// two cosines for the Fresnel equations.
fn refract(d: DVec2, n: DVec2, eta: f64) -> (DVec2, f64, f64) {
    let cos_i = -d.dot(n);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    let cos_t = (1.0 - sin2_t).sqrt();
    ((d / eta + n * (cos_i / eta - cos_t)).normalize(), cos_i, cos_t)
}

/// Unpolarised Fresnel transmittance from index `n1` to `n2` (Born & Wolf §1.5.3).
fn transmittance(n1: f64, n2: f64, cos_i: f64, cos_t: f64) -> f64 {
    let rs = ((n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t)).powi(2);
    let rp = ((n1 * cos_t - n2 * cos_i) / (n1 * cos_t + n2 * cos_i)).powi(2);
    1.0 - 0.5 * (rs + rp)
}

/// Where a line through `p` along `d` meets the line through `a` and `b`.
fn meet(p: DVec2, d: DVec2, a: DVec2, b: DVec2) -> DVec2 {
    let e = b - a;
    let t = (a - p).perp_dot(e) / d.perp_dot(e);
    p + d * t
}

/// The beam: its direction, and the point on the first face its centre meets.
fn beam() -> (DVec2, DVec2) {
    let [left, _, apex] = prism_corners();
    let inward = (apex - left).perp().normalize() * -1.0; // −(outward normal of the left face)
    let inward = if inward.x > 0.0 { inward } else { -inward };
    (rotate(inward, INCIDENCE_DEGREES), (left + apex) / 2.0)
}

/// The central ray by Snell's law at index `n`: its exit point and
/// direction, and the transmittance of the two faces.
fn snell_path(n: f64) -> (DVec2, DVec2, f64) {
    let [left, right, apex] = prism_corners();
    let (d0, entry) = beam();
    let outward = |a: DVec2, b: DVec2| {
        let normal = (b - a).perp().normalize();
        if normal.dot((a + b) / 2.0 - DVec2::new(0.0, 0.3)) > 0.0 {
            normal
        } else {
            -normal
        }
    };
    let (d1, cos_i1, cos_t1) = refract(d0, outward(left, apex), n);
    let exit = meet(entry, d1, apex, right);
    let (d2, cos_i2, cos_t2) = refract(d1, -outward(apex, right), 1.0 / n);
    (
        exit,
        d2,
        transmittance(1.0, n, cos_i1, cos_t1) * transmittance(n, 1.0, cos_i2, cos_t2),
    )
}

/// The screen: its centre, its axis across the spectrum, and its normal
/// (towards the prism), fixed by the 550 nm central ray.
fn screen() -> (DVec2, DVec2, DVec2) {
    let (exit, direction, _) = snell_path(Dispersion::BK7.ior(550.0));
    (exit + direction * SCREEN_DISTANCE, direction.perp(), -direction)
}

fn scene_text() -> String {
    let corners = prism_corners();
    let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
    let v = |p: DVec2, z: f64| DVec3::new(p.x, p.y, z);
    let mut triangles = Vec::new();
    for i in 0..3 {
        let (a, b) = (corners[i], corners[(i + 1) % 3]);
        triangles.push([v(a, -1.0), v(b, -1.0), v(b, 1.0)]);
        triangles.push([v(a, -1.0), v(b, 1.0), v(a, 1.0)]);
    }
    triangles.push([v(corners[0], -1.0), v(corners[1], -1.0), v(corners[2], -1.0)]);
    triangles.push([v(corners[0], 1.0), v(corners[1], 1.0), v(corners[2], 1.0)]);
    let mut text = String::from(
        "[camera]\nposition = [0, 0.4, -5]\nlook_at = [0, 0.4, 0]\nfov_y_degrees = 40\n\n\
         [materials.glass]\ntype = \"glass\"\nglass = \"BK7\"\n\
         [materials.screen]\ntype = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n\
         [materials.light]\ntype = \"emissive\"\nradiance = [1, 1, 1]\n",
    );
    for [a, mut b, mut c] in triangles {
        // Wind every face so its normal points out of the prism (the glass
        // tells entering from leaving by it).
        let normal = (b - a).cross(c - a);
        if normal.dot((a + b + c) / 3.0 - v(centroid, 0.0)) < 0.0 {
            std::mem::swap(&mut b, &mut c);
        }
        text += &format!(
            "[[objects]]\ntype = \"triangle\"\nvertices = [[{}, {}, {}], [{}, {}, {}], [{}, {}, {}]]\nmaterial = \"glass\"\n",
            a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z
        );
    }
    let (centre, axis, _) = screen();
    let corner = v(centre - axis * 0.1, -0.5);
    let edge = v(axis * 0.2, 0.0);
    text += &format!(
        "[[objects]]\ntype = \"quad\"\ncorner = [{}, {}, {}]\nedge_u = [{}, {}, {}]\nedge_v = [0, 0, 1]\nmaterial = \"screen\"\n",
        corner.x, corner.y, corner.z, edge.x, edge.y, edge.z
    );
    // A light far away, so the scene has one; the photons here are the beam's.
    text += "[[objects]]\ntype = \"sphere\"\ncenter = [0, 50, 0]\nradius = 0.1\nmaterial = \"light\"\n";
    text
}

/// Follows one photon of wavelength `lambda` from `ray` until it meets an
/// opaque surface (returned) or leaves the scene.
fn trace(scene: &Scene, mut ray: Ray, lambda: f64, stream: u64) -> Option<DVec3> {
    for bounce in 0..32u64 {
        let found = scene.intersect(&ray, f64::INFINITY)?;
        let material = scene.material_of(found.primitive);
        if !material.is_dispersive() {
            return Some(found.hit.point);
        }
        let frame = Frame::from_normal(found.hit.shading_normal);
        let wo = frame.to_local(-ray.direction);
        let at = ShadingPoint {
            uv: found.hit.uv,
            point: found.hit.point,
        };
        let u_lobe = (mix64(stream ^ mix64(bounce + 1)) >> 11) as f64 / (1u64 << 53) as f64;
        let sample = material.sample_at_wavelength(wo, &at, DVec2::ZERO, u_lobe, Transport::Importance, lambda)?;
        ray = Ray::spawn(
            found.hit.point,
            found.hit.point_error,
            found.hit.geometric_normal,
            frame.to_world(sample.wi),
        );
    }
    None
}

#[test]
fn a_prism_sends_each_wavelength_where_snell_and_fresnel_say() {
    let loaded = scene(&scene_text());
    assert!(loaded.scene.has_dispersion(), "glass = \"BK7\" is dispersive");
    let (direction, entry) = beam();
    let (centre, axis, _) = screen();
    let mut worst_pixels = 0.0f64;
    let mut worst_power = 0.0f64;
    let mut previous: Option<f64> = None;
    for band in 0..8 {
        let lambda = 400.0 + 40.0 * band as f64;
        let n = Dispersion::BK7.ior(lambda);
        let (exit, out, expected_power) = snell_path(n);
        let predicted = {
            let hit = exit + out * ((centre - exit).dot(-axis.perp()) / out.dot(-axis.perp()));
            (hit - centre).dot(axis) / PIXEL
        };
        // Stratified across the beam's width, all parallel, in the plane z = 0.
        let (mut sum, mut weight) = (0.0f64, 0.0f64);
        for k in 0..PHOTONS {
            let offset = ((k as f64 + 0.5) / PHOTONS as f64 - 0.5) * BEAM_WIDTH;
            let start = entry - direction * 0.5 + direction.perp() * offset;
            let ray = Ray::new(DVec3::new(start.x, start.y, 0.0), DVec3::new(direction.x, direction.y, 0.0));
            let Some(point) = trace(&loaded.scene, ray, lambda, mix64(band * 1_000_003 + k as u64)) else {
                continue;
            };
            let pixel = (DVec2::new(point.x, point.y) - centre).dot(axis) / PIXEL;
            // The main band only: ghosts from internal reflections land far away.
            if (pixel - predicted).abs() < 20.0 {
                sum += pixel;
                weight += 1.0;
            }
        }
        let centroid = sum / weight.max(1.0);
        let power = weight / PHOTONS as f64;
        let power_error = (power / expected_power - 1.0).abs();
        eprintln!(
            "{lambda} nm: n = {n:.5}, centroid {centroid:8.3} px, Snell {predicted:8.3} px, power {power:.4}, Fresnel {expected_power:.4}"
        );
        assert!(
            (centroid - predicted).abs() < 1.0,
            "{lambda} nm: centroid {centroid} px, Snell {predicted} px"
        );
        assert!(power_error < 0.02, "{lambda} nm: power {power}, Fresnel {expected_power}");
        // Teeth: the bands are resolved (blue bends more, by several pixels a band).
        if let Some(previous) = previous {
            assert!(
                (centroid - previous).abs() > 3.0,
                "bands {previous} and {centroid} px are not resolved"
            );
        }
        previous = Some(centroid);
        worst_pixels = worst_pixels.max((centroid - predicted).abs());
        worst_power = worst_power.max(power_error);
    }
    eprintln!(
        "worst centroid error {worst_pixels:.4} px, worst power error {:.3}%",
        100.0 * worst_power
    );
}
