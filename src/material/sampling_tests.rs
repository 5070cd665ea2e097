//! Sampling tests of every BSDF through [`Material`], as integrators call it
//! (Nori's `chi2test`, pbrt-v4's `bsdfs_test.cpp`).
//!
//! Non-delta lobes (diffuse, glossy GGX at several roughnesses and incident
//! angles, from both sides): a χ² goodness-of-fit test of the sampled
//! directions against `pdf`, and every sample's weight against
//! eval·|cos θi| / pdf. Delta lobes (mirror, dielectric): the dielectric's
//! choice between reflection and refraction χ²-tested against the Fresnel
//! reflectance, written independently here, and every direction checked
//! against the law of reflection and Snell's law.

use super::*;
use crate::math::chi_square::{ChiSquareOutcome, ChiSquareTest, SphericalCap, pearson_test, sidak_significance};

/// Probability that a family of tests of correct code fails anywhere (Šidák-
/// corrected per test). The seeds are fixed, so a run that passes always passes.
const FAMILY_SIGNIFICANCE: f64 = 0.01;
/// Agreement between a sample's weight or pdf and the same quantity from
/// eval and pdf: both are f64 formulas of the same direction, which differ
/// only by rounding (the half vector is recomputed from wo + wi).
const RELATIVE_TOLERANCE: f64 = 1e-9;

fn at() -> ShadingPoint {
    ShadingPoint {
        uv: DVec2::new(0.25, 0.5),
        point: DVec3::ZERO,
    }
}

/// The unit direction at polar angle `theta_degrees` and azimuth `phi`, on the
/// back side (z < 0) when `back`.
fn direction(theta_degrees: f64, phi: f64, back: bool) -> DVec3 {
    let (sin, cos) = theta_degrees.to_radians().sin_cos();
    let z = if back { -cos } else { cos };
    DVec3::new(sin * phi.cos(), sin * phi.sin(), z)
}

/// Sampling of `material` for `wo` tested against its pdf over the whole
/// sphere (bins on the wrong side must stay empty), while every sample is
/// checked to be non-specular, to carry `pdf`'s density and to weigh
/// eval·|cos θi| / pdf.
fn chi_square_of_sampling(material: &Material, wo: DVec3, seed: u64) -> ChiSquareOutcome {
    let test = ChiSquareTest {
        samples: 100_000,
        seed,
        bins: (16, 32),
    };
    test.directions(
        SphericalCap::SPHERE,
        |sampler| {
            let (u, u_lobe) = (sampler.next_2d(), sampler.next_1d());
            let sample = material.sample(wo, &at(), u, u_lobe, Transport::Radiance)?;
            let pdf = material.pdf(wo, sample.wi);
            let expected_weight = material.eval(wo, sample.wi, &at()) * sample.wi.z.abs() / pdf;
            assert!(!sample.specular && (sample.wi.length() - 1.0).abs() < 1e-12, "{sample:?}");
            assert!(
                (sample.pdf - pdf).abs() <= RELATIVE_TOLERANCE * pdf,
                "pdf {} against {pdf}",
                sample.pdf
            );
            assert!(
                (sample.weight - expected_weight).abs().max_element() <= RELATIVE_TOLERANCE * expected_weight.max_element(),
                "weight {} against eval·cos/pdf {expected_weight} for wo {wo}, wi {}",
                sample.weight,
                sample.wi
            );
            Some(sample.wi)
        },
        |wi| material.pdf(wo, wi),
    )
}

fn assert_accepted(name: &str, outcome: &ChiSquareOutcome, tests: usize) {
    let significance = sidak_significance(FAMILY_SIGNIFICANCE, tests);
    eprintln!("χ² {name}: {outcome}");
    assert!(
        outcome.accepts(significance),
        "{name} rejected at {significance:.2e}: {outcome}"
    );
}

#[test]
fn diffuse_sampling_fits_its_pdf_on_both_sides() {
    let material = Material::Diffuse {
        albedo: Texture::Constant(Color::new(0.9, 0.6, 0.3)),
    };
    let cases = [(10.0, false), (80.0, false), (10.0, true), (80.0, true)];
    for (index, &(theta, back)) in cases.iter().enumerate() {
        let wo = direction(theta, 0.7, back);
        let outcome = chi_square_of_sampling(&material, wo, 100 + index as u64);
        let side = if back { "back" } else { "front" };
        assert_accepted(&format!("diffuse, θo = {theta}° {side}"), &outcome, cases.len());
    }
}

