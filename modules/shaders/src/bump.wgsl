// The normals of `bump` (bump.rs), part of a `Perturbed` template: the
// derivatives with their normal components replaced by the height's
// gradient (central differences of step 1/1024), crossed. Parameters: the
// height texture, the scale.

fn perturbed_normal_$SELF(p: u32, s: ShadingPoint) -> vec3f {
    let id = param_u32(p);
    let step = 1.0 / 1024.0;
    let k = param_f32(p + 1u) / (2.0 * step);
    let hu = (texture_scalar(id, s.uv + vec2f(step, 0.0)) - texture_scalar(id, s.uv - vec2f(step, 0.0))) * k;
    let hv = (texture_scalar(id, s.uv + vec2f(0.0, step)) - texture_scalar(id, s.uv - vec2f(0.0, step))) * k;
    let du = vec3f(s.dp_du.xy, hu);
    let dv = vec3f(s.dp_dv.xy, hv);
    var n = try_normalize(cross(du, dv));
    if all(n == vec3f(0.0)) {
        n = vec3f(0.0, 0.0, 1.0);
    }
    if n.z < 0.0 {
        n = -n;
    }
    return perturb_sanitise(n);
}
