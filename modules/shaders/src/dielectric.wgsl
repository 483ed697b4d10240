// The smooth `dielectric` shader (dielectric.rs). Parameters: the relative
// index η, the reflectance and transmittance textures. Both lobes are
// delta lobes: evaluation is zero.
fn bsdf_sample_dielectric(p: u32, s: ShadingPoint, u: vec3f) -> BsdfSample {
    let wo = s.wo;
    if wo.z == 0.0 || !is_finite_vec3(wo) {
        return bsdf_sample_failed();
    }
    let f = fresnel_dielectric(wo.z, param_f32(p));
    if u.x <= f.r {
        let kr = texture_eval(param_u32(p + 1u), s.uv);
        return BsdfSample(vec3f(-wo.x, -wo.y, wo.z), kr, f.r, true, 1.0);
    }
    let kt = texture_eval(param_u32(p + 2u), s.uv);
    let wi = vec3f(-f.eta_ti * wo.x, -f.eta_ti * wo.y, f.cos_t);
    return BsdfSample(wi, kt * (f.eta_ti * f.eta_ti), 1.0 - f.r, true, f.eta_it);
}

fn bsdf_eval_dielectric(p: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval {
    return bsdf_eval_zero();
}
