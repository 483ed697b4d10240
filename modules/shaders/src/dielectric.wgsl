// The `dielectric` shader (dielectric.rs), smooth (two delta lobes,
// evaluation zero) or rough (Walter et al. 2007 through `interface_sample`
// and `interface_eval`). Parameters: the relative index η, the reflectance
// and transmittance textures, smooth (0/1), the α_u and α_v textures.

fn dielectric_alpha(p: u32, uv: vec2f) -> vec2f {
    return ggx_alpha(texture_scalar(param_u32(p + 4u), uv), texture_scalar(param_u32(p + 5u), uv));
}

fn bsdf_sample_dielectric(p: u32, s: ShadingPoint, u: vec3f) -> BsdfSample {
    let wo = s.wo;
    if wo.z == 0.0 || !is_finite_vec3(wo) {
        return bsdf_sample_failed();
    }
    let eta = param_f32(p);
    if param_u32(p + 3u) != 0u {
        let f = fresnel_dielectric(wo.z, eta);
        if u.x <= f.r {
            let kr = texture_eval(param_u32(p + 1u), s.uv);
            return BsdfSample(vec3f(-wo.x, -wo.y, wo.z), kr, f.r, true, 1.0);
        }
        let kt = texture_eval(param_u32(p + 2u), s.uv);
        let wi = vec3f(-f.eta_ti * wo.x, -f.eta_ti * wo.y, f.cos_t);
        return BsdfSample(wi, kt * (f.eta_ti * f.eta_ti), 1.0 - f.r, true, f.eta_it);
    }
    let i = interface_sample(dielectric_alpha(p, s.uv), eta, wo, u);
    if !i.ok {
        return bsdf_sample_failed();
    }
    if !i.transmitted {
        let kr = texture_eval(param_u32(p + 1u), s.uv);
        return BsdfSample(i.wi, kr * i.weight, i.pdf, false, 1.0);
    }
    let kt = texture_eval(param_u32(p + 2u), s.uv);
    return BsdfSample(i.wi, kt * i.weight, i.pdf, false, select(1.0 / eta, eta, wo.z > 0.0));
}

fn bsdf_eval_dielectric(p: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval {
    if param_u32(p + 3u) != 0u {
        return bsdf_eval_zero();
    }
    let e = interface_eval(dielectric_alpha(p, s.uv), param_f32(p), s.wo, wi);
    let tint = texture_eval(param_u32(p + select(1u, 2u, e.transmitted)), s.uv);
    return BsdfEval(tint * e.value, e.pdf);
}
