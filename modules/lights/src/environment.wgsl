// The `environment` light (environment.rs): a constant or an
// equirectangular map, sampled from the same tables as the Rust code.
// Parameters (offsets from p): 0 reach (2 × the scene sphere's radius),
// 1..10 the light-to-render rotation's columns, 10 the kind (0 constant,
// 1 map). A constant: 11..14 its radiance. A map: 11 width w, 12 height h,
// 13..17 the offsets of its tables: cos θ per pixel row (h), the marginal
// CDF over the h − 1 cell rows (h entries), the conditional CDF of each
// cell row (w + 1 entries each), the texels (3 floats each, row-major,
// zenith first); the tables follow from 17 on.

// acos as precise as atan2 (some GPUs' acos is off by 1e-4), for x in
// [−1, 1].
fn env_acos(x: f32) -> f32 {
    return atan2(sqrt(max((1.0 - x) * (1.0 + x), 0.0)), x);
}

struct EnvCell {
    i: u32,
    rest: f32,
}

// Distribution1D::sample over the n + 1 CDF entries at `cdf`.
fn env_sample_1d(cdf: u32, n: u32, u: f32) -> EnvCell {
    // partition_point: the number of entries ≤ u.
    var lo = 0u;
    var hi = n + 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if param_f32(cdf + mid) <= u {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let i = clamp(lo, 1u, n) - 1u;
    let c0 = param_f32(cdf + i);
    let width = param_f32(cdf + i + 1u) - c0;
    var rest = 0.5;
    if width > 0.0 {
        rest = clamp((u - c0) / width, 0.0, 0.99999994);
    }
    return EnvCell(i, rest);
}

fn env_texel(p: u32, x: u32, y: u32) -> vec3f {
    return param_vec3(p + param_u32(p + 16u) + 3u * (y * param_u32(p + 11u) + x));
}

// Map::lookup: bilinear between pixels, wrapping in u.
fn env_lookup(p: u32, u: f32, v: f32) -> vec3f {
    let w = param_u32(p + 11u);
    let h = param_u32(p + 12u);
    let fx = u * f32(w) - 0.5;
    let fy = v * f32(h - 1u);
    let xf = floor(fx);
    let wi = i32(w);
    let x0 = u32(((i32(xf) % wi) + wi) % wi);
    let y0 = min(u32(max(fy, 0.0)), h - 2u);
    let tx = fx - xf;
    let ty = fy - f32(y0);
    let x1 = (x0 + 1u) % w;
    let top = env_texel(p, x0, y0) * (1.0 - tx) + env_texel(p, x1, y0) * tx;
    let bottom = env_texel(p, x0, y0 + 1u) * (1.0 - tx) + env_texel(p, x1, y0 + 1u) * tx;
    return top * (1.0 - ty) + bottom * ty;
}

// Map::cell_pdf: the solid-angle density of cell (x, y).
fn env_cell_pdf(p: u32, x: u32, y: u32) -> f32 {
    let w = param_u32(p + 11u);
    let rows = param_u32(p + 12u) - 1u;
    let cos_at = p + param_u32(p + 13u);
    let band = param_f32(cos_at + y) - param_f32(cos_at + y + 1u);
    if band <= 0.0 {
        return 0.0;
    }
    let marginal = p + param_u32(p + 14u);
    let row = p + param_u32(p + 15u) + y * (w + 1u);
    let pdf = (param_f32(marginal + y + 1u) - param_f32(marginal + y))
        * (param_f32(row + x + 1u) - param_f32(row + x))
        * f32(w * rows);
    return pdf / (f32(rows) * (2.0 * PI) * band);
}

// EnvironmentLight::eval_local: radiance from the light-space direction d
// and the density of sampling it.
fn env_eval_local(p: u32, d: vec3f) -> EmitterEval {
    if param_u32(p + 10u) == 0u {
        return EmitterEval(param_vec3(p + 11u), 0.25 * INV_PI);
    }
    var u = atan2(d.x, -d.z) / (2.0 * PI);
    u -= floor(u);
    let v = env_acos(clamp(d.y, -1.0, 1.0)) / PI;
    // Map::cell
    let w = param_u32(p + 11u);
    let h = param_u32(p + 12u);
    let wi = i32(w);
    let x = u32(((i32(floor(u * f32(w) - 0.5)) % wi) + wi) % wi);
    let y = min(u32(max(v * f32(h - 1u), 0.0)), h - 2u);
    return EmitterEval(env_lookup(p, u, v), env_cell_pdf(p, x, y));
}

fn light_sample_environment(p: u32, r: vec3f, u: vec2f) -> LightSample {
    var local = vec3f(0.0);
    var radiance = vec3f(0.0);
    var pdf = 0.0;
    if param_u32(p + 10u) == 0u {
        local = square_to_uniform_sphere(u);
        radiance = param_vec3(p + 11u);
        pdf = 0.25 * INV_PI;
    } else {
        // Map::sample
        let w = param_u32(p + 11u);
        let rows = param_u32(p + 12u) - 1u;
        let cy = env_sample_1d(p + param_u32(p + 14u), rows, u.y);
        let cx = env_sample_1d(p + param_u32(p + 15u) + cy.i * (w + 1u), w, u.x);
        let px = (f32(cx.i) + cx.rest) / f32(w);
        let py = (f32(cy.i) + cy.rest) / f32(rows);
        let fv = clamp(py * f32(rows) - f32(cy.i), 0.0, 1.0);
        let cos_at = p + param_u32(p + 13u);
        let z0 = param_f32(cos_at + cy.i);
        let z1 = param_f32(cos_at + cy.i + 1u);
        let cos_t = clamp(z0 + (z1 - z0) * fv, -1.0, 1.0);
        let sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
        var su = px + 0.5 / f32(w);
        if su >= 1.0 {
            su -= 1.0;
        }
        let phi = 2.0 * PI * su;
        local = vec3f(sin(phi) * sin_t, cos_t, -cos(phi) * sin_t);
        radiance = env_lookup(p, su, env_acos(cos_t) / PI);
        pdf = env_cell_pdf(p, cx.i, cy.i);
    }
    let to_render = mat3x3f(param_vec3(p + 1u), param_vec3(p + 4u), param_vec3(p + 7u));
    let wi = to_render * local;
    if pdf <= 0.0 {
        radiance = vec3f(0.0);
    }
    return LightSample(r + wi * param_f32(p), vec3f(0.0), radiance, pdf);
}

fn light_escaped_environment(p: u32, dir: vec3f) -> EmitterEval {
    let to_render = mat3x3f(param_vec3(p + 1u), param_vec3(p + 4u), param_vec3(p + 7u));
    // The inverse rotation: its transpose.
    return env_eval_local(p, dir * to_render);
}
