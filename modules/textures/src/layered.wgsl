// The `layered` texture (layered.rs), a template that
// `compose::composite_gpu` fills in per combination of child types (the
// names marked with a dollar sign: the instance's identifier, the values
// of `upper`, `lower` and `mask` at uv): lower + (upper − lower) · mask.
// Parameters: upper's words, lower's, mask's (a constant's value, or a
// texture's id).
fn texture_$IDENT(p: u32, uv: vec2f) -> vec3f {
    let upper = $CHILD0;
    let lower = $CHILD1;
    let mask = $CHILD2;
    return lower + (upper - lower) * mask;
}
