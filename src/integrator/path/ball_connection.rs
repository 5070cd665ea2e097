//! Next-event estimation through glass balls and off mirror balls: light
//! that reaches a shading point only by refracting through a ball of glass
//! (the caustic under a glass ball, seen in a mirror or through the glass)
//! or by reflecting off a mirror ball cannot be found by a shadow ray, and
//! BSDF sampling finds it only when a sampled direction happens to meet
//! the ball where it leads to the light: a few rare, heavy samples. Here a
//! point y is drawn on a light by area, the paths from the shading point x
//! through or off each ball to y are solved for ([`BallOptics::paths`](crate::geometry::BallOptics::paths)),
//! and each contributes
//!
//!   f(x, ω) |cos θ| · S · Le(y) / (dA_y/dω · p_A(y)),
//!
//! where S is the ball's surface weight: T² · tint² through glass (T the
//! Fresnel transmittance of each crossing, equal by the chord's symmetry;
//! the radiance's 1/η² on entry and η² on leaving cancel), the tint off a
//! mirror; and dA_y/dω is the ball's spread of the bundle, which takes the
//! place of r²/cos θ_y of a direct connection (Hanika et al. 2015, manifold
//! next-event estimation; the generalised geometry term of Veach 1997 §8.2).
//!
//! The path tracer then gives a BSDF-sampled path x → ball → light no
//! weight exactly when this estimator claims it ([`Passage`]): the two
//! partition the paths by way of the balls, so the sum counts each once,
//! and a path the root scan misses stays with BSDF sampling.

use crate::color::Color;
use crate::geometry::{AreaSample, BallPath, Bounce, SurfaceHit};
use crate::light::{Emitter, EmitterSource, Light};
use crate::material::dielectric::fresnel_dielectric;
use crate::material::{Material, ShadingPoint};
use crate::math::{Frame, Ray};
use crate::scene::{Scene, SpecularBall};
use crate::spectrum::Radiance;
use glam::{DVec2, DVec3};

/// Shadow rays along a connection stop this fraction short of the
/// surfaces its ends lie on (the ball's own surface must not shadow it).
const SHORTFALL: f64 = 1e-7;

/// The light arriving at `hit` by way of the scene's specular balls, weighted by
/// the BSDF towards `wo` (local frame), for light-selection and area
/// sample numbers `u_select` and `u_light`.
#[allow(clippy::too_many_arguments)]
pub fn radiance_by_balls<C: Radiance>(
    scene: &Scene,
    hit: &SurfaceHit,
    frame: &Frame,
    material: &Material,
    wo: DVec3,
    at: &ShadingPoint,
    (u_select, u_light): (f64, DVec2),
    wavelengths: &C::Wavelengths,
) -> C {
    let mut radiance = C::ZERO;
    let Some((index, selection)) = scene.lights.choose(u_select) else {
        return radiance;
    };
    let light = &scene.lights.lights[index as usize];
    let emitter = scene.emitter(light.primitive);
    for ball in scene.specular_balls() {
        let Some((sample, area)) = light_point_seen_by(light, &emitter, ball, u_light) else {
            continue;
        };
        let y = sample.point;
        let area_pdf = selection / area;
        for path in ball.optics.paths(ball.bounce, hit.point, y) {
            let towards_ball = sample.normal.dot(-path.exit_direction) > 0.0;
            if !(towards_ball || light.two_sided) {
                continue;
            }
            let wi = frame.to_local(path.direction);
            let f = material.eval(wo, wi, at) * wi.z.abs();
            if f == Color::ZERO {
                continue;
            }
            let Some(spread) = ball
                .optics
                .area_per_solid_angle(ball.bounce, hit.point, &path, y, sample.normal)
            else {
                continue;
            };
            let to_ball = Ray::spawn(hit.point, hit.point_error, hit.geometric_normal, path.direction);
            if !unoccluded(scene, to_ball, &path, !ball.hollow, y, sample.point_error.length()) {
                continue;
            }
            let surface = match ball.bounce {
                Bounce::Through => {
                    let transmittance = 1.0 - fresnel_dielectric(path.cos_incidence, ball.optics.ior);
                    ball.tint * ball.tint * (transmittance * transmittance)
                }
                Bounce::Off => ball.tint,
            };
            let weight = 1.0 / (spread * area_pdf);
            radiance += C::from_rgb(f * surface, wavelengths) * C::emission(light.emission(), wavelengths) * weight;
        }
    }
    radiance
}

