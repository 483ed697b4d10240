// The `conductor` shader (conductor.rs). Parameters: kind (0 mirror,
// 1 complex index), eta, k, the specular texture, smooth (0/1), the α_u
// and α_v textures.

fn conductor_fresnel(p: u32, cos_i: f32) -> vec3f {
    if param_u32(p) == 0u {
        return vec3f(1.0);
    }
    return fresnel_conductor(cos_i, param_vec3(p + 1u), param_vec3(p + 4u));
}

fn conductor_alpha(p: u32, uv: vec2f) -> vec2f {
    return ggx_alpha(texture_scalar(param_u32(p + 9u), uv), texture_scalar(param_u32(p + 10u), uv));
}

fn bsdf_sample_conductor(p: u32, s: ShadingPoint, u: vec3f) -> BsdfSample {
    let wo = s.wo;
    if wo.z <= 0.0 {
        return bsdf_sample_failed();
    }
    let spec = texture_eval(param_u32(p + 7u), s.uv);
    if param_u32(p + 8u) != 0u {
        let w = conductor_fresnel(p, wo.z) * spec;
        return BsdfSample(vec3f(-wo.x, -wo.y, wo.z), w, 1.0, true, 1.0);
    }
    let a = conductor_alpha(p, s.uv);
    let m = ggx_sample_visible(a, wo, u.yz);
    let wi = reflect_about(wo, m);
    let pdf = ggx_pdf_visible(a, wo, m) / (4.0 * dot(wo, m));
    if wi.z <= 0.0 || !(pdf > 0.0 && is_finite_f32(pdf)) {
        return bsdf_sample_failed();
    }
    let w = conductor_fresnel(p, dot(wo, m)) * spec * ggx_g1(a, wi, m);
    return BsdfSample(wi, w, pdf, false, 1.0);
}

fn bsdf_eval_conductor(p: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval {
    let wo = s.wo;
    if param_u32(p + 8u) != 0u || wo.z <= 0.0 || wi.z <= 0.0 {
        return bsdf_eval_zero();
    }
    let h = wo + wi;
    if dot(h, h) == 0.0 {
        return bsdf_eval_zero();
    }
    let m = normalize(h);
    let a = conductor_alpha(p, s.uv);
    let d = ggx_d(a, m);
    let spec = texture_eval(param_u32(p + 7u), s.uv);
    let value = conductor_fresnel(p, dot(wo, m)) * spec
        * (d * ggx_g1(a, wo, m) * ggx_g1(a, wi, m) / (4.0 * wo.z));
    let pdf = ggx_g1(a, wo, m) * d / (4.0 * wo.z);
    if !is_finite_vec3(value) || !is_finite_f32(pdf) {
        return bsdf_eval_zero();
    }
    return BsdfEval(value, pdf);
}
