//! The sRGB transfer function (IEC 61966-2-1): 8- and 16-bit colour images
//! store sRGB-encoded values, rendering needs linear ones.

/// Decodes one sRGB-encoded channel in [0, 1] to linear.
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Encodes one linear channel in [0, 1] to sRGB.
#[inline]
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        // 128/255 is the usual "middle grey" 0.21586 in linear light.
        assert!((srgb_to_linear(128.0 / 255.0) - 0.215_861).abs() < 1e-5);
        // The linear segment.
        assert!((srgb_to_linear(0.04) - 0.04 / 12.92).abs() < 1e-8);
    }

    #[test]
    fn round_trips_every_8_bit_value() {
        for i in 0..=255u32 {
            let c = i as f32 / 255.0;
            let back = linear_to_srgb(srgb_to_linear(c));
            assert!((back - c).abs() < 1e-5, "{i}: {back}");
            assert_eq!((back * 255.0).round() as u32, i);
        }
    }
}
