// The module contract on the GPU: the structures of the module traits,
// parameter access, and the sampling warps of `radiant_core::warp`.
// Every kernel starts with it; module code may use all of it.

const PI: f32 = 3.14159265358979323846;
const INV_PI: f32 = 0.31830988618379067154;
const FLOAT_MAX: f32 = 3.40282347e38;

// A surface point as a shader sees it (local shading frame: +z normal),
// with the surface's ∂p/∂u and ∂p/∂v in that frame: their real lengths
// where the kernel has tangent frames (a material declared
// `Effects::TANGENT_FRAMES`), else the frame's unit tangents (1, 0, 0) and
// (0, 1, 0), as `SurfaceBatch` gives them on the CPU.
struct ShadingPoint {
    wo: vec3f,
    uv: vec2f,
    dp_du: vec3f,
    dp_dv: vec3f,
}

// f·|cos θi|/pdf of a sampled incident direction (zero weight: failed).
struct BsdfSample {
    wi: vec3f,
    weight: vec3f,
    pdf: f32,
    delta: bool,
    eta: f32,
}

struct BsdfEval {
    value: vec3f,
    pdf: f32,
}

struct LightSample {
    p: vec3f,
    n: vec3f,
    radiance: vec3f,
    pdf: f32,
}

struct EmitterHit {
    origin: vec3f,
    p: vec3f,
    n: vec3f,
    primitive: u32,
}

struct EmitterEval {
    radiance: vec3f,
    pdf: f32,
}

struct CameraRay {
    origin: vec3f,
    dir: vec3f,
    weight: f32,
}

// `radiant_core::Frame` as the columns (s, t, n) of a matrix.

// `Frame::from_normal`: Duff et al.'s frame around the unit vector n.
fn frame_from_normal(n: vec3f) -> mat3x3f {
    let sgn = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sgn + n.z);
    let b = n.x * n.y * a;
    let s = vec3f(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
    let t = vec3f(b, sgn + n.y * n.y * a, -n.y);
    return mat3x3f(s, t, n);
}

// `Frame::with_tangent`: the frame around the unit vector n whose tangent
// is s made orthogonal to n; all zeros where s is zero, not finite or
// (nearly) parallel to n (test with `frame_usable`).
fn frame_with_tangent(n: vec3f, s: vec3f) -> mat3x3f {
    let perp = s - n * dot(n, s);
    let l2 = dot(perp, perp);
    if !(l2 > 1e-10 * dot(s, s)) || !is_finite_f32(l2) {
        return mat3x3f(vec3f(0.0), vec3f(0.0), vec3f(0.0));
    }
    let t = perp / sqrt(l2);
    return mat3x3f(t, cross(n, t), n);
}

fn frame_usable(f: mat3x3f) -> bool {
    return any(f[2] != vec3f(0.0));
}

fn frame_to_local(f: mat3x3f, v: vec3f) -> vec3f {
    return vec3f(dot(v, f[0]), dot(v, f[1]), dot(v, f[2]));
}

fn frame_to_world(f: mat3x3f, v: vec3f) -> vec3f {
    return f[0] * v.x + f[1] * v.y + f[2] * v.z;
}

fn bsdf_sample_failed() -> BsdfSample {
    return BsdfSample(vec3f(0.0), vec3f(0.0), 0.0, false, 1.0);
}

fn bsdf_eval_zero() -> BsdfEval {
    return BsdfEval(vec3f(0.0), 0.0);
}

fn param_u32(i: u32) -> u32 {
    return module_params[i];
}

fn param_f32(i: u32) -> f32 {
    return bitcast<f32>(module_params[i]);
}

fn param_vec3(i: u32) -> vec3f {
    return vec3f(param_f32(i), param_f32(i + 1u), param_f32(i + 2u));
}

fn is_finite_f32(x: f32) -> bool {
    // NaN fails both comparisons; infinities fail the bound.
    return abs(x) <= FLOAT_MAX;
}

fn is_finite_vec3(v: vec3f) -> bool {
    return is_finite_f32(v.x) && is_finite_f32(v.y) && is_finite_f32(v.z);
}

// Shirley–Chiu concentric map of the unit square to the unit disk.
fn square_to_disk_concentric(u: vec2f) -> vec2f {
    let o = 2.0 * u - vec2f(1.0);
    if o.x == 0.0 && o.y == 0.0 {
        return vec2f(0.0);
    }
    if abs(o.x) > abs(o.y) {
        let phi = 0.78539816339744830962 * (o.y / o.x);
        return vec2f(cos(phi), sin(phi)) * o.x;
    }
    let phi = 0.78539816339744830962 * (o.x / o.y);
    return vec2f(sin(phi), cos(phi)) * o.y;
}

fn square_to_cosine_hemisphere(u: vec2f) -> vec3f {
    let d = square_to_disk_concentric(u);
    return vec3f(d, sqrt(max(1.0 - dot(d, d), 0.0)));
}

fn cosine_hemisphere_pdf(v: vec3f) -> f32 {
    return max(v.z, 0.0) * INV_PI;
}

fn square_to_uniform_sphere(u: vec2f) -> vec3f {
    let z = 1.0 - 2.0 * u.y;
    let r = sqrt(max(1.0 - z * z, 0.0));
    let phi = 2.0 * PI * u.x;
    return vec3f(r * cos(phi), r * sin(phi), z);
}

// Barycentrics (b1, b2) of a uniform point on a triangle.
fn square_to_uniform_triangle(u: vec2f) -> vec2f {
    let su = sqrt(u.x);
    return vec2f(1.0 - su, u.y * su);
}

// The stateless hash of `radiant_core::hash` (lowbias32 stages).
fn hash_u32(x0: u32) -> u32 {
    var x = x0;
    x ^= x >> 16u;
    x *= 0x21f0aaadu;
    x ^= x >> 15u;
    x *= 0xd35a2d97u;
    x ^= x >> 15u;
    return x;
}

fn hash4_first(a: u32) -> u32 {
    return hash_u32(a ^ 0x9e3779b9u);
}

fn hash4_middle(state: u32, b: u32, c: u32) -> u32 {
    return hash_u32(hash_u32(state ^ b) ^ (c * 0x85ebca6bu));
}

fn hash4_last(state: u32, d: u32) -> u32 {
    return hash_u32(state ^ (d * 0xc2b2ae35u));
}

fn unit_float(bits: u32) -> f32 {
    return f32(bits >> 8u) * (1.0 / 16777216.0);
}
