//! Which pixels trace SPPM's extra camera paths for the emitted term.
//!
//! A pixel's emitted term (lights seen directly, or through mirrors and
//! glass, and a non-black background) is the mean of its camera paths'
//! emission, and a camera path collects emission only until it meets a
//! diffuse or glossy surface. A path whose first surface is diffuse or
//! glossy therefore contributes exactly zero, and extra paths (the
//! integrator's `EMISSION_SAMPLES`) pay only in pixels whose footprint may
//! meet an emitter or a shining background, directly or through mirrors
//! and glass. Those
//! pixels are found once per render by probe rays through fixed points of
//! each pixel, dilated by one pixel so that the image of a light seen at a
//! neighbour's centre counts here too; the others trace only the path that
//! also leaves their visible point.
//!
//! A probe that meets a mirror or glass follows every specular branch whose
//! lobe probabilities multiply to at least [`BRANCH_CUTOFF`] (both the
//! reflection and the refraction of glass, weighted by Fresnel's
//! reflectance), so a glass object is flagged only where a light or a
//! shining background can be seen in it or through it: a camera path
//! through glass that ends on a diffuse surface also finds no emission.
//!
//! The estimate stays unbiased whatever the probes find: how many paths a
//! pixel traces depends on the scene and the camera alone, never on the
//! render's random draws, so each iteration's mean over a pixel's paths has
//! the emitted term's expectation. A pixel the probes misjudge (a light
//! smaller than a pixel between the probes) is only noisier, with one path
//! instead of several. The probes depend on nothing random either, so every
//! thread count and every farm share finds the same pixels.

use crate::camera::Camera;
use crate::color::Color;
use crate::material::{ShadingPoint, Transport};
use crate::math::{DVec2, DVec3, Frame as ShadingFrame, Ray};
use crate::scene::Scene;
use crate::settings::PixelRect;
use arrayvec::ArrayVec;
use rayon::prelude::*;

/// The smallest product of lobe probabilities a probe still follows through
/// mirrors and glass. Fresnel reflection off glass (≈ 4% at normal
/// incidence) is followed once, not twice: a light seen only after two
/// partial reflections is dim and rare, and its pixels are only noisier.
const BRANCH_CUTOFF: f64 = 0.01;

/// Ray casts one probe may make through specular chains; a probe that needs
/// more (a hall of mirrors) flags its pixel rather than searching on.
const PROBE_CASTS: u32 = 32;

/// Specular branches a probe keeps waiting at once.
const PROBE_BRANCHES: usize = 16;

/// Points on the lens a thin-lens camera's probes start from, as lens
/// samples in \[0,1\]²: the centre and four points at 0.7 of its radius (a
/// defocused light's image spreads over the pixels whose lens points see it).
const LENS_PROBES: [DVec2; 5] = [
    DVec2::new(0.5, 0.5),
    DVec2::new(0.15, 0.5),
    DVec2::new(0.85, 0.5),
    DVec2::new(0.5, 0.15),
    DVec2::new(0.5, 0.85),
];

/// Per pixel of a `width` × `height` image, row-major: whether its
/// footprint may meet emission along a camera path, so that extra
/// emission-only paths can find some. Pixels neither in `sampled` nor next
/// to it are not probed (they are never rendered).
pub fn pixels_that_may_see_emission(
    scene: &Scene,
    camera: &Camera,
    (width, height): (u32, u32),
    sampled: PixelRect,
    max_depth: u32,
) -> Vec<bool> {
    let lens_points: &[DVec2] = if camera.has_lens() { &LENS_PROBES } else { &LENS_PROBES[..1] };
    let background_shines = scene.background != Color::ZERO;
    let near_sampled = |x: u32, y: u32| {
        let (x0, y0) = (x.saturating_sub(1), y.saturating_sub(1));
        (y0..=y + 1).any(|ny| (x0..=x + 1).any(|nx| sampled.contains(nx, ny)))
    };
    let probed: Vec<bool> = (0..width as usize * height as usize)
        .into_par_iter()
        .map(|index| {
            let (x, y) = ((index % width as usize) as u32, (index / width as usize) as u32);
            if !near_sampled(x, y) {
                return false;
            }
            let film = DVec2::new((x as f64 + 0.5) / width as f64, (y as f64 + 0.5) / height as f64);
            lens_points.iter().any(|&lens| {
                let ray = camera.generate_ray(film, width as f64 / height as f64, lens);
                probe_finds_emission(scene, ray, background_shines, max_depth)
            })
        })
        .collect();
    // Dilate by one pixel: a pixel counts if it or a neighbour was found.
    (0..probed.len())
        .into_par_iter()
        .map(|index| {
            let (x, y) = (index % width as usize, index / width as usize);
            let (x0, y0) = (x.saturating_sub(1), y.saturating_sub(1));
            let (x1, y1) = ((x + 1).min(width as usize - 1), (y + 1).min(height as usize - 1));
            (y0..=y1).any(|ny| (x0..=x1).any(|nx| probed[ny * width as usize + nx]))
        })
        .collect()
}