/// GGX with visible-normal sampling: from a sharp lobe (α = 0.1) to the
/// roughest (α = 1), at normal, oblique and grazing incidence, on both sides.
#[test]
fn glossy_sampling_fits_its_pdf_at_every_roughness_angle_and_side() {
    let mut cases = Vec::new();
    for roughness in [0.1, 0.3, 0.7, 1.0] {
        for theta in [0.0, 45.0, 80.0] {
            for back in [false, true] {
                cases.push((roughness, theta, back));
            }
        }
    }
    for (index, &(roughness, theta, back)) in cases.iter().enumerate() {
        let material = Material::Glossy {
            tint: Texture::Constant(Color::new(0.9, 0.6, 0.3)),
            roughness,
        };
        let wo = direction(theta, 2.0, back);
        let outcome = chi_square_of_sampling(&material, wo, 200 + index as u64);
        let side = if back { "back" } else { "front" };
        assert_accepted(
            &format!("glossy α = {roughness}, θo = {theta}° {side}"),
            &outcome,
            cases.len(),
        );
    }
}

/// The test can fail: GGX samples drawn at α = 0.3 are rejected against the
/// pdf of α = 0.36, a lobe 20% wider.
#[test]
fn glossy_samples_are_rejected_against_a_wider_lobe() {
    let at = at();
    let wo = direction(45.0, 2.0, false);
    let sampled = Material::Glossy {
        tint: Texture::Constant(Color::ONE),
        roughness: 0.3,
    };
    let claimed = Material::Glossy {
        tint: Texture::Constant(Color::ONE),
        roughness: 0.36,
    };
    let test = ChiSquareTest {
        samples: 100_000,
        seed: 300,
        bins: (16, 32),
    };
    let outcome = test.directions(
        SphericalCap::SPHERE,
        |s| Some(sampled.sample(wo, &at, s.next_2d(), s.next_1d(), Transport::Radiance)?.wi),
        |wi| claimed.pdf(wo, wi),
    );
    eprintln!("χ² glossy α = 0.3 samples against the α = 0.36 pdf: {outcome}");
    assert!(outcome.p_value < 1e-12, "{outcome}");
}

/// Unpolarised Fresnel reflectance in Cook and Torrance's form (1982; Walter
/// et al. 2007, eq. 22), algebraically independent of the s/p form the
/// dielectric uses: with c = |cos θi| and g² = η² − 1 + c² (η = n_t / n_i),
/// F = ½ (g − c)² / (g + c)² · (1 + (c (g + c) − 1)² / (c (g − c) + 1)²),
/// and F = 1 when g² < 0 (total internal reflection).
fn fresnel_cook_torrance(c: f64, eta: f64) -> f64 {
    let g2 = eta * eta - 1.0 + c * c;
    if g2 < 0.0 {
        return 1.0;
    }
    let g = g2.sqrt();
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * a * a * (1.0 + b * b)
}

