//! Lights seen in a mirror ball through the lens: paths lens → mirror ball
//! → light, traced from both ends and weighted between the two.
//!
//! A camera ray finds such a path only by reflecting off the ball straight
//! into the light. Where the light's reflection is small (a distant sun in
//! a chrome ball, smaller than a pixel) and out of focus, the lens spreads
//! it over a disc of pixels, and each pixel's camera samples land on it
//! only when the lens point happens to line up with it: rare, bright
//! samples (the depth-of-field scene's noise is mostly these).
//!
//! From the other end the path is solved for: a lens point x and a point y
//! on a light are drawn, the reflection off the ball from x to y is found
//! ([`BallOptics::paths`](crate::geometry::BallOptics::paths), Alhazen's
//! problem) and splatted to the pixel its first leg shows on. It adds
//!
//!   Le(y) · tint · W · 1 / (dA_y/dω · p_A(y))
//!
//! to the film-wide measurement, where W = 1 / (A_film cos³θ) is the
//! camera's importance per unit solid angle at the lens (see
//! [`Camera::connect`]) and dA_y/dω the ball's spread of the bundle
//! (the generalised geometry term, as in [`super::ball_connection`]).
//!
//! Neither strategy is better everywhere: a reflection larger than a pixel
//! and in focus is found by every camera sample inside it (no noise),
//! while the splats land in its pixels in random numbers. So the two are
//! combined with weights that sum to one on every path (Veach 1997 §9.2,
//! which allows any such weights): the connection's share is 1 / (1 + r²),
//! where r compares the light's image as seen in the ball from that lens
//! point (the pixel count over the film density of the splats, p_A ·
//! dA_y/dω · A_film cos³θ) with the blur the lens spreads it over (one
//! pixel plus the circle of confusion at the ball): r ≪ 1 where camera
//! rays hit the image seldom, r ≫ 1 where every one inside it does. Both
//! ends compute r from the same path, so the weights sum to one and the
//! estimate stays unbiased.
//!
//! Where the shares are small (the Cornell box's light in its mirror ball
//! through a pinhole) the connections are made only some of the time,
//! with their weight raised to match (Russian roulette): the camera rays
//! do that work better.

use super::ball_connection::{light_point_seen_by, unoccluded};
use crate::camera::{Camera, FilmConnection};
use crate::color::Color;
use crate::geometry::{AreaSample, BallPath, Bounce};
use crate::light::{EmitterSource, Light};
use crate::math::Ray;
use crate::sampler::{Sampler, SamplerKind};
use crate::scene::{MAX_SPECULAR_BALLS, Scene, SpecularBall};
use glam::{DVec2, DVec3};

/// Connections whose share is below this are made with probability share /
/// `SHARE_KEPT` (but at least [`LEAST_SURVIVAL`]; Russian roulette, their
/// weight raised to match), which spares the work of those the camera rays
/// do nearly all the work for (a reflection many pixels wide).
const SHARE_KEPT: f64 = 0.5;

/// Connections per mirror ball that a render's first pass makes in advance
/// (without shadow rays) to find the mean share the ball's paths get.
const PILOT_CONNECTIONS: u64 = 64;

/// Least probability with which a connection off a ball is made at all.
const LEAST_SURVIVAL: f64 = 1.0 / 32.0;

/// The seed of the pilot's (independent) samples.
const PILOT_SEED: u64 = 0x9110_7c0f_fee5;

/// The camera and image size, which both strategies need to weight a path,
/// and how often connections off each ball are made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensView {
    camera: Camera,
    width: u32,
    height: u32,
    /// Per specular ball (as [`Scene::specular_balls`] lists them), the
    /// probability that a connection off it is tried at all: below 1 where
    /// the pilot's shares were small on average (a reflection many pixels
    /// wide, which camera rays find well), so that its connections, which
    /// would add little, cost little.
    survival: [f64; MAX_SPECULAR_BALLS],
}

/// Whether `scene` has paths for lens connections: a mirror ball and a
/// light that is not clipped (a clipped sphere's visible cap depends on
/// where it is seen from, which the weights would have to follow).
pub fn scene_has_lens_connections(scene: &Scene) -> bool {
    scene.specular_balls().iter().any(|ball| ball.bounce == Bounce::Off)
        && scene.lights.lights.iter().any(|light| light.clipped.is_none())
}

/// One path lens → ball → light, solved for but not yet tested for
/// occlusion.
struct Candidate {
    path: BallPath,
    film: FilmConnection,
    light_point: AreaSample,
    /// The connection's share of the path.
    share: f64,
    /// Its contribution per unit emitted radiance before the share: the
    /// importance per unit solid angle over the density of the light point
    /// per unit solid angle at the lens, times the pixel count.
    weight: f64,
}

