// The `ashikhmin_shirley` shader (ashikhmin_shirley.rs over
// half_vector.rs): the anisotropic Phong glossy lobe with Schlick's
// Fresnel and its energy-coupled diffuse term. Parameters: the diffuse
// and specular reflectance, exponent u and exponent v textures.

struct AshikhminShirleyLobes {
    rd: vec3f,
    rs: vec3f,
    nu: f32,
    nv: f32,
}

fn ashikhmin_shirley_lobes(p: u32, uv: vec2f) -> AshikhminShirleyLobes {
    return AshikhminShirleyLobes(
        texture_eval(param_u32(p), uv),
        texture_eval(param_u32(p + 1u), uv),
        clamp(texture_scalar(param_u32(p + 2u), uv), 0.0, 1e5),
        clamp(texture_scalar(param_u32(p + 3u), uv), 0.0, 1e5),
    );
}

// x^y for x in (0, 1], as `powf`: to within an ulp also where x or the
// result is near 1 (the sharp lobes' cases), where exp2(y·log2 x) keeps
// too few digits of log x.
fn ashikhmin_shirley_pow(x: f32, y: f32) -> f32 {
    let d = x - 1.0;
    var ln_x = log(x);
    if abs(d) < 1e-2 {
        // log(1 + d), exact to f32 for |d| < 1e-2 (d is exact there).
        ln_x = d * (1.0 - d * (0.5 - d * (1.0 / 3.0 - d * 0.25)));
    }
    let z = y * ln_x;
    if abs(z) < 1e-3 {
        return 1.0 + z * (1.0 + 0.5 * z);
    }
    return exp(z);
}

// The exponent nu cos²φh + nv sin²φh.
fn ashikhmin_shirley_exponent(l: AshikhminShirleyLobes, h: vec3f) -> f32 {
    let r2 = h.x * h.x + h.y * h.y;
    if r2 > 0.0 {
        return (l.nu * h.x * h.x + l.nv * h.y * h.y) / r2;
    }
    return 0.5 * (l.nu + l.nv);
}

// Density of the sampled half vector per unit solid angle.
fn ashikhmin_shirley_half_pdf(l: AshikhminShirleyLobes, h: vec3f) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    return sqrt((l.nu + 1.0) * (l.nv + 1.0)) / (2.0 * PI)
        * ashikhmin_shirley_pow(h.z, ashikhmin_shirley_exponent(l, h));
}

fn ashikhmin_shirley_sample_half(l: AshikhminShirleyLobes, u: vec2f) -> vec3f {
    // φ from the first quadrant's warp, mirrored into the others.
    let q = min(floor(u.x * 4.0), 3.0);
    let x = u.x * 4.0 - q;
    let k = sqrt((l.nu + 1.0) / (l.nv + 1.0));
    let phi0 = atan(k * tan(0.5 * PI * x));
    var phi = phi0;
    switch u32(q) {
        case 0u: { phi = phi0; }
        case 1u: { phi = PI - phi0; }
        case 2u: { phi = PI + phi0; }
        default: { phi = 2.0 * PI - phi0; }
    }
    let s = sin(phi);
    let c = cos(phi);
    let e = l.nu * c * c + l.nv * s * s;
    let cos_h = ashikhmin_shirley_pow(1.0 - u.y, 1.0 / (e + 1.0));
    let sin_h = sqrt(max(1.0 - cos_h * cos_h, 0.0));
    return vec3f(sin_h * c, sin_h * s, cos_h);
}

fn ashikhmin_shirley_fade(c: f32) -> f32 {
    let x = 1.0 - 0.5 * c;
    return 1.0 - x * x * x * x * x;
}

// (f·cos θi, pdf) of the whole model.
fn ashikhmin_shirley_eval_lobes(l: AshikhminShirleyLobes, wo: vec3f, wi: vec3f) -> BsdfEval {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return bsdf_eval_zero();
    }
    let ps = half_vector_specular_probability(l.rd, l.rs);
    var value = l.rd * (vec3f(1.0) - l.rs) * (28.0 / (23.0 * PI)
        * ashikhmin_shirley_fade(wi.z) * ashikhmin_shirley_fade(wo.z) * wi.z);
    var pdf = (1.0 - ps) * cosine_hemisphere_pdf(wi);
    let h = try_normalize(wo + wi);
    if any(h != vec3f(0.0)) {
        let kh = dot(wi, h);
        let ph = ashikhmin_shirley_half_pdf(l, h);
        if kh > 0.0 && ph > 0.0 {
            let spec = ph / (4.0 * kh * max(wi.z, wo.z));
            value += fresnel_schlick(kh, l.rs) * (spec * wi.z);
            pdf += ps * ph / (4.0 * kh);
        }
    }
    if !is_finite_vec3(value) || !is_finite_f32(pdf) {
        return bsdf_eval_zero();
    }
    return BsdfEval(value, pdf);
}

fn bsdf_sample_ashikhmin_shirley(p: u32, s: ShadingPoint, u: vec3f) -> BsdfSample {
    let wo = s.wo;
    if wo.z <= 0.0 {
        return bsdf_sample_failed();
    }
    let l = ashikhmin_shirley_lobes(p, s.uv);
    var wi: vec3f;
    if u.x < half_vector_specular_probability(l.rd, l.rs) {
        let h = ashikhmin_shirley_sample_half(l, u.yz);
        wi = 2.0 * dot(wo, h) * h - wo;
    } else {
        wi = square_to_cosine_hemisphere(u.yz);
    }
    let e = ashikhmin_shirley_eval_lobes(l, wo, wi);
    if e.pdf > 0.0 {
        return BsdfSample(wi, e.value / e.pdf, e.pdf, false, 1.0);
    }
    return bsdf_sample_failed();
}

fn bsdf_eval_ashikhmin_shirley(p: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval {
    return ashikhmin_shirley_eval_lobes(ashikhmin_shirley_lobes(p, s.uv), s.wo, wi);
}