/// Reflections and refractions of the glass for `wo`, over `n` lobe choices
/// from an independent stream, with every direction checked: reflection
/// mirrors wo about the normal; refraction crosses to the other side in the
/// plane of incidence with n_i sin θi = n_t sin θt; each sample's `pdf` is
/// its lobe's probability; weights are the tint, divided by η² for radiance
/// refracted (Veach 1997, §5.2).
fn glass_lobe_counts(ior: f64, wo: DVec3, n: u32, seed: u64, transport: Transport) -> [u64; 2] {
    let tint = Color::new(0.9, 0.8, 0.7);
    let glass = Material::Glass {
        ior,
        tint,
        dispersion: None,
    };
    let eta = if wo.z > 0.0 { ior } else { 1.0 / ior };
    let reflectance = fresnel_cook_torrance(wo.z.abs(), eta);
    let mut counts = [0u64; 2];
    for index in 0..n {
        let mut sampler = crate::sampler::Sampler::new(crate::sampler::SamplerKind::Random, 0, index, seed);
        let (u, u_lobe) = (sampler.next_2d(), sampler.next_1d());
        let Some(s) = glass.sample(wo, &at(), u, u_lobe, transport) else {
            panic!("glass drew nothing for wo {wo}");
        };
        assert!(s.specular && (s.wi.length() - 1.0).abs() < 1e-12);
        if s.wi.z * wo.z > 0.0 {
            counts[0] += 1;
            assert!(
                (s.wi - reflect(wo)).length() < 1e-12,
                "law of reflection: wo {wo}, wi {}",
                s.wi
            );
            assert!((s.pdf - reflectance).abs() < 1e-12 && s.weight == tint);
        } else {
            counts[1] += 1;
            let (sin_i, sin_t) = (wo.truncate().length(), s.wi.truncate().length());
            assert!(
                (sin_i - eta * sin_t).abs() < 1e-12,
                "Snell: sin θi {sin_i}, η sin θt {}",
                eta * sin_t
            );
            // Opposite azimuth: wi's tangential part is −wo's, shortened by 1/η.
            assert!(
                (s.wi.truncate() + wo.truncate() / eta).length() < 1e-12,
                "plane of incidence: wo {wo}, wi {}",
                s.wi
            );
            assert!((s.pdf - (1.0 - reflectance)).abs() < 1e-12);
            let scale = if transport == Transport::Radiance {
                1.0 / (eta * eta)
            } else {
                1.0
            };
            assert!((s.weight - tint * scale).abs().max_element() < 1e-12, "weight {}", s.weight);
        }
    }
    counts
}

/// Incident directions for the glass: from outside at normal, oblique and
/// grazing incidence; from inside below and beyond the critical angle
/// (asin(1/1.5) ≈ 41.8° for glass, ≈ 48.8° for water), where every sample
/// must reflect.
const GLASS_CASES: [(f64, f64, bool); 12] = [
    (1.5, 0.0, false),
    (1.5, 45.0, false),
    (1.5, 75.0, false),
    (1.5, 89.0, false),
    (1.5, 30.0, true),
    (1.5, 41.0, true),
    (1.5, 43.0, true),
    (1.5, 70.0, true),
    (1.33, 20.0, false),
    (1.33, 80.0, false),
    (1.33, 45.0, true),
    (1.33, 60.0, true),
];

/// The lobe choice follows the Fresnel reflectance: χ² over the two
/// outcomes, expected N·F and N·(1 − F), with total internal reflection
/// included (F = 1: a single refraction rejects outright).
#[test]
fn glass_chooses_reflection_with_the_fresnel_probability() {
    let n = 20_000;
    for (index, &(ior, theta, inside)) in GLASS_CASES.iter().enumerate() {
        let wo = direction(theta, 0.4, inside);
        let eta = if inside { 1.0 / ior } else { ior };
        let reflectance = fresnel_cook_torrance(wo.z.abs(), eta);
        // Importance draws the same choices; its directions and weights are checked too.
        glass_lobe_counts(ior, wo, 1000, 400 + index as u64, Transport::Importance);
        let counts = glass_lobe_counts(ior, wo, n, 400 + index as u64, Transport::Radiance);
        let expected = [n as f64 * reflectance, n as f64 * (1.0 - reflectance)];
        let outcome = pearson_test(&counts, &expected, |i| ["reflected", "refracted"][i].to_string());
        let side = if inside { "inside" } else { "outside" };
        assert_accepted(&format!("glass η = {ior}, θo = {theta}° {side}"), &outcome, GLASS_CASES.len());
    }
}

/// The lobe test can fail: at 60° Schlick's approximation (F = 0.070 for
/// η = 1.5, against the exact 0.089) is rejected as the reflection probability.
#[test]
fn glass_lobe_choice_is_rejected_against_schlicks_approximation() {
    let (n, ior) = (20_000, 1.5);
    let wo = direction(60.0, 0.4, false);
    let counts = glass_lobe_counts(ior, wo, n, 500, Transport::Radiance);
    let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
    let schlick = f0 + (1.0 - f0) * (1.0 - wo.z).powi(5);
    let outcome = pearson_test(&counts, &[n as f64 * schlick, n as f64 * (1.0 - schlick)], |i| i.to_string());
    eprintln!("χ² glass lobes against Schlick's reflectance: {outcome}");
    assert!(outcome.p_value < 1e-12, "{outcome}");
}