impl LensView {
    /// The view of `camera` on an image of `width` × `height` pixels of
    /// `scene`, with a pilot of connections off each mirror ball.
    pub fn new(scene: &Scene, camera: &Camera, (width, height): (u32, u32)) -> Self {
        let balls = scene.specular_balls();
        let mut view = Self {
            camera: *camera,
            width,
            height,
            survival: [1.0; MAX_SPECULAR_BALLS],
        };
        let (mut shares, mut counts) = ([0.0f64; MAX_SPECULAR_BALLS], [0u32; MAX_SPECULAR_BALLS]);
        for index in 0..PILOT_CONNECTIONS {
            let mut sampler = Sampler::new(SamplerKind::Random, index, 0, PILOT_SEED);
            let (lens, u_select, u_light) = (sampler.next_2d(), sampler.next_1d(), sampler.next_2d());
            let Some((light, selection)) = view.light(scene, u_select) else {
                continue;
            };
            for (b, ball) in balls.iter().enumerate() {
                view.candidates(scene, ball, lens, (light, selection), u_light, |candidate| {
                    shares[b] += candidate.share;
                    counts[b] += 1;
                });
            }
        }
        for ((survival, share), count) in view.survival.iter_mut().zip(shares).zip(counts) {
            let mean_share = if count > 0 { share / count as f64 } else { 0.0 };
            *survival = (mean_share / SHARE_KEPT).clamp(LEAST_SURVIVAL, 1.0);
        }
        view
    }

    fn aspect(&self) -> f64 {
        self.width as f64 / self.height as f64
    }

    fn pixel_count(&self) -> f64 {
        self.width as f64 * self.height as f64
    }

