// What every `checkerboard` instance shares (checkerboard.rs): whether uv
// lies in a `color1` check, ⌊2u⌋ + ⌊2v⌋ odd, with the parities of Rust's
// saturating `as i64` casts (NaN reads as 0, +∞ and beyond 2⁶³ as
// i64::MAX, which is odd; every float of magnitude 2²⁴ or more is even).

fn checkerboard_parity(c: f32) -> u32 {
    if (bitcast<u32>(c) & 0x7fffffffu) > 0x7f800000u {
        return 0u;
    }
    if c >= 9223372036854775808.0 {
        return 1u;
    }
    if abs(c) < 16777216.0 {
        return u32(abs(c)) & 1u;
    }
    return 0u;
}

fn checkerboard_odd(uv: vec2f) -> bool {
    let c = floor(2.0 * uv);
    return (checkerboard_parity(c.x) ^ checkerboard_parity(c.y)) == 1u;
}
