// Fresnel reflectance, as fresnel.rs (in single precision throughout):
// dielectric, conductor and Schlick.

// Unpolarised reflectance of a conductor of relative index eta + i k.
fn fresnel_conductor(cos_i: f32, eta: vec3f, k: vec3f) -> vec3f {
    let c2 = min(cos_i * cos_i, 1.0);
    let s2 = 1.0 - c2;
    let s4 = s2 * s2;
    let t1 = eta * eta - k * k - vec3f(s2);
    let a2pb2 = sqrt(max(t1 * t1 + 4.0 * k * k * eta * eta, vec3f(0.0)));
    let a = sqrt(max(0.5 * (a2pb2 + t1), vec3f(0.0)));
    let term1 = a2pb2 + vec3f(c2);
    let term2 = 2.0 * abs(cos_i) * a;
    let tiny = vec3f(1.17549435e-38);
    let rs = (term1 - term2) / max(term1 + term2, tiny);
    let term3 = a2pb2 * c2 + vec3f(s4);
    let term4 = term2 * s2;
    let rp = rs * (term3 - term4) / max(term3 + term4, tiny);
    return clamp(0.5 * (rs + rp), vec3f(0.0), vec3f(1.0));
}

// r: reflectance; cos_t: signed cosine of the transmitted direction;
// eta_it = η_t/η_i on the side of incidence, eta_ti its inverse.
struct DielectricFresnel {
    r: f32,
    cos_t: f32,
    eta_it: f32,
    eta_ti: f32,
}

fn fresnel_dielectric(cos_i: f32, eta: f32) -> DielectricFresnel {
    var eta_it = 1.0 / eta;
    var eta_ti = eta;
    if cos_i >= 0.0 {
        eta_it = eta;
        eta_ti = 1.0 / eta;
    }
    let ci = min(abs(cos_i), 1.0);
    let cos_t2 = 1.0 - (1.0 - ci * ci) * eta_ti * eta_ti;
    if cos_t2 <= 0.0 {
        return DielectricFresnel(1.0, 0.0, eta_it, eta_ti);
    }
    let ct = sqrt(cos_t2);
    var r = 0.0;
    if eta != 1.0 {
        if ci == 0.0 {
            r = 1.0;
        } else {
            let a_s = (ci - eta_it * ct) / (ci + eta_it * ct);
            let a_p = (ct - eta_it * ci) / (ct + eta_it * ci);
            r = min(0.5 * (a_s * a_s + a_p * a_p), 1.0);
        }
    }
    return DielectricFresnel(r, select(ct, -ct, cos_i >= 0.0), eta_it, eta_ti);
}

// Schlick's approximation R0 + (1 − R0)(1 − cos)^5, per channel.
fn fresnel_schlick(cos_i: f32, r0: vec3f) -> vec3f {
    let m = clamp(1.0 - abs(cos_i), 0.0, 1.0);
    let m2 = m * m;
    return r0 + (vec3f(1.0) - r0) * (m2 * m2 * m);
}
