// The `rough_diffuse` shader (rough_diffuse.rs): the full Oren–Nayar model
// (Mitsuba 3's `roughdiffuse`), sampled by the cosine. Parameters: the
// reflectance and α textures.

// acos(c) for c in (0, 1], as `f32::acos` computes it: atan2 of the sine
// from (1 − c)(1 + c), exact where c is near 1. WGSL's acos may be coarse
// (lavapipe's is off by up to 1.6e-4, its atan2 by 3e-6), and the model's
// cancellations at grazing angles would make that 0.3 % of a value.
fn rough_diffuse_acos(c: f32) -> f32 {
    return atan2(sqrt((1.0 - c) * (1.0 + c)), c);
}

// f·cos θi of the full Oren–Nayar model (`oren_nayar`).
fn rough_diffuse_value(rho: vec3f, alpha: f32, wo: vec3f, wi: vec3f) -> vec3f {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return vec3f(0.0);
    }
    let sigma = alpha / 1.41421356237309504880;
    let sigma2 = sigma * sigma;
    let cos_i = min(wi.z, 1.0);
    let cos_o = min(wo.z, 1.0);
    let sin_i = sqrt(max(1.0 - cos_i * cos_i, 0.0));
    let sin_o = sqrt(max(1.0 - cos_o * cos_o, 0.0));
    var cos_phi_diff = 0.0;
    if sin_i > 1e-4 && sin_o > 1e-4 {
        cos_phi_diff = clamp((wi.x * wo.x + wi.y * wo.y) / (sin_i * sin_o), -1.0, 1.0);
    }
    let theta_i = rough_diffuse_acos(cos_i);
    let theta_o = rough_diffuse_acos(cos_o);
    let alpha_ang = max(theta_i, theta_o);
    let beta = min(theta_i, theta_o);
    var sin_alpha = sin_i;
    var sin_beta = sin_o;
    var tan_beta = sin_o / cos_o;
    if cos_i > cos_o {
        sin_alpha = sin_o;
        sin_beta = sin_i;
        tan_beta = sin_i / cos_i;
    }
    let tmp = sigma2 / (sigma2 + 0.09);
    let tmp2 = 4.0 * INV_PI * INV_PI * alpha_ang * beta;
    let tmp3 = 2.0 * beta * INV_PI;
    let c1 = 1.0 - 0.5 * sigma2 / (sigma2 + 0.33);
    var c2 = 0.45 * tmp;
    let c3 = 0.125 * tmp * tmp2 * tmp2;
    let c4 = 0.17 * sigma2 / (sigma2 + 0.13);
    if cos_phi_diff > 0.0 {
        c2 *= sin_alpha;
    } else {
        c2 *= sin_alpha - tmp3 * tmp3 * tmp3;
    }
    let tan_half = (sin_alpha + sin_beta)
        / (sqrt(max(1.0 - sin_alpha * sin_alpha, 0.0))
            + sqrt(max(1.0 - sin_beta * sin_beta, 0.0)));
    let single = rho
        * (c1 + cos_phi_diff * c2 * tan_beta + (1.0 - abs(cos_phi_diff)) * c3 * tan_half);
    let double = rho * rho * (c4 * (1.0 - cos_phi_diff * tmp3 * tmp3));
    let value = max(single + double, vec3f(0.0)) * (INV_PI * cos_i);
    return select(vec3f(0.0), value, is_finite_vec3(value));
}

fn bsdf_sample_rough_diffuse(p: u32, s: ShadingPoint, u: vec3f) -> BsdfSample {
    let wi = square_to_cosine_hemisphere(u.yz);
    let pdf = cosine_hemisphere_pdf(wi);
    if s.wo.z <= 0.0 || pdf <= 0.0 {
        return bsdf_sample_failed();
    }
    let rho = texture_eval(param_u32(p), s.uv);
    let alpha = texture_scalar(param_u32(p + 1u), s.uv);
    return BsdfSample(wi, rough_diffuse_value(rho, alpha, s.wo, wi) / pdf, pdf, false, 1.0);
}

fn bsdf_eval_rough_diffuse(p: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval {
    if s.wo.z <= 0.0 || wi.z <= 0.0 {
        return bsdf_eval_zero();
    }
    let rho = texture_eval(param_u32(p), s.uv);
    let alpha = texture_scalar(param_u32(p + 1u), s.uv);
    return BsdfEval(rough_diffuse_value(rho, alpha, s.wo, wi), cosine_hemisphere_pdf(wi));
}
