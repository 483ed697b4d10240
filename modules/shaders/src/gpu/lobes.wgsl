// Per-point lobes shared by several shaders, as lobes.rs: GGX reflection
// without its Fresnel factor, and the rough dielectric interface of
// Walter et al. (2007) sampled through the visible normals. Values are
// f·|cos θi|, densities per unit solid angle, in the local frame. A
// `None` of the Rust code is `ok == false` here.

struct GlossySample {
    wi: vec3f,
    m: vec3f,
    weight: f32,
    pdf: f32,
    ok: bool,
}

// `glossy_sample`: a GGX reflection for `wo` (upper hemisphere only).
fn glossy_sample(a: vec2f, wo: vec3f, u: vec2f) -> GlossySample {
    if wo.z <= 0.0 {
        return GlossySample(vec3f(0.0), vec3f(0.0), 0.0, 0.0, false);
    }
    let m = ggx_sample_visible(a, wo, u);
    let wi = reflect_about(wo, m);
    let pdf = ggx_pdf_visible(a, wo, m) / (4.0 * dot(wo, m));
    let ok = wi.z > 0.0 && pdf > 0.0 && is_finite_f32(pdf);
    return GlossySample(wi, m, ggx_g1(a, wi, m), pdf, ok);
}

struct GlossyEval {
    m: vec3f,
    value: f32,
    pdf: f32,
    ok: bool,
}

// `glossy_eval`: (half vector, D·G/(4 cos θo), pdf of `glossy_sample`).
fn glossy_eval(a: vec2f, wo: vec3f, wi: vec3f) -> GlossyEval {
    let none = GlossyEval(vec3f(0.0), 0.0, 0.0, false);
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return none;
    }
    let m = try_normalize(wo + wi);
    if all(m == vec3f(0.0)) {
        return none;
    }
    let d = ggx_d(a, m);
    let value = d * (ggx_g1(a, wo, m) * ggx_g1(a, wi, m)) / (4.0 * wo.z);
    let pdf = ggx_g1(a, wo, m) * d / (4.0 * wo.z);
    if !is_finite_f32(value) || !is_finite_f32(pdf) {
        return none;
    }
    return GlossyEval(m, value, pdf, true);
}

// `microfacet::refract`: `v` refracted about `m`.
fn refract_about(v: vec3f, m: vec3f, cos_t: f32, eta_ti: f32) -> vec3f {
    return m * (dot(v, m) * eta_ti + cos_t) - v * eta_ti;
}

struct InterfaceSample {
    wi: vec3f,
    weight: f32,
    pdf: f32,
    transmitted: bool,
    ok: bool,
}

// `interface_sample`: reflection or refraction at a rough interface of
// relative index `eta` for `wo` on either side.
fn interface_sample(a: vec2f, eta: f32, wo: vec3f, u: vec3f) -> InterfaceSample {
    let none = InterfaceSample(vec3f(0.0), 0.0, 0.0, false, false);
    if wo.z == 0.0 {
        return none;
    }
    let up = select(-wo, wo, wo.z > 0.0);
    let m = ggx_sample_visible(a, up, u.yz);
    let pdf_m = ggx_pdf_visible(a, up, m);
    let f = fresnel_dielectric(dot(wo, m), eta);
    var wi: vec3f;
    var jacobian: f32;
    var lobe: f32;
    var transmitted = false;
    if u.x <= f.r {
        wi = reflect_about(wo, m);
        if wi.z * wo.z <= 0.0 {
            return none;
        }
        jacobian = 1.0 / (4.0 * abs(dot(wi, m)));
        lobe = f.r;
    } else {
        wi = refract_about(wo, m, f.cos_t, f.eta_ti);
        if wi.z * wo.z >= 0.0 {
            return none;
        }
        let denom = dot(wo, m) + f.eta_it * dot(wi, m);
        jacobian = abs(f.eta_it * f.eta_it * dot(wi, m) / (denom * denom));
        lobe = 1.0 - f.r;
        transmitted = true;
    }
    let pdf = pdf_m * lobe * jacobian;
    var weight = ggx_g1(a, wi, m);
    if transmitted {
        weight *= f.eta_ti * f.eta_ti;
    }
    if !(pdf > 0.0 && is_finite_f32(pdf) && is_finite_f32(weight)) {
        return none;
    }
    return InterfaceSample(wi, weight, pdf, transmitted, true);
}

struct InterfaceEval {
    value: f32,
    pdf: f32,
    transmitted: bool,
}

// `interface_eval`: (f·|cos θi|, pdf of `interface_sample`, whether the
// pair refracts).
fn interface_eval(a: vec2f, eta: f32, wo: vec3f, wi: vec3f) -> InterfaceEval {
    if wo.z == 0.0 || wi.z == 0.0 {
        return InterfaceEval(0.0, 0.0, false);
    }
    let reflected = wo.z * wi.z > 0.0;
    let none = InterfaceEval(0.0, 0.0, !reflected);
    var eta_rel = 1.0 / eta;
    if wo.z > 0.0 {
        eta_rel = eta;
    }
    var m = try_normalize(wo + wi * select(eta_rel, 1.0, reflected));
    if all(m == vec3f(0.0)) {
        return none;
    }
    if m.z < 0.0 {
        m = -m;
    }
    if dot(wo, m) * wo.z <= 0.0 || dot(wi, m) * wi.z <= 0.0 {
        return none;
    }
    let d = ggx_d(a, m);
    let f = fresnel_dielectric(dot(wo, m), eta).r;
    let g = ggx_g1(a, wo, m) * ggx_g1(a, wi, m);
    let up = select(-wo, wo, wo.z > 0.0);
    let pdf_m = ggx_pdf_visible(a, up, m);
    var value: f32;
    var pdf: f32;
    if reflected {
        value = f * d * g / (4.0 * abs(wo.z));
        pdf = pdf_m * f / (4.0 * abs(dot(wi, m)));
    } else {
        let denom = dot(wo, m) + eta_rel * dot(wi, m);
        let denom2 = denom * denom;
        value = abs((1.0 - f) * d * g * dot(wo, m) * dot(wi, m) / (wo.z * denom2));
        pdf = pdf_m * (1.0 - f) * abs(eta_rel * eta_rel * dot(wi, m) / denom2);
    }
    if !is_finite_f32(value) || !is_finite_f32(pdf) {
        return none;
    }
    return InterfaceEval(value, pdf, !reflected);
}
