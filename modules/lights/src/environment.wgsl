// The `environment` light (environment.rs): a constant or an
// equirectangular map, sampled from the same tables as the Rust code.
// Parameters (offsets from p): 0 reach (2 × the scene sphere's radius),
// 1..10 the light-to-render rotation's columns, 10 the kind (0 constant,
// 1 map). A constant: 11..14 its radiance. A map: 11 width w, 12 height h,
// 13..17 the offsets of its tables: the sampling weight per pixel (w × h,
// row-major), the marginal CDF over the h − 1 cell rows (h entries), the
// conditional CDF of each cell row (w + 1 entries each), the texels (3
// floats each, row-major, zenith first); the tables follow from 17 on.

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

// bilinear.rs: sample_linear, a point of [0, 1) with density
// ∝ (1 − x) a + x b.
fn env_sample_linear(u: f32, a: f32, b: f32) -> f32 {
    let sum = a + b;
    if sum <= 0.0 {
        return u;
    }
    let an = a / sum;
    let bn = b / sum;
    let den = an + sqrt((1.0 - u) * an * an + u * bn * bn);
    if den > 0.0 {
        return min(u / den, 0.99999994);
    }
    return 0.0;
}

// bilinear.rs: sample_bilinear; corners w.x at (0, 0), w.y at (1, 0),
// w.z at (0, 1), w.w at (1, 1).
fn env_sample_bilinear(u: vec2f, w: vec4f) -> vec2f {
    let y = env_sample_linear(u.y, w.x + w.y, w.z + w.w);
    let x = env_sample_linear(u.x, w.x + (w.z - w.x) * y, w.y + (w.w - w.y) * y);
    return vec2f(x, y);
}

// bilinear.rs: bilinear_pdf.
fn env_bilinear_pdf(t: vec2f, w: vec4f) -> f32 {
    let sum = w.x + w.y + w.z + w.w;
    if sum <= 0.0 {
        return 1.0;
    }
    let top = w.x + (w.y - w.x) * t.x;
    let bottom = w.z + (w.w - w.z) * t.x;
    return 4.0 * (top + (bottom - top) * t.y) / sum;
}

// Map's Patch: a cell (between the centres of pixels x0 and x1, rows y0
// and y0 + 1) and a place t within it.
struct EnvPatch {
    x0: u32,
    x1: u32,
    y0: u32,
    t: vec2f,
}

// Map::locate: the cell of (u, v), as the radiance is interpolated.
fn env_locate(p: u32, u: f32, v: f32) -> EnvPatch {
    let w = param_u32(p + 11u);
    let h = param_u32(p + 12u);
    let fx = u * f32(w) - 0.5;
    let fy = v * f32(h - 1u);
    let xf = floor(fx);
    let wi = i32(w);
    let x0 = u32(((i32(xf) % wi) + wi) % wi);
    let y0 = min(u32(max(fy, 0.0)), h - 2u);
    return EnvPatch(x0, (x0 + 1u) % w, y0, vec2f(fx - xf, fy - f32(y0)));
}

fn env_texel(p: u32, x: u32, y: u32) -> vec3f {
    return param_vec3(p + param_u32(p + 16u) + 3u * (y * param_u32(p + 11u) + x));
}

// Map::radiance: bilinear between pixels.
fn env_radiance(p: u32, at: EnvPatch) -> vec3f {
    let t = at.t;
    let top = env_texel(p, at.x0, at.y0) * (1.0 - t.x) + env_texel(p, at.x1, at.y0) * t.x;
    let bottom = env_texel(p, at.x0, at.y0 + 1u) * (1.0 - t.x) + env_texel(p, at.x1, at.y0 + 1u) * t.x;
    return top * (1.0 - t.y) + bottom * t.y;
}

// Map::corners of the pixel weights.
fn env_weights(p: u32, at: EnvPatch) -> vec4f {
    let w = param_u32(p + 11u);
    let weights = p + param_u32(p + 13u);
    let top = weights + at.y0 * w;
    let bottom = top + w;
    return vec4f(
        param_f32(top + at.x0),
        param_f32(top + at.x1),
        param_f32(bottom + at.x0),
        param_f32(bottom + at.x1),
    );
}

// Map::pdf: the solid-angle density at `at`, where sin θ is `sin_theta`.
fn env_pdf(p: u32, at: EnvPatch, sin_theta: f32) -> f32 {
    if sin_theta <= 0.0 {
        return 0.0;
    }
    let w = param_u32(p + 11u);
    let rows = param_u32(p + 12u) - 1u;
    let marginal = p + param_u32(p + 14u);
    let row = p + param_u32(p + 15u) + at.y0 * (w + 1u);
    let cell = (param_f32(marginal + at.y0 + 1u) - param_f32(marginal + at.y0))
        * (param_f32(row + at.x0 + 1u) - param_f32(row + at.x0))
        * f32(w * rows);
    let within = env_bilinear_pdf(at.t, env_weights(p, at));
    return cell * within / (2.0 * PI * PI * sin_theta);
}

// EnvironmentLight::eval_local: radiance from the light-space direction d
// and the density of sampling it.
fn env_eval_local(p: u32, d: vec3f) -> EmitterEval {
    if param_u32(p + 10u) == 0u {
        return EmitterEval(param_vec3(p + 11u), 0.25 * INV_PI);
    }
    var u = atan2(d.x, -d.z) / (2.0 * PI);
    u -= floor(u);
    // θ from atan2, not acos(y): exact near the poles too (and some
    // GPUs' acos is off by 1e-4).
    let sin_theta = sqrt(d.x * d.x + d.z * d.z);
    let v = atan2(sin_theta, d.y) / PI;
    let at = env_locate(p, u, v);
    return EmitterEval(env_radiance(p, at), env_pdf(p, at, sin_theta));
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
        var at = EnvPatch(cx.i, (cx.i + 1u) % w, cy.i, vec2f(0.0));
        at.t = env_sample_bilinear(vec2f(cx.rest, cy.rest), env_weights(p, at));
        // Cells start at the first pixel centre, half a pixel into the map.
        var su = (f32(cx.i) + 0.5 + at.t.x) / f32(w);
        if su >= 1.0 {
            su -= 1.0;
        }
        let v = (f32(cy.i) + at.t.y) / f32(rows);
        let sin_t = sin(PI * v);
        let cos_t = cos(PI * v);
        let phi = 2.0 * PI * su;
        local = vec3f(sin(phi) * sin_t, cos_t, -cos(phi) * sin_t);
        radiance = env_radiance(p, at);
        pdf = env_pdf(p, at, sin_t);
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
