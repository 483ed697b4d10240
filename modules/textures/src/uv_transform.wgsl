// The `uv_transform` texture (uv_transform.rs), a template that
// `compose::composite_gpu` fills in per child type (the names marked with
// a dollar sign: the instance's identifier, the child's value at the
// mapped uv). Parameters: the matrix R(rotate) · diag(scale) by columns
// (4), the offset (2), then the child's words (a constant's value, or a
// texture's id).
fn texture_$IDENT(p: u32, uv_in: vec2f) -> vec3f {
    let m = mat2x2f(param_f32(p), param_f32(p + 1u), param_f32(p + 2u), param_f32(p + 3u));
    let uv = m * uv_in + vec2f(param_f32(p + 4u), param_f32(p + 5u));
    return $CHILD0;
}
