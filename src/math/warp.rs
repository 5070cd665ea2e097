//! Warps from the unit square to sampling domains, each with its density
//! (pbrt-v4 appendix A.5, Nori's warp.cpp).

use super::lane_mask::select;
use super::trig::{cos_sin_eighth, cos_sin_turns};
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_1_PI, FRAC_PI_4, PI};

/// Uniform point on the unit disk, Shirley–Chiu concentric map (keeps strata;
/// Shirley & Chiu 1997, "A Low Distortion Map Between Disk and Square").
pub fn square_to_concentric_disk(u: DVec2) -> DVec2 {
    let o = 2.0 * u - DVec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return DVec2::ZERO;
    }
    // The coordinate of larger magnitude is the radius, the other over it
    // the angle a within its octant; about the y axis θ = π/2 − a, so
    // cos θ = sin a and sin θ = cos a. Which octant is a coin toss per
    // sample: one computation with its operands chosen by selects (mask
    // operations, not a branch) instead of two behind a mispredicted branch.
    let x_major = o.x.abs() > o.y.abs();
    let (radius, other) = (select(x_major, o.x, o.y), select(x_major, o.y, o.x));
    let (cos, sin) = cos_sin_eighth(FRAC_PI_4 * (other / radius));
    radius * DVec2::new(select(x_major, cos, sin), select(x_major, sin, cos))
}

/// Cosine-weighted direction on the +z hemisphere (Malley's method).
/// Inlined, so the direction reaches the caller in registers, not through
/// a returned record read back in pieces.
#[inline]
pub fn square_to_cosine_hemisphere(u: DVec2) -> DVec3 {
    let d = square_to_concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    DVec3::new(d.x, d.y, z)
}

/// Density of `square_to_cosine_hemisphere`, per steradian.
pub fn cosine_hemisphere_pdf(cos_theta: f64) -> f64 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// Uniform direction on the unit sphere.
pub fn square_to_uniform_sphere(u: DVec2) -> DVec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (cos_phi, sin_phi) = cos_sin_turns(u.y);
    DVec3::new(r * cos_phi, r * sin_phi, z)
}

/// Density of `square_to_uniform_sphere`, per steradian: 1 / 4π.
pub const UNIFORM_SPHERE_PDF: f64 = 1.0 / (4.0 * PI);

/// Uniform direction in the cone of half-angle `acos(cos_theta_max)` around +z.
pub fn square_to_uniform_cone(u: DVec2, cos_theta_max: f64) -> DVec3 {
    let (cos_theta, azimuth) = square_to_uniform_cone_angles(u, cos_theta_max);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    DVec3::new(sin_theta * azimuth.x, sin_theta * azimuth.y, cos_theta)
}

/// The polar angle's cosine and the azimuth of [`square_to_uniform_cone`]:
/// cos θ uniform in [cos θmax, 1] (the cone's solid angle is linear in cos θ),
/// and (cos φ, sin φ) for φ uniform in [0, 2π).
pub fn square_to_uniform_cone_angles(u: DVec2, cos_theta_max: f64) -> (f64, DVec2) {
    let (cos_phi, sin_phi) = cos_sin_turns(u.y);
    ((1.0 - u.x) + u.x * cos_theta_max, DVec2::new(cos_phi, sin_phi))
}

/// Density of `square_to_uniform_cone`, per steradian: one over the cone's
/// solid angle 2π (1 − cos θmax).
pub fn uniform_cone_pdf(cos_theta_max: f64) -> f64 {
    1.0 / (2.0 * PI * (1.0 - cos_theta_max))
}

/// Barycentric coordinates (b1, b2) uniform over a triangle (Heitz 2019,
/// "A Low-Distortion Map Between Triangle and Square").
pub fn square_to_uniform_triangle(u: DVec2) -> DVec2 {
    if u.y > u.x {
        let b0 = u.x / 2.0;
        let b1 = u.y - b0;
        DVec2::new(b0, b1)
    } else {
        let b1 = u.y / 2.0;
        let b0 = u.x - b1;
        DVec2::new(b0, b1)
    }
}

