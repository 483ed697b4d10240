// The `spot` light (spot.rs): intensity × falloff / distance² towards the
// reference point, Mitsuba 3's linear falloff in angle. Parameters:
// position (3), unit axis (3), intensity (3), cutoff and beam half-angles
// (radians), their cosines.

// acos as precise as atan2 (some GPUs' acos is off by 1e-4), for x in
// [−1, 1].
fn spot_acos(x: f32) -> f32 {
    return atan2(sqrt(max((1.0 - x) * (1.0 + x), 0.0)), x);
}

fn spot_falloff(p: u32, cos_theta: f32) -> f32 {
    if cos_theta <= param_f32(p + 11u) {
        return 0.0;
    }
    if cos_theta >= param_f32(p + 12u) {
        return 1.0;
    }
    let cutoff = param_f32(p + 9u);
    let beam = param_f32(p + 10u);
    return clamp((cutoff - spot_acos(clamp(cos_theta, -1.0, 1.0))) / (cutoff - beam), 0.0, 1.0);
}

fn light_sample_spot(p: u32, r: vec3f, u: vec2f) -> LightSample {
    let position = param_vec3(p);
    let d = r - position;
    let dist2 = dot(d, d);
    var radiance = vec3f(0.0);
    if dist2 > 0.0 {
        let falloff = spot_falloff(p, dot(param_vec3(p + 3u), d) / sqrt(dist2));
        radiance = param_vec3(p + 6u) * (falloff / dist2);
    }
    return LightSample(position, vec3f(0.0), radiance, 1.0);
}
