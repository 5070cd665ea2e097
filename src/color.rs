//! Linear RGB colours and the sRGB transfer function (IEC 61966-2-1).

/// Linear RGB radiance or reflectance. Plain `DVec3` so arithmetic is free.
pub type Color = glam::DVec3;

/// Rec. 709 / sRGB luminance of linear RGB.
pub fn luminance(c: Color) -> f64 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Linear value in [0, 1] to sRGB-encoded value in [0, 1].
pub fn srgb_encode(linear: f64) -> f64 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// sRGB-encoded value in [0, 1] to linear.
pub fn srgb_decode(encoded: f64) -> f64 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trips_and_hits_known_values() {
        for i in 0..=255 {
            let e = i as f64 / 255.0;
            assert!((srgb_encode(srgb_decode(e)) - e).abs() < 1e-12);
        }
        // 50% grey in sRGB is 21.4% linear (the standard's 0.214041).
        assert!((srgb_decode(0.5) - 0.214_041).abs() < 1e-6);
        assert_eq!(luminance(Color::ONE), 1.0);
    }
}
