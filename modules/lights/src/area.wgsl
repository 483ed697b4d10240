// The `area` light (area.rs, rectangle.rs, sphere.rs). Parameters:
// radiance (3), the number of parts, the number of primitives, then 16
// words per part — kind (0 triangle, 1 rectangle, 2 sphere), probability,
// cumulative area, then a, b, c, n of a triangle; corner, ex, ey, n of a
// rectangle; centre, radius of a sphere — then the part of each primitive.

const AREA_PART_WORDS: u32 = 16u;

fn area_part(p: u32, i: u32) -> u32 {
    return p + 5u + i * AREA_PART_WORDS;
}

fn area_total(p: u32) -> f32 {
    return param_f32(area_part(p, param_u32(p + 3u) - 1u) + 2u);
}

// Density (solid angle) of area sampling of the whole light at point x
// with normal n, seen from `origin`.
fn area_pdf_by_area(p: u32, origin: vec3f, x: vec3f, n: vec3f) -> f32 {
    let d = origin - x;
    let dist2 = dot(d, d);
    let n_dot_d = dot(n, d);
    if n_dot_d > 0.0 {
        return dist2 * sqrt(dist2) / (n_dot_d * area_total(p));
    }
    return 0.0;
}

// ---- Spherical rectangles (Ureña et al. 2013, as rectangle.rs) ----

struct SphericalRect {
    origin: vec3f,
    x: vec3f,
    y: vec3f,
    z: vec3f,
    x0: f32,
    x1: f32,
    y0: f32,
    y1: f32,
    z0: f32,
    b0: f32,
    b1: f32,
    k0: f32,
    k1: f32,
    solid_angle: f32,
}

fn angle_between(a: vec3f, b: vec3f) -> f32 {
    if dot(a, b) < 0.0 {
        return PI - 2.0 * asin(min(length(a + b) * 0.5, 1.0));
    }
    return 2.0 * asin(min(length(b - a) * 0.5, 1.0));
}

fn safe_normal(v: vec3f) -> vec3f {
    let l = length(v);
    if l > 0.0 && is_finite_f32(1.0 / l) {
        return v / l;
    }
    return vec3f(0.0);
}

// The rectangle as seen from `origin` when solid-angle sampling applies
// (solid_angle > 0), as Rectangle::spherical decides.
fn spherical_rect(origin: vec3f, corner: vec3f, ex: vec3f, ey: vec3f, n: vec3f) -> SphericalRect {
    var s: SphericalRect;
    s.solid_angle = 0.0;
    let centre = corner + 0.5 * (ex + ey);
    let area = length(cross(ex, ey));
    let to_centre = centre - origin;
    if dot(n, origin - corner) <= 0.0 || dot(to_centre, to_centre) > 4.0 * area {
        return s;
    }
    let exl = length(ex);
    let eyl = length(ey);
    s.origin = origin;
    s.x = ex / exl;
    s.y = ey / eyl;
    s.z = cross(s.x, s.y);
    let d = corner - origin;
    s.z0 = dot(d, s.z);
    if s.z0 > 0.0 {
        s.z = -s.z;
        s.z0 = -s.z0;
    }
    s.x0 = dot(d, s.x);
    s.y0 = dot(d, s.y);
    s.x1 = s.x0 + exl;
    s.y1 = s.y0 + eyl;
    let v00 = vec3f(s.x0, s.y0, s.z0);
    let v01 = vec3f(s.x0, s.y1, s.z0);
    let v10 = vec3f(s.x1, s.y0, s.z0);
    let v11 = vec3f(s.x1, s.y1, s.z0);
    let n0 = safe_normal(cross(v00, v10));
    let n1 = safe_normal(cross(v10, v11));
    let n2 = safe_normal(cross(v11, v01));
    let n3 = safe_normal(cross(v01, v00));
    if dot(n0, n0) == 0.0 || dot(n1, n1) == 0.0 || dot(n2, n2) == 0.0 || dot(n3, n3) == 0.0 {
        return s;
    }
    let g0 = angle_between(-n0, n1);
    let g1 = angle_between(-n1, n2);
    let g2 = angle_between(-n2, n3);
    let g3 = angle_between(-n3, n0);
    let solid_angle = g0 + g1 + g2 + g3 - 2.0 * PI;
    s.b0 = n0.z;
    s.b1 = n2.z;
    s.k0 = g0 + g1 - 2.0 * PI;
    s.k1 = g2 + g3;
    if solid_angle >= 3e-4 && solid_angle < 6.22 {
        s.solid_angle = solid_angle;
    }
    return s;
}

fn spherical_rect_sample(s: SphericalRect, u: vec2f) -> vec3f {
    let au = u.x * s.k0 + (u.x - 1.0) * s.k1;
    let fu = (cos(au) * s.b0 - s.b1) / sin(au);
    let cu = clamp(sign(fu) * (1.0 / sqrt(fu * fu + s.b0 * s.b0)), -1.0 + 1e-7, 1.0 - 1e-7);
    let xu = clamp(-(cu * s.z0) / sqrt(max(1.0 - cu * cu, 0.0)), s.x0, s.x1);
    let dd = sqrt(xu * xu + s.z0 * s.z0);
    let h0 = s.y0 / sqrt(dd * dd + s.y0 * s.y0);
    let h1 = s.y1 / sqrt(dd * dd + s.y1 * s.y1);
    let hv = h0 + u.y * (h1 - h0);
    let hv2 = hv * hv;
    var yv = s.y1;
    if hv2 < 1.0 - 1e-6 {
        yv = clamp(hv * dd / sqrt(1.0 - hv2), s.y0, s.y1);
    }
    return s.origin + s.x * xu + s.y * yv + s.z * s.z0;
}

