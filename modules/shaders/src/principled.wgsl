// The `principled` shader (principled.rs): GGX reflection with Schlick's
// Fresnel, the coupled diffuse term and a rough dielectric interface,
// mixed by metalness and transmission. Parameters: the base colour,
// metallic, roughness, specular and transmission textures.

// The lobes at one point (`Lobes`).
struct PrincipledLobes {
    base: vec3f,
    a: vec2f,
    f0: vec3f,
    r0: f32,
    eta: f32,
    weights: vec3f,
}

fn principled_lobes(p: u32, uv: vec2f) -> PrincipledLobes {
    let base = clamp(texture_eval(param_u32(p), uv), vec3f(0.0), vec3f(1.0));
    let m = clamp(texture_scalar(param_u32(p + 1u), uv), 0.0, 1.0);
    let roughness = texture_scalar(param_u32(p + 2u), uv);
    let specular = texture_scalar(param_u32(p + 3u), uv);
    let t = clamp(texture_scalar(param_u32(p + 4u), uv), 0.0, 1.0);
    let r0 = 0.08 * clamp(specular, 0.0, 1.0);
    let rc = clamp(roughness, 0.0, 1.0);
    let a = rc * rc;
    let s = sqrt(r0);
    let f0 = vec3f(r0) * (1.0 - m) + base * m;
    let eta = max((1.0 + s) / (1.0 - s), 1.01);
    let weights = vec3f(1.0 - (1.0 - m) * t, (1.0 - m) * (1.0 - t), (1.0 - m) * t);
    return PrincipledLobes(base, ggx_alpha(a, a), f0, r0, eta, weights);
}

// Probabilities of sampling the reflection, diffuse and interface lobes.
fn principled_probabilities(l: PrincipledLobes, wo: vec3f) -> vec3f {
    var q = vec3f(0.0, 0.0, l.weights.z);
    if wo.z > 0.0 {
        q = vec3f(
            l.weights.x * rgb_luminance(fresnel_schlick(wo.z, l.f0)),
            l.weights.y * rgb_luminance(l.base) * (1.0 - l.r0),
            l.weights.z,
        );
    }
    let sum = q.x + q.y + q.z;
    if sum > 0.0 {
        return q / sum;
    }
    if wo.z > 0.0 {
        return vec3f(1.0, 0.0, 0.0);
    }
    return vec3f(0.0);
}

fn principled_fade(c: f32) -> f32 {
    let x = 1.0 - 0.5 * c;
    return 1.0 - x * x * x * x * x;
}

// (f·|cos θi|, pdf) of the whole mix.
fn principled_eval_lobes(l: PrincipledLobes, wo: vec3f, wi: vec3f) -> BsdfEval {
    let q = principled_probabilities(l, wo);
    var value = vec3f(0.0);
    var pdf = 0.0;
    if wo.z > 0.0 && wi.z > 0.0 {
        let g = glossy_eval(l.a, wo, wi);
        if g.ok {
            value += fresnel_schlick(dot(wo, g.m), l.f0) * (l.weights.x * g.value);
            pdf += q.x * g.pdf;
        }
        value += l.base * (l.weights.y * (1.0 - l.r0) * 28.0 / (23.0 * PI)
            * principled_fade(wi.z) * principled_fade(wo.z) * wi.z);
        pdf += q.y * cosine_hemisphere_pdf(wi);
    }
    if l.weights.z > 0.0 {
        let e = interface_eval(l.a, l.eta, wo, wi);
        var tint = vec3f(1.0);
        if e.transmitted {
            tint = l.base;
        }
        value += tint * (l.weights.z * e.value);
        pdf += q.z * e.pdf;
    }
    if !is_finite_vec3(value) || !is_finite_f32(pdf) {
        return bsdf_eval_zero();
    }
    return BsdfEval(value, pdf);
}

fn bsdf_sample_principled(p: u32, s: ShadingPoint, u: vec3f) -> BsdfSample {
    let wo = s.wo;
    let l = principled_lobes(p, s.uv);
    let q = principled_probabilities(l, wo);
    var wi: vec3f;
    if u.x < q.x {
        let g = glossy_sample(l.a, wo, u.yz);
        if !g.ok {
            return bsdf_sample_failed();
        }
        wi = g.wi;
    } else if u.x < q.x + q.y {
        wi = square_to_cosine_hemisphere(u.yz);
    } else if q.z > 0.0 {
        let x = clamp((u.x - q.x - q.y) / q.z, 0.0, 1.0);
        let i = interface_sample(l.a, l.eta, wo, vec3f(x, u.y, u.z));
        if !i.ok {
            return bsdf_sample_failed();
        }
        wi = i.wi;
    } else {
        return bsdf_sample_failed();
    }
    let e = principled_eval_lobes(l, wo, wi);
    if e.pdf > 0.0 && wi.z != 0.0 {
        var eta = 1.0;
        if wi.z * wo.z < 0.0 {
            eta = select(1.0 / l.eta, l.eta, wo.z > 0.0);
        }
        return BsdfSample(wi, e.value / e.pdf, e.pdf, false, eta);
    }
    return bsdf_sample_failed();
}

fn bsdf_eval_principled(p: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval {
    return principled_eval_lobes(principled_lobes(p, s.uv), s.wo, wi);
}
