// The `checkerboard` texture (checkerboard.rs), a template that
// `compose::composite_gpu` fills in per combination of child types (the
// names marked with a dollar sign: the instance's identifier, the values
// of `color0` and `color1` at uv). Parameters: color0's words, then
// color1's (a constant's value, or a texture's id).
fn texture_$IDENT(p: u32, uv: vec2f) -> vec3f {
    if checkerboard_odd(uv) {
        return $CHILD1;
    }
    return $CHILD0;
}
