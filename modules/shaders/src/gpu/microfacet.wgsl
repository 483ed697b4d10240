// GGX (Trowbridge–Reitz) with visible-normal sampling, as microfacet.rs.
// `a` holds (α_u, α_v), each at least 1e-4.

fn ggx_alpha(au: f32, av: f32) -> vec2f {
    return max(vec2f(au, av), vec2f(1e-4));
}

fn ggx_d(a: vec2f, m: vec3f) -> f32 {
    if m.z <= 0.0 {
        return 0.0;
    }
    let x = m.x / a.x;
    let y = m.y / a.y;
    let s = x * x + y * y + m.z * m.z;
    let d = 1.0 / (PI * a.x * a.y * s * s);
    return select(0.0, d, is_finite_f32(d));
}

fn ggx_g1(a: vec2f, v: vec3f, m: vec3f) -> f32 {
    if dot(v, m) * v.z <= 0.0 {
        return 0.0;
    }
    let xy = (a.x * v.x) * (a.x * v.x) + (a.y * v.y) * (a.y * v.y);
    if xy == 0.0 {
        return 1.0;
    }
    let tan2 = xy / (v.z * v.z);
    return 2.0 / (1.0 + sqrt(1.0 + tan2));
}

fn ggx_sample_visible(a: vec2f, wo: vec3f, u: vec2f) -> vec3f {
    let vh = normalize(vec3f(a.x * wo.x, a.y * wo.y, wo.z));
    let lensq = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3f(1.0, 0.0, 0.0);
    if lensq > 0.0 {
        t1 = vec3f(-vh.y, vh.x, 0.0) / sqrt(lensq);
    }
    let t2 = cross(vh, t1);
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    let p1 = r * cos(phi);
    let h = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - h) * sqrt(max(1.0 - p1 * p1, 0.0)) + h * r * sin(phi);
    let nh = t1 * p1 + t2 * p2 + vh * sqrt(max(1.0 - p1 * p1 - p2 * p2, 0.0));
    return normalize(vec3f(a.x * nh.x, a.y * nh.y, max(nh.z, 1e-7)));
}

fn ggx_pdf_visible(a: vec2f, wo: vec3f, m: vec3f) -> f32 {
    if wo.z <= 0.0 {
        return 0.0;
    }
    return ggx_g1(a, wo, m) * max(dot(wo, m), 0.0) * ggx_d(a, m) / wo.z;
}

fn reflect_about(v: vec3f, m: vec3f) -> vec3f {
    return 2.0 * dot(v, m) * m - v;
}