// ---- Spheres seen from outside (pbrt-v4's cone sampling, as sphere.rs) ----

// (sin²θmax, cos θmax, 1 − cos θmax), or sin²θmax < 0 from inside.
fn sphere_cone(centre: vec3f, radius: f32, origin: vec3f) -> vec3f {
    let d = centre - origin;
    let dist2 = dot(d, d);
    let r2 = radius * radius;
    if dist2 <= r2 * (1.0 + 1e-4) {
        return vec3f(-1.0, 0.0, 0.0);
    }
    let sin2_max = r2 / dist2;
    let cos_max = sqrt(max(1.0 - sin2_max, 0.0));
    var one_minus = 1.0 - cos_max;
    if sin2_max < 0.00068523 {
        one_minus = 0.5 * sin2_max;
    }
    return vec3f(sin2_max, cos_max, one_minus);
}

// ---- The light ----

fn light_sample_area(p: u32, r: vec3f, u: vec2f) -> LightSample {
    let radiance = param_vec3(p);
    let count = param_u32(p + 3u);
    // The part, by cumulative area (binary search), and u.x reused.
    let target_area = u.x * area_total(p);
    var lo = 0u;
    var hi = count - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if param_f32(area_part(p, mid) + 2u) <= target_area {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let q = area_part(p, lo);
    var before = 0.0;
    if lo > 0u {
        before = param_f32(area_part(p, lo - 1u) + 2u);
    }
    let width = param_f32(q + 2u) - before;
    var ux = 0.0;
    if width > 0.0 {
        ux = clamp((target_area - before) / width, 0.0, 0.99999994);
    }
    if count == 1u {
        ux = u.x;
    }
    let uu = vec2f(ux, u.y);
    let kind = param_u32(q);
    let prob = param_f32(q + 1u);
    var x = vec3f(0.0);
    var n = vec3f(0.0);
    var pdf = -1.0;
    if kind == 0u {
        let b = square_to_uniform_triangle(uu);
        x = param_vec3(q + 3u) * (1.0 - b.x - b.y) + param_vec3(q + 6u) * b.x + param_vec3(q + 9u) * b.y;
        n = param_vec3(q + 12u);
    } else if kind == 1u {
        let corner = param_vec3(q + 3u);
        let ex = param_vec3(q + 6u);
        let ey = param_vec3(q + 9u);
        n = param_vec3(q + 12u);
        let s = spherical_rect(r, corner, ex, ey, n);
        if s.solid_angle > 0.0 {
            x = spherical_rect_sample(s, uu);
            pdf = prob / s.solid_angle;
        } else {
            x = corner + ex * uu.x + ey * uu.y;
        }
    } else {
        let centre = param_vec3(q + 3u);
        let radius = param_f32(q + 6u);
        let cone = sphere_cone(centre, radius, r);
        if cone.x >= 0.0 {
            var sin2_theta = 0.0;
            var cos_theta = 0.0;
            if cone.x < 0.00068523 {
                sin2_theta = cone.x * uu.x;
                cos_theta = sqrt(1.0 - sin2_theta);
            } else {
                cos_theta = (cone.y - 1.0) * uu.x + 1.0;
                sin2_theta = 1.0 - cos_theta * cos_theta;
            }
            let cos_alpha = sin2_theta / sqrt(cone.x)
                + cos_theta * sqrt(max(1.0 - sin2_theta / cone.x, 0.0));
            let sin_alpha = sqrt(max(1.0 - cos_alpha * cos_alpha, 0.0));
            let phi = 2.0 * PI * uu.y;
            let w = vec3f(sin_alpha * cos(phi), sin_alpha * sin(phi), cos_alpha);
            n = -(frame_from_normal(normalize(centre - r)) * w);
            x = centre + n * radius;
            pdf = prob / (2.0 * PI * cone.z);
        } else {
            n = square_to_uniform_sphere(uu);
            x = centre + n * radius;
        }
    }
    if pdf < 0.0 {
        pdf = area_pdf_by_area(p, r, x, n);
    }
    if pdf > 0.0 && is_finite_f32(pdf) {
        return LightSample(x, n, radiance, pdf);
    }
    return LightSample(x, n, vec3f(0.0), 0.0);
}

fn light_hit_area(p: u32, h: EmitterHit) -> EmitterEval {
    let count = param_u32(p + 3u);
    let prims = param_u32(p + 4u);
    let part = param_u32(area_part(p, count) + min(h.primitive, prims - 1u));
    let q = area_part(p, part);
    let kind = param_u32(q);
    let prob = param_f32(q + 1u);
    var pdf = -1.0;
    if kind == 1u {
        let s = spherical_rect(h.origin, param_vec3(q + 3u), param_vec3(q + 6u), param_vec3(q + 9u), param_vec3(q + 12u));
        if s.solid_angle > 0.0 {
            pdf = prob / s.solid_angle;
        }
    } else if kind == 2u {
        let cone = sphere_cone(param_vec3(q + 3u), param_f32(q + 6u), h.origin);
        if cone.x >= 0.0 {
            pdf = prob / (2.0 * PI * cone.z);
        }
    }
    if pdf < 0.0 {
        pdf = area_pdf_by_area(p, h.origin, h.p, h.n);
    }
    if pdf > 0.0 {
        return EmitterEval(param_vec3(p), pdf);
    }
    return EmitterEval(vec3f(0.0), 0.0);
}
