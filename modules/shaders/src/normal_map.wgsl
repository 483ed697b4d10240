// The normals of `normal_map` (normal_map.rs), part of a `Perturbed`
// template: n′ = normalize(2·c − 1) of the texture at p.

fn perturbed_normal_$SELF(p: u32, s: ShadingPoint) -> vec3f {
    return perturb_sanitise(2.0 * texture_eval(param_u32(p), s.uv) - vec3f(1.0));
}
