// The `directional` light (directional.rs): the sample point lies upstream
// of the reference point, outside the scene. Parameters: the offset from
// a reference point to its sample point (−direction × 2 × scene radius),
// irradiance (3).

fn light_sample_directional(p: u32, r: vec3f, u: vec2f) -> LightSample {
    return LightSample(r + param_vec3(p), vec3f(0.0), param_vec3(p + 3u), 1.0);
}
