// The `hg` phase function (its asymmetry g), sampled as `phase.rs`
// samples it: by inverting its CDF in cos θ, pbrt-v4's convention (wo
// points away from the event, so g > 0 scatters towards −wo).

fn henyey_greenstein(cos_theta: f32, g: f32) -> f32 {
    let denom = 1.0 + g * g + 2.0 * g * cos_theta;
    return 0.25 * INV_PI * (1.0 - g * g) / (denom * sqrt(max(denom, 0.0)));
}

fn phase_sample_hg(p: u32, wo: vec3f, u: vec2f) -> BsdfSample {
    let g = param_f32(p);
    var cos_theta = 1.0 - 2.0 * u.x;
    if abs(g) >= 1e-3 {
        let s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u.x);
        cos_theta = -(1.0 + g * g - s * s) / (2.0 * g);
    }
    cos_theta = clamp(cos_theta, -1.0, 1.0);
    let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    let phi = 2.0 * PI * u.y;
    let wi = frame_to_world(frame_from_normal(wo), vec3f(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta));
    return BsdfSample(wi, vec3f(1.0), henyey_greenstein(cos_theta, g), false, 1.0);
}

fn phase_eval_hg(p: u32, wo: vec3f, wi: vec3f) -> BsdfEval {
    let v = henyey_greenstein(dot(wo, wi), param_f32(p));
    return BsdfEval(vec3f(v), v);
}
