// The `thin_dielectric` shader (thin_dielectric.rs): a slab reflecting
// r + t²r/(1 − r²), passing light straight through; both lobes are delta
// lobes, so evaluation is zero. Parameters: the relative index η, the
// reflectance and transmittance textures.

fn thin_dielectric_slab(r: f32) -> f32 {
    if r < 1.0 {
        return r + (1.0 - r) * (1.0 - r) * r / (1.0 - r * r);
    }
    return 1.0;
}

fn bsdf_sample_thin_dielectric(p: u32, s: ShadingPoint, u: vec3f) -> BsdfSample {
    let wo = s.wo;
    if wo.z == 0.0 || !is_finite_vec3(wo) {
        return bsdf_sample_failed();
    }
    let r = thin_dielectric_slab(fresnel_dielectric(abs(wo.z), param_f32(p)).r);
    if u.x <= r {
        let kr = texture_eval(param_u32(p + 1u), s.uv);
        return BsdfSample(vec3f(-wo.x, -wo.y, wo.z), kr, r, true, 1.0);
    }
    let kt = texture_eval(param_u32(p + 2u), s.uv);
    return BsdfSample(-wo, kt, 1.0 - r, true, 1.0);
}

fn bsdf_eval_thin_dielectric(p: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval {
    return bsdf_eval_zero();
}
