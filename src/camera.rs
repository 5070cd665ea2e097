//! Thin-lens camera (Cook et al. 1984; a pinhole when the aperture is 0).
//! The lens focuses on the plane at `focal_distance` along the view axis.

use crate::math::{Ray, warp};
use glam::{DVec2, DVec3};

/// A look-at thin-lens camera in world space. The public fields are the
/// user's parameters; after changing any of them call [`Camera::update`],
/// which rebuilds the orthonormal basis (right = forward × up, so the world
/// is right-handed and the image's x runs along `right`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Centre of the lens (the eye), world space.
    pub position: DVec3,
    /// The point looked at; orbiting turns about it.
    pub target: DVec3,
    /// Approximate up direction; only its component orthogonal to the view
    /// axis matters, and it must not be parallel to it.
    pub up: DVec3,
    /// Vertical field of view in degrees (the horizontal one follows from the
    /// image's aspect ratio).
    pub fov_y_degrees: f64,
    /// Lens radius in scene units; 0 gives a pinhole.
    pub aperture_radius: f64,
    /// Distance from the lens to the plane in focus, along the view axis.
    pub focal_distance: f64,
    /// Rays start on the plane this far along the view axis, so geometry in
    /// front of it is invisible (smallpt's camera sits behind a wall this way).
    pub near_clip: f64,
    basis: Basis,
}

/// A surface point seen from the lens: see [`Camera::connect`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilmConnection {
    /// Where on the film, in \[0,1)² (x right, y down).
    pub film: DVec2,
    /// Unit direction from the point towards the lens point.
    pub towards_lens: DVec3,
    /// Length of the segment from the point that must be unoccluded (up to
    /// the near-clip plane, or to the lens).
    pub clear_distance: f64,
    /// |cos θₓ| · weight is the film-wide measurement per unit radiance
    /// leaving the point towards the lens (θₓ: between that direction and
    /// the surface normal); divide by the pixel's fraction of the film.
    pub weight: f64,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Basis {
    right: DVec3,
    up: DVec3,
    forward: DVec3,
    tan_half_fov_y: f64,
}

impl Camera {
    /// A camera with no near clipping, its basis computed.
    pub fn new(position: DVec3, target: DVec3, up: DVec3, fov_y_degrees: f64, aperture_radius: f64, focal_distance: f64) -> Self {
        let mut camera = Self {
            position,
            target,
            up,
            fov_y_degrees,
            aperture_radius,
            focal_distance,
            near_clip: 0.0,
            basis: Basis {
                right: DVec3::X,
                up: DVec3::Y,
                forward: DVec3::Z,
                tan_half_fov_y: 1.0,
            },
        };
        camera.update();
        camera
    }

    /// Recomputes the derived basis after a field changed.
    pub fn update(&mut self) {
        let forward = (self.target - self.position).normalize();
        let right = forward.cross(self.up).normalize();
        let up = right.cross(forward);
        self.basis = Basis {
            right,
            up,
            forward,
            tan_half_fov_y: (self.fov_y_degrees.to_radians() * 0.5).tan(),
        };
    }

    /// Unit view direction, from `position` towards `target`.
    pub fn forward(&self) -> DVec3 {
        self.basis.forward
    }

    /// Unit vector to the image's right.
    pub fn right(&self) -> DVec3 {
        self.basis.right
    }

    /// Unit vector to the image's top: `up` made orthogonal to the view axis.
    pub fn view_up(&self) -> DVec3 {
        self.basis.up
    }

    /// Whether rays start on a lens (a finite aperture): a pinhole camera's
    /// [`generate_ray`](Self::generate_ray) ignores its lens sample.
    #[inline]
    pub fn has_lens(&self) -> bool {
        self.aperture_radius > 0.0 || self.aperture_radius.is_nan()
    }

    /// Primary ray through `film` ∈ \[0,1\]² (x right, y down) for an image of
    /// the given aspect ratio (width / height); `lens` ∈ \[0,1\]² picks the
    /// point on the aperture.
    #[inline]
    pub fn generate_ray(&self, film: DVec2, aspect: f64, lens: DVec2) -> Ray {
        self.generate_ray_inlined(film, aspect, lens)
    }

    /// [`Camera::generate_ray`], always compiled into its caller (the
    /// path tracer's pixel loop through a lens).
    #[inline(always)]
    pub(crate) fn generate_ray_inlined(&self, film: DVec2, aspect: f64, lens: DVec2) -> Ray {
        let b = &self.basis;
        let x = (2.0 * film.x - 1.0) * b.tan_half_fov_y * aspect;
        let y = (1.0 - 2.0 * film.y) * b.tan_half_fov_y;
        // Direction with unit forward component: `focal_distance` along it
        // lands on the focal plane.
        let direction = b.forward + x * b.right + y * b.up;
        let mut ray = if self.has_lens() {
            let focus = self.position + self.focal_distance * direction;
            let origin = self.lens_point_inlined(lens);
            Ray::new(origin, focus - origin)
        } else {
            Ray::new(self.position, direction)
        };
        if self.near_clip > 0.0 {
            ray.origin += ray.direction * (self.near_clip / ray.direction.dot(b.forward));
        }
        ray
    }