/// Power heuristic with β = 2 (Veach 1997, eq. 9.13), for the sample drawn
/// with density `pdf_a` against the competing strategy `pdf_b`.
pub fn power_heuristic(pdf_a: f64, pdf_b: f64) -> f64 {
    let a = pdf_a * pdf_a;
    let b = pdf_b * pdf_b;
    if a.is_infinite() {
        return 1.0;
    }
    if a + b == 0.0 { 0.0 } else { a / (a + b) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::chi_square::{ChiSquareOutcome, ChiSquareTest, SphericalCap, sidak_significance};

    fn grid(n: usize) -> impl Iterator<Item = DVec2> {
        (0..n * n).map(move |i| DVec2::new(((i % n) as f64 + 0.5) / n as f64, ((i / n) as f64 + 0.5) / n as f64))
    }

    #[test]
    fn cosine_hemisphere_integrates_cos_over_pdf_to_pi() {
        // E[cos / pdf] = π exactly for this density.
        let n = 64;
        let mean: f64 = grid(n)
            .map(|u| {
                let w = square_to_cosine_hemisphere(u);
                w.z / cosine_hemisphere_pdf(w.z)
            })
            .sum::<f64>()
            / (n * n) as f64;
        assert!((mean - PI).abs() < 1e-9);
    }

    #[test]
    fn warps_land_in_their_domains() {
        for u in grid(32) {
            assert!(square_to_concentric_disk(u).length() <= 1.0 + 1e-12);
            assert!((square_to_uniform_sphere(u).length() - 1.0).abs() < 1e-12);
            let c = square_to_uniform_cone(u, 0.9);
            assert!(c.z >= 0.9 - 1e-12);
            let b = square_to_uniform_triangle(u);
            assert!(b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 + 1e-12);
        }
    }

    /// The χ² tests of the warps below: a family of six at 1% together
    /// (Šidák), each over 50 000 independent samples.
    const CHI_SQUARE_TESTS: usize = 6;

    fn chi_square(seed: u64, bins: (usize, usize)) -> ChiSquareTest {
        ChiSquareTest {
            samples: 50_000,
            seed,
            bins,
        }
    }

    fn assert_accepted(name: &str, outcome: ChiSquareOutcome) {
        let significance = sidak_significance(0.01, CHI_SQUARE_TESTS);
        eprintln!("χ² {name}: {outcome}");
        assert!(
            outcome.accepts(significance),
            "{name} rejected at {significance:.2e}: {outcome}"
        );
    }

    /// The branch-free map is Shirley and Chiu's: radius the larger
    /// coordinate, angle π/4 · (smaller / larger) from the x axis, or its
    /// complement from the y axis, to within a few ulps of the library's
    /// sine and cosine, in every octant and on the diagonals between them.
    #[test]
    fn concentric_disk_is_shirley_and_chius_map() {
        let n = 64;
        for i in 0..=n {
            for j in 0..=n {
                let u = DVec2::new(i as f64 / n as f64, j as f64 / n as f64);
                let o = 2.0 * u - DVec2::ONE;
                let expected = if o.x == 0.0 && o.y == 0.0 {
                    DVec2::ZERO
                } else if o.x.abs() > o.y.abs() {
                    let angle = FRAC_PI_4 * (o.y / o.x);
                    o.x * DVec2::new(angle.cos(), angle.sin())
                } else {
                    let angle = std::f64::consts::FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y);
                    o.y * DVec2::new(angle.cos(), angle.sin())
                };
                let found = square_to_concentric_disk(u);
                assert!(
                    (found - expected).abs().max_element() <= 4.0 * f64::EPSILON,
                    "{u}: {found} against {expected}"
                );
            }
        }
    }

    /// Uniform on the unit disk: density 1/π inside, binned over [−1, 1]² so
    /// that points outside the disk fall in bins expecting none.
    #[test]
    fn concentric_disk_fits_its_density() {
        let outcome = chi_square(11, (16, 16)).planar(
            (-1.0, 1.0),
            (-1.0, 1.0),
            |s| Some(square_to_concentric_disk(s.next_2d())),
            |p| if p.length_squared() <= 1.0 { FRAC_1_PI } else { 0.0 },
        );
        assert_accepted("concentric disk", outcome);
    }

    /// Density cos θ / π on the upper hemisphere, binned over it (samples
    /// below the horizon would land "elsewhere", where none are expected).
    #[test]
    fn cosine_hemisphere_fits_its_density() {
        let hemisphere = SphericalCap {
            axis: DVec3::Z,
            cos_theta_min: 0.0,
        };
        let outcome = chi_square(12, (10, 20)).directions(
            hemisphere,
            |s| Some(square_to_cosine_hemisphere(s.next_2d())),
            |w| cosine_hemisphere_pdf(w.z),
        );
        assert_accepted("cosine hemisphere", outcome);
    }

    #[test]
    fn uniform_sphere_fits_its_density() {
        let outcome = chi_square(13, (10, 20)).directions(
            SphericalCap::SPHERE,
            |s| Some(square_to_uniform_sphere(s.next_2d())),
            |_| UNIFORM_SPHERE_PDF,
        );
        assert_accepted("uniform sphere", outcome);
    }

    /// A narrow cone and one wider than a hemisphere, each binned over its
    /// own cap so that every bin has samples to compare.
    #[test]
    fn uniform_cones_fit_their_density() {
        for (seed, cos_theta_max) in [(14, 0.8), (15, -0.3)] {
            let cap = SphericalCap {
                axis: DVec3::Z,
                cos_theta_min: cos_theta_max,
            };
            let outcome = chi_square(seed, (10, 20)).directions(
                cap,
                |s| Some(square_to_uniform_cone(s.next_2d(), cos_theta_max)),
                |w| {
                    if w.z >= cos_theta_max {
                        uniform_cone_pdf(cos_theta_max)
                    } else {
                        0.0
                    }
                },
            );
            assert_accepted(&format!("uniform cone, cos θmax = {cos_theta_max}"), outcome);
        }
    }

    /// Barycentrics uniform over the triangle b₁, b₂ ≥ 0, b₁ + b₂ ≤ 1: density
    /// 2 there (the triangle has area ½), binned over the unit square.
    #[test]
    fn uniform_triangle_fits_its_density() {
        let outcome = chi_square(16, (16, 16)).planar(
            (0.0, 1.0),
            (0.0, 1.0),
            |s| Some(square_to_uniform_triangle(s.next_2d())),
            |b| if b.x + b.y <= 1.0 { 2.0 } else { 0.0 },
        );
        assert_accepted("uniform triangle", outcome);
    }

    /// The test can fail: cosine-weighted directions checked against the
    /// uniform hemisphere's density 1/(2π) are rejected beyond doubt.
    #[test]
    fn cosine_samples_are_rejected_against_the_uniform_hemisphere_density() {
        let hemisphere = SphericalCap {
            axis: DVec3::Z,
            cos_theta_min: 0.0,
        };
        let outcome = chi_square(12, (10, 20)).directions(
            hemisphere,
            |s| Some(square_to_cosine_hemisphere(s.next_2d())),
            |_| 1.0 / (2.0 * PI),
        );
        eprintln!("χ² cosine samples against the uniform hemisphere: {outcome}");
        assert!(outcome.p_value < 1e-12, "{outcome}");
    }

    #[test]
    fn triangle_map_is_uniform_in_the_mean() {
        // The centroid of a uniform density over the triangle is (1/3, 1/3).
        let n = 128;
        let mean = grid(n).map(square_to_uniform_triangle).sum::<DVec2>() / (n * n) as f64;
        assert!((mean - DVec2::splat(1.0 / 3.0)).length() < 1e-3);
    }
}