/// A point on `light` drawn uniformly by area from the part of it that
/// light leaving `ball` might reach, with that part's area: for a sphere
/// cut by opaque spheres, the cap on the ball's side of each (a straight
/// leg from the ball crosses none of them, so it ends there: smallpt's
/// light, whose whole sphere is 4400 times the sliver below its ceiling);
/// otherwise the whole surface. `None` if the area is degenerate, or if
/// the point drawn faces away from the whole ball (it then receives nothing
/// from it: the draw counts as zero).
pub(super) fn light_point_seen_by(light: &Light, emitter: &Emitter, ball: &SpecularBall, u: DVec2) -> Option<(AreaSample, f64)> {
    let cap = light
        .clipped
        .as_deref()
        .and_then(|clipped| Some((clipped, clipped.cap_seen_by_ball(ball.optics.center, ball.optics.radius)?)));
    let (sample, area) = match cap {
        Some((clipped, (cap, area))) => (clipped.sample_cap(&cap, u), area),
        None => (emitter.sample_area(u), emitter.area()),
    };
    // A one-sided light's point that no path from the ball reaches from the
    // front (most often on the far side of a sphere light): every path the
    // root search found there would fail the callers' `towards_ball` test,
    // so the search is not run.
    let hidden = !light.two_sided && ball.optics.hidden_behind_tangent_plane(sample.point, sample.normal);
    (area > 0.0 && area.is_finite() && !hidden).then_some((sample, area))
}

/// Whether nothing blocks the legs of `path`: `to_ball` (a ray along
/// its first leg) up to the ball, across it (if it goes through and
/// `across` asks), and from it to `y` (stopping short of y by its error bound).
pub(super) fn unoccluded(scene: &Scene, to_ball: Ray, path: &BallPath, across: bool, y: DVec3, y_error: f64) -> bool {
    let to_entry = (path.entry - to_ball.origin).length();
    if scene.occluded(&to_ball, to_entry * (1.0 - SHORTFALL)) {
        return false;
    }
    let chord = path.exit - path.entry;
    let length = chord.length();
    if across
        && length > 0.0
        && scene.occluded(
            &Ray::new(path.entry + chord * SHORTFALL, chord),
            length * (1.0 - 2.0 * SHORTFALL),
        )
    {
        return false;
    }
    let leg = (y - path.exit).length();
    let to_light = Ray::new(path.exit + path.exit_direction * (leg * SHORTFALL), path.exit_direction);
    !scene.occluded(&to_light, leg * (1.0 - 2.0 * SHORTFALL) - y_error)
}

/// A shading point where a connection by way of the balls was made, and
/// the direction the path's BSDF sample left it in.
#[derive(Clone, Copy, Debug)]
pub struct Departure {
    /// The shading point.
    pub from: DVec3,
    /// Unit direction leaving it.
    pub direction: DVec3,
}

/// Where a BSDF-sampled path stands against the connection made at its
/// last shading point: the path from there is claimed by
/// [`radiance_by_balls`] if it passes through a glass ball or reflects off
/// a mirror ball, next meets a light, and the connection from the shading
/// point to that point on the light finds it.
#[derive(Clone, Copy, Debug, Default)]
pub enum Passage {
    /// No connection made at the last shading point, or the path since has
    /// done something else.
    #[default]
    None,
    /// Leaving the shading point.
    Left(Departure),
    /// Inside a glass ball (index into [`Scene::specular_balls`]) after refracting in.
    Inside(Departure, usize),
    /// Through a glass ball and out, or off a mirror ball.
    Past(Departure, usize),
}

impl Passage {
    /// The passage after the path refracts (`refracted`) or reflects at a
    /// hit on `primitive`, arriving from outside it or not (`from_outside`).
    pub fn after(self, scene: &Scene, primitive: u32, from_outside: bool, refracted: bool) -> Passage {
        let balls = scene.specular_balls();
        match self {
            Passage::Left(departure) if from_outside => match balls.iter().position(|ball| ball.primitive == primitive) {
                Some(ball) => match (balls[ball].bounce, refracted) {
                    (Bounce::Through, true) => Passage::Inside(departure, ball),
                    (Bounce::Off, false) => Passage::Past(departure, ball),
                    _ => Passage::None,
                },
                None => Passage::None,
            },
            Passage::Inside(departure, ball) if refracted && !from_outside && balls[ball].primitive == primitive => {
                Passage::Past(departure, ball)
            }
            _ => Passage::None,
        }
    }

    /// Whether emission found at `point` on a light ends a path that
    /// [`radiance_by_balls`] has already counted.
    pub fn claims(self, scene: &Scene, point: DVec3) -> bool {
        match self {
            Passage::Past(Departure { from, direction }, ball) => {
                let ball = &scene.specular_balls()[ball];
                ball.optics.finds(ball.bounce, from, point, direction)
            }
            _ => false,
        }
    }
}