    /// How a world `point` shows on the film through the lens point that
    /// `lens` picks (as in [`generate_ray`](Self::generate_ray)): the
    /// adjoint of a camera ray, for paths traced from the lights. `None` if
    /// the point is behind the lens or the near-clip plane, or off the film.
    ///
    /// Why the weight: a pixel's estimate is the mean radiance over the
    /// camera rays through it, film positions uniform on the pixel and lens
    /// points uniform on the aperture. On the film plane at unit distance a
    /// ray making angle θ with the view axis maps film area to solid angle
    /// as dω = cos³θ dA (and the same holds from any lens point through the
    /// focal plane); solid angle at the lens maps to area at the point as
    /// dω = |cos θₓ| dAₓ / d². So radiance L leaving the point towards the
    /// lens adds L · |cos θₓ| / (A · cos³θ · d²) to the film-wide mean, A
    /// being the film's area at unit distance; a pixel covering a fraction a
    /// of the film receives that divided by a (the importance We of pbrt-v3
    /// §16.1.1 over the lens-sampling pdf, for a box pixel filter).
    pub fn connect(&self, point: DVec3, aspect: f64, lens: DVec2) -> Option<FilmConnection> {
        let b = &self.basis;
        let lens_point = self.lens_point(lens);
        let towards_point = point - lens_point;
        let depth = towards_point.dot(b.forward);
        let distance = towards_point.length();
        // Written so that NaN fails too.
        let in_front = depth > self.near_clip.max(0.0) && distance > 0.0;
        if !in_front {
            return None;
        }
        // The ray from the lens point through `point` meets the focal plane
        // (a pinhole: the unit plane) where `generate_ray` aims it.
        let focus_depth = if self.has_lens() { self.focal_distance } else { 1.0 };
        let direction = (lens_point + towards_point * (focus_depth / depth) - self.position) / focus_depth;
        let x = direction.dot(b.right) / (b.tan_half_fov_y * aspect);
        let y = direction.dot(b.up) / b.tan_half_fov_y;
        let film = DVec2::new(0.5 * (x + 1.0), 0.5 * (1.0 - y));
        let on_film = (0.0..1.0).contains(&film.x) && (0.0..1.0).contains(&film.y);
        if !on_film {
            return None;
        }
        let cos_theta = depth / distance;
        let film_area = self.film_area(aspect);
        // Camera rays start on the near-clip plane: only the part of the
        // segment beyond it must be clear.
        let clipped = self.near_clip.max(0.0) / cos_theta;
        Some(FilmConnection {
            film,
            towards_lens: -towards_point / distance,
            clear_distance: distance - clipped,
            weight: 1.0 / (film_area * cos_theta * cos_theta * cos_theta * distance * distance),
        })
    }

    /// The point on the aperture that `lens` picks, as
    /// [`generate_ray`](Self::generate_ray) does (the eye for a pinhole).
    #[inline]
    pub fn lens_point(&self, lens: DVec2) -> DVec3 {
        self.lens_point_inlined(lens)
    }

    /// [`Camera::lens_point`], always compiled into its caller.
    #[inline(always)]
    fn lens_point_inlined(&self, lens: DVec2) -> DVec3 {
        if self.has_lens() {
            let disk = warp::square_to_concentric_disk(lens) * self.aperture_radius;
            self.position + disk.x * self.basis.right + disk.y * self.basis.up
        } else {
            self.position
        }
    }

    /// Where the line of a camera ray crosses the lens plane: the lens point
    /// it left from, wherever along it (near clipping) the ray starts.
    pub fn lens_point_of(&self, ray: &Ray) -> DVec3 {
        let forward = self.basis.forward;
        ray.origin - ray.direction * ((ray.origin - self.position).dot(forward) / ray.direction.dot(forward))
    }

    /// The film's area on the plane at unit distance, for an image of
    /// `aspect` (width / height): solid angle per unit of film is
    /// `film_area · cos³θ`.
    pub fn film_area(&self, aspect: f64) -> f64 {
        4.0 * self.basis.tan_half_fov_y * self.basis.tan_half_fov_y * aspect
    }