/// Whether a camera path along `ray` may collect emission: it meets an
/// emitter, or escapes into a shining background, directly or through
/// mirrors and glass, following each specular branch that is likely enough
/// (see [`BRANCH_CUTOFF`]) for up to `max_depth` bounces, as camera paths do.
fn probe_finds_emission(scene: &Scene, ray: Ray, background_shines: bool, max_depth: u32) -> bool {
    // (ray, product of the lobe probabilities so far, bounces so far)
    let mut branches: ArrayVec<(Ray, f64, u32), PROBE_BRANCHES> = ArrayVec::new();
    branches.push((ray, 1.0, 0));
    let mut casts = 0;
    while let Some((ray, probability, depth)) = branches.pop() {
        casts += 1;
        if casts > PROBE_CASTS {
            return true;
        }
        let Some(found) = scene.intersect(&ray, f64::INFINITY) else {
            if background_shines {
                return true;
            }
            continue;
        };
        let material = scene.material_of(found.primitive);
        if !material.scatters() {
            return true;
        }
        if !material.is_specular() || depth >= max_depth {
            continue;
        }
        let hit = found.hit;
        let frame = ShadingFrame::from_normal(hit.shading_normal);
        let wo = frame.to_local(-ray.direction);
        let at = ShadingPoint {
            uv: hit.uv,
            point: hit.point,
        };
        // The lobe sample picks reflection below Fresnel's reflectance and
        // refraction above it: these two reach both lobes where both exist.
        let mut followed: Option<DVec3> = None;
        for u_lobe in [0.0, 1.0 - f64::EPSILON / 2.0] {
            let Some(sample) = material.sample(wo, &at, DVec2::splat(0.5), u_lobe, Transport::Radiance) else {
                continue;
            };
            let probability = probability * sample.pdf.min(1.0);
            if followed == Some(sample.wi) || probability < BRANCH_CUTOFF {
                continue;
            }
            followed = Some(sample.wi);
            let next = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, frame.to_world(sample.wi));
            if branches.try_push((next, probability, depth + 1)).is_err() {
                return true;
            }
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load_scene_str;
    use std::path::Path;

    /// A diffuse wall filling the view, a glass ball and a small light in
    /// front of it, seen by a pinhole camera at 40 × 30.
    const WALL_BALL_LIGHT: &str = r#"
        [camera]
        position = [0, 0, -10]
        look_at = [0, 0, 0]
        fov_y_degrees = 40
        [render]
        width = 40
        height = 30
        [materials.wall]
        type = "diffuse"
        albedo = [0.5, 0.5, 0.5]
        [materials.glass]
        type = "glass"
        ior = 1.5
        [materials.light]
        type = "emissive"
        radiance = [5, 5, 5]
        [[objects]]
        type = "quad"
        corner = [-50, -50, 5]
        edge_u = [100, 0, 0]
        edge_v = [0, 100, 0]
        material = "wall"
        [[objects]]
        type = "sphere"
        center = [-1.5, 0, 0]
        radius = 1
        material = "glass"
        [[objects]]
        type = "sphere"
        center = [2, 1, 0]
        radius = 0.3
        material = "light"
    "#;

    fn flagged(text: &str) -> (Vec<bool>, u32, u32) {
        let loaded = load_scene_str(text, Path::new("<test>"), Path::new(".")).expect("test scene parses");
        let (width, height) = (loaded.settings.width, loaded.settings.height);
        let flags = pixels_that_may_see_emission(
            &loaded.scene,
            &loaded.camera,
            (width, height),
            loaded.settings.sampled_pixels(),
            loaded.settings.max_depth,
        );
        (flags, width, height)
    }

    /// The material a pixel's centre sees first.
    fn seen_at_centre(loaded: &crate::scene::LoadedScene, x: i64, y: i64) -> Option<&'static str> {
        let (width, height) = (loaded.settings.width as i64, loaded.settings.height as i64);
        if x < 0 || y < 0 || x >= width || y >= height {
            return None;
        }
        let film = DVec2::new((x as f64 + 0.5) / width as f64, (y as f64 + 0.5) / height as f64);
        let ray = loaded
            .camera
            .generate_ray(film, width as f64 / height as f64, DVec2::splat(0.5));
        let found = loaded.scene.intersect(&ray, f64::INFINITY)?;
        Some(match loaded.scene.material_of(found.primitive) {
            crate::material::Material::Emissive { .. } => "light",
            crate::material::Material::Glass { .. } => "glass",
            _ => "other",
        })
    }

    /// The light's image and a one-pixel ring around it are flagged; the
    /// glass ball, through which the camera sees only the diffuse wall, is
    /// not (but for the few pixels that show the light reflected in it).
    #[test]
    fn flags_the_image_of_a_light_and_its_neighbours_not_glass_that_shows_none() {
        let loaded = load_scene_str(WALL_BALL_LIGHT, Path::new("<test>"), Path::new(".")).expect("test scene parses");
        let (flags, width, height) = flagged(WALL_BALL_LIGHT);
        let (mut light_ring, mut glass, mut glass_flagged) = (0, 0, 0);
        for y in 0..height as i64 {
            for x in 0..width as i64 {
                let flag = flags[(y * width as i64 + x) as usize];
                let near_light = (-1..=1).any(|dy| (-1..=1).any(|dx| seen_at_centre(&loaded, x + dx, y + dy) == Some("light")));
                if near_light {
                    assert!(flag, "pixel ({x}, {y}) is next to the light's image");
                    light_ring += 1;
                } else if seen_at_centre(&loaded, x, y) == Some("glass") {
                    glass += 1;
                    glass_flagged += usize::from(flag);
                }
            }
        }
        assert!(light_ring >= 9, "{light_ring} pixels around the light");
        assert!(glass > 30, "{glass} pixels see the ball");
        assert!(glass_flagged * 4 < glass, "{glass_flagged} of {glass} glass pixels flagged");
    }

    /// A light seen only through a glass ball (behind it, on the camera's
    /// axis) flags the ball's centre; the same ball in front of a diffuse
    /// sphere flags nothing.
    #[test]
    fn a_light_seen_through_glass_is_flagged() {
        let behind = WALL_BALL_LIGHT
            .replace("center = [-1.5, 0, 0]", "center = [0, 0, 0]")
            .replace("center = [2, 1, 0]", "center = [0, 0, 2]");
        let loaded = load_scene_str(&behind, Path::new("<test>"), Path::new(".")).expect("test scene parses");
        let (flags, width, height) = flagged(&behind);
        let (cx, cy) = (width as i64 / 2, height as i64 / 2);
        assert_eq!(seen_at_centre(&loaded, cx, cy), Some("glass"));
        assert!(flags[(cy * width as i64 + cx) as usize], "the light behind the ball");

        let dark = behind.replace(
            "type = \"emissive\"\n        radiance = [5, 5, 5]",
            "type = \"diffuse\"\n        albedo = [0.5, 0.5, 0.5]",
        );
        assert_ne!(dark, behind);
        let (flags, ..) = flagged(&dark);
        assert!(flags.iter().all(|&f| !f), "nothing emits");
    }

    /// A non-black background is emission too: pixels seeing it are flagged.
    #[test]
    fn a_shining_background_is_emission() {
        let text = WALL_BALL_LIGHT.replace("corner = [-50, -50, 5]", "corner = [0, -50, 5]");
        let (dark, ..) = flagged(&text);
        let (lit, ..) = flagged(&format!("background = [0.1, 0.2, 0.3]\n{text}"));
        let (dark_count, lit_count) = (dark.iter().filter(|&&f| f).count(), lit.iter().filter(|&&f| f).count());
        assert!(lit_count > dark_count + 300, "{dark_count} → {lit_count}");
        assert!(dark.iter().zip(&lit).all(|(&d, &l)| !d || l));
    }
}
