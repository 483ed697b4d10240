// The `stripes` texture of the outside module crate (lib.rs): colour a on
// even stripes of u·count, b on odd ones. Parameters: a (3 floats), b (3),
// count.
fn texture_stripes(p: u32, uv: vec2f) -> vec3f {
    let stripe = i32(floor(uv.x * param_f32(p + 6u)));
    if (stripe & 1) == 0 {
        return param_vec3(p);
    }
    return param_vec3(p + 3u);
}
