// Helpers of the shaders' GPU sides, as inputs.rs and glam compute them
// on the CPU: scalar texture inputs, luminance, `try_normalize`.

// A scalar input: the mean of the texture's channels (`inputs::scalar`).
fn texture_scalar(id: u32, uv: vec2f) -> f32 {
    let c = texture_eval(id, uv);
    return (c.x + c.y + c.z) * (1.0 / 3.0);
}

// `radiant_core::luminance`.
fn rgb_luminance(c: vec3f) -> f32 {
    return 0.212671 * c.x + 0.715160 * c.y + 0.072169 * c.z;
}

// glam's `try_normalize`: the unit vector, or zero where the length is
// zero or not finite.
fn try_normalize(v: vec3f) -> vec3f {
    let l = length(v);
    if !(l > 0.0) || !is_finite_f32(l) {
        return vec3f(0.0);
    }
    let r = 1.0 / l;
    if !is_finite_f32(r) {
        return vec3f(0.0);
    }
    return v * r;
}