    /// The light `u_select` chooses, with its probability, unless it is clipped.
    fn light<'a>(&self, scene: &'a Scene, u_select: f64) -> Option<(&'a Light, f64)> {
        let (index, selection) = scene.lights.choose(u_select)?;
        let light = &scene.lights.lights[index as usize];
        light.clipped.is_none().then_some((light, selection))
    }

    /// The connection's share of `path`, which leaves the lens to a mirror
    /// ball and goes on to a light point drawn with area density
    /// `area_pdf`, the ball spreading the bundle by `spread` (dA/dω).
    fn connection_share(&self, path: &BallPath, spread: f64, area_pdf: f64) -> f64 {
        let cos = path.direction.dot(self.camera.forward());
        // Splats per unit of film (the film being 1 × 1) from one lens
        // point: the light's image there covers the pixel count over that.
        let film_density = area_pdf * spread * self.camera.film_area(self.aspect()) * cos * cos * cos;
        let image = self.pixel_count() / film_density;
        // Camera rays find the image in a pixel as often as the image
        // covers the pixel and the blur around it.
        let relative = image / (1.0 + self.blur_pixels(path.entry));
        let share = 1.0 / (1.0 + relative * relative);
        if share.is_finite() { share } else { 0.0 }
    }

    /// Pixels the lens spreads a point at `point`'s depth over: the circle
    /// of confusion, radius a·|z − f| / z on the focal plane (Potmesil &
    /// Chakravarty 1981), over a pixel's size there; 0 for a pinhole.
    fn blur_pixels(&self, point: DVec3) -> f64 {
        let camera = &self.camera;
        if !camera.has_lens() {
            return 0.0;
        }
        let depth = camera.depth_of(point);
        let focal = camera.focal_distance;
        let radius = camera.aperture_radius * (depth - focal).abs() / depth;
        // The film covers f² · A_film of the focal plane.
        let pixel_area = focal * focal * camera.film_area(self.aspect()) / self.pixel_count();
        std::f64::consts::PI * radius * radius / pixel_area
    }

    /// The camera ray's share of emission from `light` found at `y`
    /// (normal `normal`) by `camera_ray` after reflecting off `ball`: what
    /// the connections leave to it (all of it if they cannot make the path).
    pub fn camera_share(&self, scene: &Scene, ball: &SpecularBall, camera_ray: &Ray, light: u32, y: DVec3, normal: DVec3) -> f64 {
        let emitter = &scene.lights.lights[light as usize];
        if emitter.clipped.is_some() || ball.bounce != Bounce::Off {
            return 1.0;
        }
        let x = self.camera.lens_point_of(camera_ray);
        let Some(path) = ball.optics.path_along(Bounce::Off, x, y, camera_ray.direction) else {
            return 1.0;
        };
        let Some(spread) = ball.optics.area_per_solid_angle(Bounce::Off, x, &path, y, normal) else {
            return 1.0;
        };
        let area_pdf = scene.lights.probability(light) / scene.emitter(emitter.primitive).area();
        1.0 - self.connection_share(&path, spread, area_pdf)
    }

    /// The paths from the lens point `lens` picks off mirror ball `ball`
    /// to the point `u_light` picks on `light` (chosen with probability
    /// `selection`) that show on the film, before occlusion.
    fn candidates(
        &self,
        scene: &Scene,
        ball: &SpecularBall,
        lens: DVec2,
        (light, selection): (&Light, f64),
        u_light: DVec2,
        mut each: impl FnMut(Candidate),
    ) {
        if ball.bounce != Bounce::Off {
            return;
        }
        let emitter = scene.emitter(light.primitive);
        let Some((light_point, area)) = light_point_seen_by(light, &emitter, ball, u_light) else {
            return;
        };
        let (x, y) = (self.camera.lens_point(lens), light_point.point);
        let area_pdf = selection / area;
        for path in ball.optics.paths(Bounce::Off, x, y) {
            let towards_ball = light_point.normal.dot(-path.exit_direction) > 0.0;
            if !(towards_ball || light.two_sided) {
                continue;
            }
            let Some(film) = self.camera.connect(path.entry, self.aspect(), lens) else {
                continue;
            };
            let Some(spread) = ball.optics.area_per_solid_angle(Bounce::Off, x, &path, y, light_point.normal) else {
                continue;
            };
            // Importance per unit solid angle at the lens: `connect`'s
            // weight is per unit area at the ball.
            let distance = (path.entry - x).length();
            let importance = film.weight * distance * distance;
            each(Candidate {
                share: self.connection_share(&path, spread, area_pdf),
                weight: importance * self.pixel_count() / (spread * area_pdf),
                path,
                film,
                light_point,
            });
        }
    }

    /// Makes one lens connection from `sampler`'s next five dimensions (lens
    /// point, light choice, point on the light) off each mirror ball, and
    /// calls `splat(x, y, value)` for each that is unoccluded: `value` is
    /// its weighted contribution to pixel (x, y) if one connection were made
    /// for the whole image (divide by the number made).
    pub fn connect(&self, scene: &Scene, sampler: &mut Sampler, mut splat: impl FnMut(u32, u32, Color)) {
        let (lens, u_select, u_light) = (sampler.next_2d(), sampler.next_1d(), sampler.next_2d());
        let Some((light, selection)) = self.light(scene, u_select) else {
            return;
        };
        let (width, height) = (self.width, self.height);
        for (ball, &tried) in scene.specular_balls().iter().zip(&self.survival) {
            if tried < 1.0 && sampler.next_1d_independent() >= tried {
                continue;
            }
            let mut connect = |candidate: Candidate| {
                // Made in all with probability `survival`: `tried` so far.
                let survival = (candidate.share / SHARE_KEPT).max(LEAST_SURVIVAL).min(tried);
                if survival < tried && sampler.next_1d_independent() * tried >= survival {
                    return;
                }
                let value = light.emission().rgb * ball.tint * (candidate.share / survival * candidate.weight);
                if value == Color::ZERO {
                    return;
                }
                // The first leg starts where camera rays do (the lens, or
                // the near-clip plane).
                let Candidate {
                    path, film, light_point, ..
                } = candidate;
                let start = path.entry + film.towards_lens * film.clear_distance;
                let to_ball = Ray::new(start, path.direction);
                if unoccluded(
                    scene,
                    to_ball,
                    &path,
                    false,
                    light_point.point,
                    light_point.point_error.length(),
                ) {
                    let px = ((film.film.x * width as f64) as u32).min(width - 1);
                    let py = ((film.film.y * height as f64) as u32).min(height - 1);
                    splat(px, py, value);
                }
            };
            self.candidates(scene, ball, lens, (light, selection), u_light, &mut connect);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::luminance;
    use crate::film::PixelAccumulator;
    use crate::integrator::path::PathTracer;
    use crate::sampler::SamplerKind;
    use crate::scene::load_scene_str;
    use std::path::Path;

    /// A mirror ball out of focus with a sphere light beside the camera,
    /// whose reflection covers a pixel or so of an 8 × 8 image: the two
    /// strategies then share most paths.
    const MIRROR_BALL: &str = r#"
        [camera]
        position = [0, 0, 6]
        look_at = [0, 0, 0]
        fov_y_degrees = 12
        aperture_radius = 0.05
        focal_distance = 3
        [materials.chrome]
        type = "mirror"
        tint = [0.9, 0.8, 0.7]
        [materials.lamp]
        type = "emissive"
        radiance = [3, 2, 1]
        [[objects]]
        type = "sphere"
        center = [0, 0, 0]
        radius = 1
        material = "chrome"
        [[objects]]
        type = "sphere"
        center = [2.5, 2, 5]
        radius = 0.6
        material = "lamp"
    "#;

    /// The camera rays' share of the paths lens → mirror ball → light plus
    /// the lens connections equals, in the mean over the film, what the
    /// camera rays find counting every such path in full: the weights sum
    /// to one on every path and the connection's measurement is the
    /// camera's (importance, the ball's spread, the light's area density).
    #[test]
    fn camera_share_and_connections_add_up_to_the_camera_estimate() {
        let loaded = load_scene_str(MIRROR_BALL, Path::new("<test>"), Path::new(".")).expect("test scene parses");
        let (scene, camera) = (loaded.scene, loaded.camera);
        let (width, height) = (8, 8);
        let view = LensView::new(&scene, &camera, (width, height));
        assert!(scene_has_lens_connections(&scene));
        let ball = scene.specular_balls()[0];

        // Camera rays, film and lens uniform: emission met right after the
        // ball, in full (`all`) and weighted by the camera's share (`kept`),
        // zero for the other rays.
        let rays = 1_000_000;
        let (mut all, mut kept) = (PixelAccumulator::default(), PixelAccumulator::default());
        let mut random = Sampler::new(SamplerKind::Random, 0, 0, 17);
        let tracer = PathTracer {
            max_depth: 4,
            light_sampling: true,
            caustics_by_light_paths: true,
            lens_connections: Some(view),
        };
        // The emission a camera ray meets right after reflecting off the
        // ball, and the camera's share of it.
        let off_ball = |ray: &Ray| -> Option<(Color, f64)> {
            let first = scene
                .intersect(ray, f64::INFINITY)
                .filter(|first| first.primitive == ball.primitive)?;
            let normal = first.hit.geometric_normal;
            let reflected = ray.direction - 2.0 * ray.direction.dot(normal) * normal;
            let bounce = Ray::spawn(first.hit.point, first.hit.point_error, normal, reflected);
            let second = scene.intersect(&bounce, f64::INFINITY)?;
            let light = scene.lights.light_of_primitive(second.primitive)?;
            let value = scene.lights.lights[light as usize].radiance * ball.tint;
            let share = view.camera_share(&scene, &ball, ray, light, second.hit.point, second.hit.geometric_normal);
            Some((value, share))
        };
        for _ in 0..rays {
            let (film, lens) = (random.next_2d(), random.next_2d());
            let ray = camera.generate_ray(film, 1.0, lens);
            let (value, share) = off_ball(&ray).unwrap_or((Color::ZERO, 0.0));
            if value != Color::ZERO {
                assert!((0.0..=1.0).contains(&share), "{share}");
                // The path tracer, told of the connections, weights the same.
                let traced = tracer.radiance(&scene, ray, &mut random.clone());
                assert!(
                    (traced - value * share).length() <= 1e-9 * value.length(),
                    "{traced} vs {}",
                    value * share
                );
            }
            all.add(value);
            kept.add(value * share);
        }

        // Lens connections: each splat is a pixel's value for one connection
        // per image, so the film-wide mean is the splats' sum over the pixel
        // count, per connection.
        let connections = 100_000;
        let pixels = (width * height) as f64;
        let mut splatted = PixelAccumulator::default();
        let mut landed = 0;
        for index in 0..connections {
            let mut sampler = Sampler::new(SamplerKind::Random, index, 0, 5);
            let mut this = Color::ZERO;
            view.connect(&scene, &mut sampler, |x, y, value| {
                assert!(x < width && y < height);
                this += value / pixels;
                landed += 1;
            });
            splatted.add(this);
        }
        let mean_and_error = |tally: &PixelAccumulator| (luminance(tally.mean()), tally.standard_error());
        let ((all, all_error), (kept, kept_error)) = (mean_and_error(&all), mean_and_error(&kept));
        let (splatted, splatted_error) = mean_and_error(&splatted);

        // Both strategies matter here, so a wrong weight on either side shows.
        assert!(landed > 1000, "{landed} connections landed");
        assert!(kept > 0.1 * all && kept < 0.9 * all, "camera share {kept} of {all}");
        let error = (all_error.powi(2) + kept_error.powi(2) + splatted_error.powi(2)).sqrt();
        let difference = kept + splatted - all;
        assert!(
            difference.abs() < 4.0 * error,
            "camera {kept} ± {kept_error} + connections {splatted} ± {splatted_error} vs all {all} ± {all_error}"
        );
        // And the test can tell: the connections alone, or the camera's
        // share alone, are far from the whole.
        assert!((splatted - all).abs() > 8.0 * error && (kept - all).abs() > 8.0 * error);
    }
}