/// The independent Fresnel agrees with the dielectric's own to rounding,
/// including the critical angle's neighbourhood (asin(1/1.5)).
#[test]
fn fresnel_forms_agree() {
    for i in 0..=200 {
        let c = i as f64 / 200.0;
        for ior in [1.33, 1.5, 2.4] {
            let outside = dielectric::fresnel_dielectric(c, ior);
            let inside = dielectric::fresnel_dielectric(-c, ior);
            assert!((outside - fresnel_cook_torrance(c, ior)).abs() < 1e-12, "cos {c}, η {ior}");
            assert!(
                (inside - fresnel_cook_torrance(c, 1.0 / ior)).abs() < 1e-12,
                "cos −{c}, η {ior}"
            );
        }
    }
}

/// The mirror reflects about the normal from either side, with probability
/// 1 and the tint as weight; as a delta lobe its eval and pdf are 0.
#[test]
fn mirror_obeys_the_law_of_reflection_on_both_sides() {
    let tint = Color::new(0.9, 0.8, 0.7);
    let mirror = Material::Mirror {
        tint: Texture::Constant(tint),
    };
    for theta in [0.0, 30.0, 60.0, 89.0] {
        for back in [false, true] {
            let wo = direction(theta, 1.1, back);
            let Some(s) = mirror.sample(wo, &at(), DVec2::new(0.3, 0.6), 0.5, Transport::Radiance) else {
                panic!("mirror drew nothing for wo {wo}");
            };
            // wi = 2 (n·wo) n − wo: equal angles, in the plane of n and wo.
            assert!((s.wi - (2.0 * wo.z * DVec3::Z - wo)).length() < 1e-15, "wo {wo}, wi {}", s.wi);
            assert!(s.specular && s.pdf == 1.0 && s.weight == tint);
            assert_eq!((mirror.eval(wo, s.wi, &at()), mirror.pdf(wo, s.wi)), (Color::ZERO, 0.0));
        }
    }
    // The exactly tangential direction has no side to reflect on.
    assert!(
        mirror
            .sample(DVec3::X, &at(), DVec2::ZERO, 0.0, Transport::Radiance)
            .is_none()
    );
}

/// `sample_inputs` must name every input `sample` reads: paths skip the
/// draws it says are unused, so changing an unused input must change nothing.
#[test]
fn sample_reads_only_the_inputs_it_declares() {
    let tint = Texture::Constant(Color::new(0.9, 0.6, 0.3));
    let materials = [
        Material::Diffuse { albedo: tint.clone() },
        Material::Glossy {
            tint: tint.clone(),
            roughness: 0.3,
        },
        Material::Mirror { tint },
        Material::Glass {
            ior: 1.5,
            tint: Color::ONE,
            dispersion: None,
        },
    ];
    let inputs = [
        (DVec2::new(0.1, 0.7), 0.02),
        (DVec2::new(0.8, 0.3), 0.97),
        (DVec2::new(0.45, 0.55), 0.5),
    ];
    for material in &materials {
        let (uses_direction, uses_lobe) = material.sample_inputs();
        for wo in [
            direction(10.0, 0.3, false),
            direction(70.0, 2.0, false),
            direction(40.0, 1.0, true),
        ] {
            for &(u, u_lobe) in &inputs {
                let reference = material.sample(wo, &at(), u, u_lobe, Transport::Radiance);
                let other_u = if uses_direction { u } else { DVec2::new(0.999, 0.001) };
                let other_lobe = if uses_lobe { u_lobe } else { 0.123 };
                let varied = material.sample(wo, &at(), other_u, other_lobe, Transport::Radiance);
                assert_eq!(format!("{reference:?}"), format!("{varied:?}"), "{material:?}");
            }
        }
    }
    // And the inputs declared used do matter.
    let glass = &materials[3];
    let wo = direction(30.0, 0.0, false);
    let reflect = glass.sample(wo, &at(), DVec2::ZERO, 0.0, Transport::Radiance);
    let refract = glass.sample(wo, &at(), DVec2::ZERO, 0.999, Transport::Radiance);
    assert_ne!(format!("{reflect:?}"), format!("{refract:?}"));
}
