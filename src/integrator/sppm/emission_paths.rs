//! Which pixels trace SPPM's extra camera paths for the emitted term.
//!
//! A pixel's emitted term (lights seen directly, or through mirrors and
//! glass, and a non-black background) is the mean of its camera paths'
//! emission, and a camera path collects emission only until it meets a
//! diffuse or glossy surface. A path whose first surface is diffuse or
//! glossy therefore contributes exactly zero, and extra paths (the
//! integrator's `EMISSION_SAMPLES`) pay only in pixels whose footprint may
//! first meet an emitter, a mirror or glass, or the background. Those
//! pixels are found once per render by probe rays through fixed points of
//! each pixel, dilated by one pixel so that the image of a light or a glass
//! object seen at a neighbour's centre counts here too; the others trace
//! only the path that also leaves their visible point.
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
use crate::math::DVec2;
use crate::scene::Scene;
use crate::settings::PixelRect;
use rayon::prelude::*;

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
                match scene.intersect(&ray, f64::INFINITY) {
                    None => background_shines,
                    Some(found) => {
                        let material = scene.material_of(found.primitive);
                        !material.scatters() || material.is_specular()
                    }
                }
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
        );
        (flags, width, height)
    }

    /// The pixels flagged are the ball's and the light's images and a
    /// one-pixel ring around them: every pixel whose centre sees either is
    /// flagged, and every pixel with no such centre within one pixel is not.
    #[test]
    fn flags_the_images_of_lights_and_glass_and_their_neighbours() {
        let loaded = load_scene_str(WALL_BALL_LIGHT, Path::new("<test>"), Path::new(".")).expect("test scene parses");
        let (flags, width, height) = flagged(WALL_BALL_LIGHT);
        let sees = |x: i64, y: i64| {
            if x < 0 || y < 0 || x >= width as i64 || y >= height as i64 {
                return false;
            }
            let film = DVec2::new((x as f64 + 0.5) / width as f64, (y as f64 + 0.5) / height as f64);
            let ray = loaded
                .camera
                .generate_ray(film, width as f64 / height as f64, DVec2::splat(0.5));
            let found = loaded.scene.intersect(&ray, f64::INFINITY).expect("the wall fills the view");
            let material = loaded.scene.material_of(found.primitive);
            !matches!(material, crate::material::Material::Diffuse { .. })
        };
        let mut count = 0;
        for y in 0..height as i64 {
            for x in 0..width as i64 {
                let near = (-1..=1).any(|dy| (-1..=1).any(|dx| sees(x + dx, y + dy)));
                assert_eq!(flags[(y * width as i64 + x) as usize], near, "pixel ({x}, {y})");
                count += usize::from(near);
            }
        }
        // Both objects are seen, and most of the wall is not flagged.
        assert!(count > 20 && count < flags.len() / 3, "{count} of {} flagged", flags.len());
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
