// The `null` boundary: rays go straight through (a delta lobe of weight
// 1), it reflects nothing.

fn bsdf_sample_null(p: u32, s: ShadingPoint, u: vec3f) -> BsdfSample {
    return BsdfSample(-s.wo, vec3f(1.0), 1.0, true, 1.0);
}

fn bsdf_eval_null(p: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval {
    return bsdf_eval_zero();
}
