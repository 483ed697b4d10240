// The `plastic` shader (plastic.rs): a diffuse base under a smooth or
// rough (GGX) dielectric coat. Parameters: η, rough (0/1), the coat's α,
// the diffuse and specular textures, nonlinear (0/1), the coat's internal
// diffuse reflectance, the share of samples steered to the coat, then the
// 64 entries of the coat's transmittance by cos θ (rough coats).

const PLASTIC_TABLE: u32 = 64u;

fn plastic_transmittance(p: u32, cos_i: f32) -> f32 {
    if param_u32(p + 1u) == 0u {
        return 1.0 - fresnel_dielectric(cos_i, param_f32(p)).r;
    }
    let x = clamp(cos_i, 0.0, 1.0) * f32(PLASTIC_TABLE - 1u);
    let i = min(u32(x), PLASTIC_TABLE - 2u);
    let t = x - f32(i);
    return param_f32(p + 8u + i) * (1.0 - t) + param_f32(p + 9u + i) * t;
}

fn plastic_specular_probability(p: u32, cos_i: f32) -> f32 {
    let t = plastic_transmittance(p, cos_i);
    let w = param_f32(p + 7u);
    let ps = (1.0 - t) * w;
    let pd = t * (1.0 - w);
    if ps + pd > 0.0 {
        return ps / (ps + pd);
    }
    return 1.0;
}

// (f·cos θi, pdf) of the non-delta part.
fn plastic_eval_point(p: u32, albedo: vec3f, spec: vec3f, wo: vec3f, wi: vec3f) -> BsdfEval {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return bsdf_eval_zero();
    }
    let eta = param_f32(p);
    let internal = param_f32(p + 6u);
    let ps = plastic_specular_probability(p, wo.z);
    var denom = vec3f(1.0 - internal);
    if param_u32(p + 5u) != 0u {
        denom = vec3f(1.0) - albedo * internal;
    }
    var value = albedo / denom
        * (plastic_transmittance(p, wo.z) * plastic_transmittance(p, wi.z) * INV_PI * wi.z
            / (eta * eta));
    var pdf = (1.0 - ps) * cosine_hemisphere_pdf(wi);
    if param_u32(p + 1u) != 0u {
        let alpha = param_f32(p + 2u);
        let g = glossy_eval(ggx_alpha(alpha, alpha), wo, wi);
        if g.ok {
            value += spec * (fresnel_dielectric(dot(wo, g.m), eta).r * g.value);
            pdf += ps * g.pdf;
        }
    }
    return BsdfEval(value, pdf);
}

fn bsdf_sample_plastic(p: u32, s: ShadingPoint, u: vec3f) -> BsdfSample {
    let wo = s.wo;
    if wo.z <= 0.0 {
        return bsdf_sample_failed();
    }
    let albedo = texture_eval(param_u32(p + 3u), s.uv);
    let spec = texture_eval(param_u32(p + 4u), s.uv);
    let ps = plastic_specular_probability(p, wo.z);
    var wi: vec3f;
    if u.x < ps {
        if param_u32(p + 1u) == 0u {
            let r = fresnel_dielectric(wo.z, param_f32(p)).r;
            return BsdfSample(vec3f(-wo.x, -wo.y, wo.z), spec * (r / ps), ps, true, 1.0);
        }
        let alpha = param_f32(p + 2u);
        let g = glossy_sample(ggx_alpha(alpha, alpha), wo, u.yz);
        if !g.ok {
            return bsdf_sample_failed();
        }
        wi = g.wi;
    } else {
        wi = square_to_cosine_hemisphere(u.yz);
    }
    let e = plastic_eval_point(p, albedo, spec, wo, wi);
    if e.pdf > 0.0 && wi.z > 0.0 {
        return BsdfSample(wi, e.value / e.pdf, e.pdf, false, 1.0);
    }
    return bsdf_sample_failed();
}

fn bsdf_eval_plastic(p: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval {
    let albedo = texture_eval(param_u32(p + 3u), s.uv);
    let spec = texture_eval(param_u32(p + 4u), s.uv);
    return plastic_eval_point(p, albedo, spec, s.wo, wi);
}
