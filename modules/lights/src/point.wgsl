// The `point` light (point.rs). Parameters: position, intensity.
fn light_sample_point(p: u32, r: vec3f, u: vec2f) -> LightSample {
    let position = param_vec3(p);
    let d = position - r;
    let dist2 = dot(d, d);
    var radiance = vec3f(0.0);
    if dist2 > 0.0 {
        radiance = param_vec3(p + 3u) / dist2;
    }
    return LightSample(position, vec3f(0.0), radiance, 1.0);
}
