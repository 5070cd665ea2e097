//! Object placement: translate, rotate, scale, composed as scale → rotate →
//! translate, the order people mean when they write all three.

use glam::{DAffine3, DMat3, DQuat, DVec3};

/// A rigid-plus-scale placement of an object from its own coordinates into the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Object to world: `x ↦ M x + t` with `M = R S` (scale first).
    pub to_world: DAffine3,
}

impl Default for Transform {
    fn default() -> Self {
        Self {
            to_world: DAffine3::IDENTITY,
        }
    }
}

impl Transform {
    /// `rotate_degrees` are Euler angles applied about x, then y, then z.
    pub fn new(translate: DVec3, rotate_degrees: DVec3, scale: DVec3) -> Self {
        let r = rotate_degrees * (std::f64::consts::PI / 180.0);
        let rotation = DQuat::from_euler(glam::EulerRot::ZYX, r.z, r.y, r.x);
        Self {
            to_world: DAffine3::from_scale_rotation_translation(scale, rotation, translate),
        }
    }

    /// A point from object to world space.
    pub fn point(&self, p: DVec3) -> DVec3 {
        self.to_world.transform_point3(p)
    }

    /// Normals transform with the inverse transpose of the linear part.
    pub fn normal_matrix(&self) -> DMat3 {
        self.to_world.matrix3.inverse().transpose()
    }

    /// Whether this is exactly the identity (nothing to apply).
    pub fn is_identity(&self) -> bool {
        self.to_world == DAffine3::IDENTITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_then_rotate_then_translate() {
        let t = Transform::new(DVec3::new(10.0, 0.0, 0.0), DVec3::new(0.0, 90.0, 0.0), DVec3::splat(2.0));
        // (1,0,0) → scale (2,0,0) → rotate 90° about y gives (0,0,-2) → translate.
        let p = t.point(DVec3::X);
        assert!((p - DVec3::new(10.0, 0.0, -2.0)).length() < 1e-12);
    }
}