    /// Depth of a world point along the view axis: what the focal distance
    /// must be for that point to be sharp.
    pub fn depth_of(&self, point: DVec3) -> f64 {
        (point - self.position).dot(self.basis.forward)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_at_target_and_focus_plane_is_sharp() {
        let mut camera = Camera::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -10.0), DVec3::Y, 40.0, 0.5, 7.0);
        let center = camera.generate_ray(DVec2::splat(0.5), 1.5, DVec2::splat(0.5));
        assert!((center.direction - -DVec3::Z).length() < 1e-12);
        // Every lens sample through one film point meets the focal plane at one point.
        let film = DVec2::new(0.2, 0.7);
        let meet = |lens: DVec2| {
            let r = camera.generate_ray(film, 1.5, lens);
            let t = (camera.depth_of(camera.position + camera.forward() * 7.0) - camera.depth_of(r.origin))
                / r.direction.dot(camera.forward());
            r.at(t)
        };
        let a = meet(DVec2::new(0.1, 0.9));
        let b = meet(DVec2::new(0.8, 0.3));
        assert!((a - b).length() < 1e-9);
        camera.aperture_radius = 0.0;
        let pinhole = camera.generate_ray(film, 1.5, DVec2::new(0.1, 0.9));
        assert_eq!(pinhole.origin, DVec3::ZERO);
    }

    /// `connect` inverts `generate_ray`: a point on a camera ray maps back
    /// to the film position and lens sample that made the ray, with the
    /// direction back to the ray's start, through a pinhole and a lens,
    /// with and without near clipping; points behind the lens or off the
    /// film have no connection.
    #[test]
    fn connect_finds_the_film_point_of_a_camera_ray() {
        let position = DVec3::new(1.0, 2.0, 3.0);
        for (aperture, near_clip) in [(0.0, 0.0), (0.3, 0.0), (0.0, 0.5), (0.3, 0.5)] {
            let mut camera = Camera::new(position, DVec3::new(0.0, 1.0, -4.0), DVec3::Y, 50.0, aperture, 5.0);
            camera.near_clip = near_clip;
            for (film, lens) in [
                (DVec2::new(0.5, 0.5), DVec2::new(0.5, 0.5)),
                (DVec2::new(0.1, 0.8), DVec2::new(0.2, 0.9)),
                (DVec2::new(0.97, 0.03), DVec2::new(0.7, 0.1)),
            ] {
                let ray = camera.generate_ray(film, 1.6, lens);
                let point = ray.at(3.0);
                let connection = camera.connect(point, 1.6, lens).expect("a point on a camera ray is seen");
                assert!((connection.film - film).length() < 1e-12, "{:?} vs {film:?}", connection.film);
                assert!((connection.towards_lens + ray.direction).length() < 1e-12);
                // The segment to clear ends where the camera ray started.
                assert!(
                    (connection.clear_distance - 3.0).abs() < 1e-12,
                    "{}",
                    connection.clear_distance
                );
                // Behind the lens: nothing.
                assert!(camera.connect(ray.at(-3.0), 1.6, lens).is_none());
            }
            // Outside the field of view: nothing.
            assert!(
                camera
                    .connect(position + 5.0 * camera.right(), 1.6, DVec2::splat(0.5))
                    .is_none()
            );
        }
    }

    /// The weight is the Jacobian from film area to the point's area: the
    /// film positions whose camera rays land on a small patch facing the
    /// lens at distance d cover a fraction a of the film, and weight · A_patch
    /// must equal that fraction (a pinhole, the patch off the axis).
    #[test]
    fn connection_weight_is_the_film_fraction_per_unit_area() {
        let camera = Camera::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0), DVec3::Y, 60.0, 0.0, 1.0);
        let aspect = 1.25;
        let center = DVec3::new(1.0, 0.6, -4.0);
        let towards_lens = -center.normalize();
        let frame = crate::math::Frame::from_normal(towards_lens);
        let half = 0.01;
        // Film positions of the patch's corners: the patch is small enough
        // that its image is a parallelogram to well below the tolerance.
        let film_of = |u: f64, v: f64| {
            let point = center + frame.to_world(DVec3::new(u, v, 0.0));
            camera.connect(point, aspect, DVec2::ZERO).expect("in view").film
        };
        let (origin, du, dv) = (film_of(-half, -half), film_of(half, -half), film_of(-half, half));
        let (a, b) = (du - origin, dv - origin);
        let film_fraction = (a.x * b.y - a.y * b.x).abs();
        let weight = camera.connect(center, aspect, DVec2::ZERO).expect("in view").weight;
        let patch_area = (2.0 * half) * (2.0 * half);
        // |cos θₓ| = 1: the patch faces the lens.
        let relative = weight * patch_area / film_fraction - 1.0;
        assert!(relative.abs() < 1e-3, "weight off by {relative}");
    }
}
