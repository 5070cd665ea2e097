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

/// Linear value in [0, 1] to the nearest 8-bit sRGB code; values outside
/// saturate at 0 and 255 (and NaN gives 0), as `as u8` does.
pub fn srgb_encode_8bit(linear: f64) -> u8 {
    (srgb_encode(linear) * 255.0 + 0.5) as u8
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

    #[test]
    fn eight_bit_codes_round_to_nearest_and_saturate() {
        // Every code decodes to a linear value that encodes back to itself:
        // the decoded value sits at the code's centre, half a code (0.5/255)
        // from either rounding boundary, far beyond the f64 rounding.
        for code in 0..=255u8 {
            assert_eq!(srgb_encode_8bit(srgb_decode(code as f64 / 255.0)), code);
        }
        // Linear 0.2 encodes to 0.48453 · 255 = 123.56, nearest code 124.
        assert_eq!(srgb_encode_8bit(0.2), 124);
        assert_eq!(srgb_encode_8bit(-1.0), 0);
        assert_eq!(srgb_encode_8bit(2.0), 255);
        assert_eq!(srgb_encode_8bit(f64::NAN), 0);
    }
}
