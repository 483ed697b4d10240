// The `isotropic` phase function: 1/4π in every direction, sampled
// uniformly on the sphere (weight 1).

fn phase_sample_isotropic(p: u32, wo: vec3f, u: vec2f) -> BsdfSample {
    return BsdfSample(square_to_uniform_sphere(u), vec3f(1.0), 0.25 * INV_PI, false, 1.0);
}

fn phase_eval_isotropic(p: u32, wo: vec3f, wi: vec3f) -> BsdfEval {
    return BsdfEval(vec3f(0.25 * INV_PI), 0.25 * INV_PI);
}
