//! Orthonormal shading frames. BSDFs work in local coordinates where the
//! shading normal is +z, so `cos θ = w.z` (the convention of Nori and pbrt).

use glam::DVec3;

/// An orthonormal, right-handed basis (`s × t = n`) used as a shading frame:
/// `to_local` maps world vectors to coordinates where `n` is +z.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// First tangent; the local +x axis.
    pub s: DVec3,
    /// Second tangent; the local +y axis.
    pub t: DVec3,
    /// The (shading) normal; the local +z axis, so a local vector's `z` is cos θ.
    pub n: DVec3,
}

impl Frame {
    /// A frame around the unit vector `n`, built without branches on the
    /// sign of `n.z` that could flip it (Duff et al. 2017, "Building an
    /// Orthonormal Basis, Revisited").
    pub fn from_normal(n: DVec3) -> Self {
        let sign = 1.0_f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = DVec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { s, t, n }
    }

    /// World-space vector in this frame's coordinates (`n` becomes +z). The
    /// basis is orthonormal, so this is the transpose of `to_world`.
    pub fn to_local(&self, v: DVec3) -> DVec3 {
        DVec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Local coordinates back to a world-space vector; the inverse of `to_local`.
    pub fn to_world(&self, v: DVec3) -> DVec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_round_trip() {
        for n in [
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(0.3, -0.4, 0.5).normalize(),
            DVec3::new(1e-9, 0.0, -1.0).normalize(),
        ] {
            let f = Frame::from_normal(n);
            assert!((f.s.dot(f.t)).abs() < 1e-12 && (f.s.dot(f.n)).abs() < 1e-12);
            assert!((f.s.length() - 1.0).abs() < 1e-12 && (f.t.length() - 1.0).abs() < 1e-12);
            let v = DVec3::new(0.2, 0.7, -0.1);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-12);
        }
    }
}
