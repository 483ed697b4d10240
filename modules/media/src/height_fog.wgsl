// The `height_fog` medium: parameters σa, σs, Le, then the unit up axis,
// the reference height h0 and the scale height H (render space; ρ0 = 1).
// The density integral D(t) along a ray and its inverse in closed form
// (`medium/height.rs`, here in f32 with series near zero), so a free
// flight is the homogeneous one in D mapped back to t, and the
// transmittance is exact.

// The largest |exponent| of the density (height.rs MAX_EXPONENT).
const FOG_MAX_EXPONENT: f32 = 80.0;

// e^x − 1 without cancellation near 0.
fn fog_expm1(x: f32) -> f32 {
    if abs(x) < 1e-3 {
        return x * (1.0 + x * (0.5 + x / 6.0));
    }
    return exp(x) - 1.0;
}

// ln(1 + x) without cancellation near 0.
fn fog_ln1p(x: f32) -> f32 {
    if abs(x) < 1e-3 {
        return x * (1.0 - x * (0.5 - x / 3.0));
    }
    return log(1.0 + x);
}

fn fog_density(p: u32, x: vec3f) -> f32 {
    let h = dot(param_vec3(p + 9u), x);
    let e = clamp(-(h - param_f32(p + 12u)) / param_f32(p + 13u), -FOG_MAX_EXPONENT, FOG_MAX_EXPONENT);
    return exp(e);
}

// D(t) = ∫0^t ρ(o + s·d) ds.
fn fog_integral(p: u32, o: vec3f, d: vec3f, t: f32) -> f32 {
    let a = fog_density(p, o);
    if a == 0.0 || t <= 0.0 {
        return 0.0;
    }
    let k = dot(param_vec3(p + 9u), d);
    if k == 0.0 {
        return a * t;
    }
    let big_h = param_f32(p + 13u);
    let x = t * k / big_h;
    return a * big_h / k * -fog_expm1(-min(x, FOG_MAX_EXPONENT));
}

// The t with D(t) = depth, or FLOAT_MAX where the ray's integral stays
// below it.
fn fog_inverse(p: u32, o: vec3f, d: vec3f, depth: f32) -> f32 {
    let a = fog_density(p, o);
    if a == 0.0 {
        return FLOAT_MAX;
    }
    let k = dot(param_vec3(p + 9u), d);
    if k == 0.0 {
        return depth / a;
    }
    let big_h = param_f32(p + 13u);
    let y = depth * k / (a * big_h);
    if y >= 1.0 {
        return FLOAT_MAX;
    }
    return -big_h / k * fog_ln1p(-y);
}

fn medium_flight_height_fog(p: u32, o: vec3f, d: vec3f, t_max: f32, beta: vec3f, u: vec2f, rng: ptr<function, Stream>) -> MediumFlight {
    // A homogeneous flight in D: the density at the event cancels out of
    // σs·T/pdf.
    var f = free_flight(p, beta, u, fog_integral(p, o, d, t_max));
    if f.scattered {
        f.t = min(fog_inverse(p, o, d, f.t), t_max);
    } else {
        f.t = t_max;
    }
    return f;
}

fn medium_transmittance_height_fog(p: u32, o: vec3f, d: vec3f, t_max: f32, rng: ptr<function, Stream>) -> vec3f {
    return beer(medium_sigma_a(p) + medium_sigma_s(p), fog_integral(p, o, d, t_max));
}
