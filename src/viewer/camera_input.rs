//! Mouse navigation (orbit about the target, pan, zoom), click-to-focus, and
//! the depth grid behind the focal-plane overlay. Pure camera math on the UI
//! thread; only `Camera` changes, never the scene.

use crate::camera::Camera;
use crate::scene::Scene;
use glam::{DQuat, DVec2, DVec3};
use std::sync::Arc;

/// Orbit: dragging across the image's full height turns the camera by π.
pub fn orbit(camera: &mut Camera, delta_pixels: DVec2, image_height: f64) {
    let radians_per_pixel = std::f64::consts::PI / image_height.max(1.0);
    let up = camera.up.normalize();
    let offset = camera.position - camera.target;
    // Yaw about the world up, then pitch about the camera's right axis,
    // keeping at least ~3° from the poles so the basis stays defined.
    let yaw = DQuat::from_axis_angle(up, -delta_pixels.x * radians_per_pixel);
    let offset = yaw * offset;
    let right = offset.cross(up).normalize_or_zero();
    let polar = offset.normalize().dot(up).clamp(-1.0, 1.0).acos();
    let limit = 0.05;
    let pitch_angle = (delta_pixels.y * radians_per_pixel).clamp(limit - polar, std::f64::consts::PI - limit - polar);
    let offset = if right == DVec3::ZERO {
        offset
    } else {
        DQuat::from_axis_angle(right, -pitch_angle) * offset
    };
    camera.position = camera.target + offset;
    camera.update();
}

/// Pan: the point under the cursor on the target's plane follows the cursor.
pub fn pan(camera: &mut Camera, delta_pixels: DVec2, image_height: f64) {
    let distance = (camera.target - camera.position).length();
    let units_per_pixel = 2.0 * distance * (camera.fov_y_degrees.to_radians() * 0.5).tan() / image_height.max(1.0);
    let shift = (-delta_pixels.x * camera.right() + delta_pixels.y * camera.view_up()) * units_per_pixel;
    camera.position += shift;
    camera.target += shift;
    camera.update();
}

/// Zoom: moves towards the target by a factor of e^(-scroll/500) (one wheel
/// notch of ~50 points ≈ 10 %), never through it.
pub fn zoom(camera: &mut Camera, scroll_points: f64) {
    let factor = (-scroll_points / 500.0).exp();
    let offset = camera.position - camera.target;
    let length = offset.length();
    let new_length = (length * factor).max(1e-4 * length.max(1e-9));
    camera.position = camera.target + offset * (new_length / length.max(1e-12));
    camera.update();
}

/// Depth along the view axis of the surface seen through `film` ∈ [0,1]²
/// (through the lens centre), or `None` if the ray escapes.
pub fn surface_depth(scene: &Scene, camera: &Camera, film: DVec2, aspect: f64) -> Option<f64> {
    let mut pinhole = *camera;
    pinhole.aperture_radius = 0.0;
    let ray = pinhole.generate_ray(film, aspect, DVec2::splat(0.5));
    let (t, _) = scene.nearest_distance(&ray, f64::INFINITY)?;
    Some(camera.depth_of(ray.at(t)))
}

/// Columns of the focal-plane overlay grid.
const GRID_COLUMNS: usize = 96;

/// Depths of a coarse grid of primary rays, cached per scene and camera
/// placement (aperture and focus do not move what is seen).
#[derive(Default)]
pub struct DepthGrid {
    key: Option<(usize, Camera, u32, u32)>,
    pub columns: usize,
    pub rows: usize,
    /// Row-major; `None` where the ray escapes.
    pub depths: Vec<Option<f64>>,
}

impl DepthGrid {
    /// Recomputes the grid if the scene, the camera placement or the image shape changed.
    pub fn update(&mut self, scene: &Arc<Scene>, camera: &Camera, width: u32, height: u32) {
        let mut placement = *camera;
        placement.aperture_radius = 0.0;
        placement.focal_distance = 1.0;
        let key = (Arc::as_ptr(scene) as usize, placement, width, height);
        if self.key == Some(key) {
            return;
        }
        let aspect = width as f64 / height.max(1) as f64;
        self.columns = GRID_COLUMNS;
        self.rows = ((GRID_COLUMNS as f64 / aspect).round() as usize).max(1);
        self.depths = (0..self.rows * self.columns)
            .map(|i| {
                let film = DVec2::new(
                    ((i % self.columns) as f64 + 0.5) / self.columns as f64,
                    ((i / self.columns) as f64 + 0.5) / self.rows as f64,
                );
                surface_depth(scene, &placement, film, aspect)
            })
            .collect();
        self.key = Some(key);
    }

    /// Cells within the depth band around `focal_distance` whose width grows
    /// with distance (2 % of it), so the band reads as a plane on any scale.
    pub fn in_focus(&self, focal_distance: f64) -> impl Iterator<Item = (usize, usize)> + '_ {
        let tolerance = 0.02 * focal_distance.abs();
        self.depths.iter().enumerate().filter_map(move |(i, depth)| {
            depth
                .filter(|d| (d - focal_distance).abs() <= tolerance)
                .map(|_| (i % self.columns, i / self.columns))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera::new(DVec3::new(0.0, 0.0, 10.0), DVec3::ZERO, DVec3::Y, 40.0, 0.0, 10.0)
    }

    #[test]
    fn orbit_keeps_distance_to_target() {
        let mut c = camera();
        orbit(&mut c, DVec2::new(120.0, -40.0), 500.0);
        // Rotations preserve length; 1e-9 is rounding on a length of 10.
        assert!(((c.position - c.target).length() - 10.0).abs() < 1e-9);
        assert!((c.position - DVec3::new(0.0, 0.0, 10.0)).length() > 1.0);
    }

    #[test]
    fn pan_moves_target_with_camera_and_zoom_approaches() {
        let mut c = camera();
        pan(&mut c, DVec2::new(10.0, 0.0), 500.0);
        assert!((c.position - c.target - DVec3::new(0.0, 0.0, 10.0)).length() < 1e-9);
        assert!(c.target.x < 0.0, "dragging right moves the view left: {:?}", c.target);
        let mut z = camera();
        zoom(&mut z, 50.0);
        let d = (z.position - z.target).length();
        assert!((d - 10.0 * (-0.1f64).exp()).abs() < 1e-9);
    }
}
