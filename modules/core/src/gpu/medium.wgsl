// Participating media on the GPU: the maths of `radiant_core::medium` that
// every medium type and the backend's medium stage share. Included once
// in a kernel whose scene has media or `null` boundaries.
//
// A medium type `T` defines
//   fn medium_flight_T(p: u32, o: vec3f, d: vec3f, t_max: f32, beta: vec3f,
//                      u: vec2f, rng: ptr<function, Stream>) -> MediumFlight
//   fn medium_transmittance_T(p: u32, o: vec3f, d: vec3f, t_max: f32,
//                             rng: ptr<function, Stream>) -> vec3f
// along the ray o + t·d (d a unit vector, t up to t_max; FLOAT_MAX where
// the ray leaves the scene), with its coefficients σa, σs, Le (where its
// density is 1) as its first nine parameter words. A phase type `T`
// defines phase_sample_T(p, wo, u: vec2f) -> BsdfSample and
// phase_eval_T(p, wo, wi) -> BsdfEval, as the `Phase` trait does.

// A path's next interaction in a medium (`Tracked`): where, whether it
// scatters there, the path's new throughput (σs included at an event,
// zero where absorbed) and the emission gathered on the way (already
// times the throughput).
struct MediumFlight {
    t: f32,
    scattered: bool,
    beta: vec3f,
    emitted: vec3f,
}

// `medium::Stream`: uniform numbers from a hashed key and a counter, for
// the walks whose count of numbers is unbounded.
struct Stream {
    key: u32,
    counter: u32,
}

fn stream_new(a: u32, b: u32, c: u32, d: u32) -> Stream {
    return Stream(hash4_last(hash4_middle(hash4_first(a), b, c), d), 0u);
}

fn stream_next(s: ptr<function, Stream>) -> f32 {
    (*s).counter += 1u;
    return unit_float(hash4_last(hash4_middle(hash4_first((*s).key), (*s).counter, 0x6d656469u), 0x756du));
}

fn medium_sigma_a(p: u32) -> vec3f {
    return param_vec3(p);
}

fn medium_sigma_s(p: u32) -> vec3f {
    return param_vec3(p + 3u);
}

fn medium_emission(p: u32) -> vec3f {
    return param_vec3(p + 6u);
}

// Beer–Lambert per channel; 1 where σt = 0 (at any distance).
fn beer(sigma_t: vec3f, d: f32) -> vec3f {
    return select(exp(-sigma_t * d), vec3f(1.0), sigma_t == vec3f(0.0));
}

fn channel_average(c: vec3f) -> f32 {
    return (c.x + c.y + c.z) / 3.0;
}

// `medium::free_flight` over a segment of optical length `t_max` of a
// homogeneous medium, turned into the flight's weights as
// `integrators/medium.rs` applies them (σs·T/pdf and the emission at an
// event, T/P(pass) where the ray passes). The hero channel comes from
// u.x; the density is the average of the three channels' (one-sample MIS).
fn free_flight(p: u32, beta: vec3f, u: vec2f, t_max: f32) -> MediumFlight {
    let sigma_a = medium_sigma_a(p);
    let sigma_s = medium_sigma_s(p);
    let sigma_t = sigma_a + sigma_s;
    let s = sigma_t[min(u32(u.x * 3.0), 2u)];
    var t = FLOAT_MAX;
    if s > 0.0 {
        // 1 − u in (0, 1]: the logarithm is finite.
        t = -log(1.0 - u.y) / s;
    }
    if t < t_max {
        let tr = beer(sigma_t, t);
        let pdf = channel_average(sigma_t * tr);
        let w = select(vec3f(0.0), tr / pdf, pdf > 0.0);
        return MediumFlight(t, true, beta * w * sigma_s, beta * w * sigma_a * medium_emission(p));
    }
    let tr = beer(sigma_t, t_max);
    let through = channel_average(tr);
    let w = select(vec3f(0.0), tr / through, through > 0.0);
    return MediumFlight(t_max, false, beta * w, vec3f(0.0));
}
