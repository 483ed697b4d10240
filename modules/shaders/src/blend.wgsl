// The `blend` shader (blend.rs): (1 − w)·A + w·B. A template, made into
// WGSL per pair of part types by `Blend::gpu`: `$SELF` becomes this
// blend's identifier, `$A` and `$B` those of its parts' functions.
// Parameters: the weight texture, the offset of B's parameters from this
// blend's, then A's parameters (at offset 2) and B's.

fn bsdf_sample_$SELF(p: u32, s: ShadingPoint, u: vec3f) -> BsdfSample {
    let w = clamp(texture_scalar(param_u32(p), s.uv), 0.0, 1.0);
    let pa = p + 2u;
    let pb = p + param_u32(p + 1u);
    // Choose a part, reusing u.x for the part's own choice.
    var r: BsdfSample;
    var prob: f32;
    if u.x < w {
        prob = w;
        r = bsdf_sample_$B(pb, s, vec3f(clamp(u.x / w, 0.0, 1.0), u.y, u.z));
    } else {
        prob = 1.0 - w;
        r = bsdf_sample_$A(pa, s, vec3f(clamp((u.x - w) / (1.0 - w), 0.0, 1.0), u.y, u.z));
    }
    r.pdf *= prob;
    if r.delta || r.pdf <= 0.0 {
        return r;
    }
    // The mixture's value and density at a non-delta sample.
    let ea = bsdf_eval_$A(pa, s, r.wi);
    let eb = bsdf_eval_$B(pb, s, r.wi);
    let value = ea.value * (1.0 - w) + eb.value * w;
    let pdf = ea.pdf * (1.0 - w) + eb.pdf * w;
    if pdf > 0.0 {
        return BsdfSample(r.wi, value / pdf, pdf, false, r.eta);
    }
    return bsdf_sample_failed();
}

fn bsdf_eval_$SELF(p: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval {
    let w = clamp(texture_scalar(param_u32(p), s.uv), 0.0, 1.0);
    let ea = bsdf_eval_$A(p + 2u, s, wi);
    let eb = bsdf_eval_$B(p + param_u32(p + 1u), s, wi);
    return BsdfEval(ea.value * (1.0 - w) + eb.value * w, ea.pdf * (1.0 - w) + eb.pdf * w);
}
