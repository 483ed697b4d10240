// The `diffuse` shader (diffuse.rs). Parameters: the reflectance texture.
fn bsdf_sample_diffuse(p: u32, s: ShadingPoint, u: vec3f) -> BsdfSample {
    let wi = square_to_cosine_hemisphere(u.yz);
    let pdf = cosine_hemisphere_pdf(wi);
    if s.wo.z <= 0.0 || pdf <= 0.0 {
        return bsdf_sample_failed();
    }
    let albedo = texture_eval(param_u32(p), s.uv);
    return BsdfSample(wi, albedo, pdf, false, 1.0);
}

fn bsdf_eval_diffuse(p: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval {
    if s.wo.z <= 0.0 || wi.z <= 0.0 {
        return bsdf_eval_zero();
    }
    let albedo = texture_eval(param_u32(p), s.uv);
    return BsdfEval(albedo * (INV_PI * wi.z), cosine_hemisphere_pdf(wi));
}
