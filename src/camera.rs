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
        let b = &self.basis;
        let x = (2.0 * film.x - 1.0) * b.tan_half_fov_y * aspect;
        let y = (1.0 - 2.0 * film.y) * b.tan_half_fov_y;
        // Direction with unit forward component: `focal_distance` along it
        // lands on the focal plane.
        let direction = b.forward + x * b.right + y * b.up;
        let mut ray = if self.has_lens() {
            let focus = self.position + self.focal_distance * direction;
            let disk = warp::square_to_concentric_disk(lens) * self.aperture_radius;
            let origin = self.position + disk.x * b.right + disk.y * b.up;
            Ray::new(origin, focus - origin)
        } else {
            Ray::new(self.position, direction)
        };
        if self.near_clip > 0.0 {
            ray.origin += ray.direction * (self.near_clip / ray.direction.dot(b.forward));
        }
        ray
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
}
