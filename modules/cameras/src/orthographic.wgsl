// The `orthographic` camera (orthographic.rs): parallel rays from the
// camera-space plane z = 0. Parameters: the pose (origin, x, y, z axes),
// the raster scale (2/resolution), half the window's extent per axis, the
// rays' direction (the pose's +z, normalised).
fn camera_ray_orthographic(p: u32, film: vec2f, lens: vec2f) -> CameraRay {
    let scale = vec2f(param_f32(p + 12u), param_f32(p + 13u));
    let half = vec2f(param_f32(p + 14u), param_f32(p + 15u));
    let ndc = vec2f(film.x * scale.x - 1.0, 1.0 - film.y * scale.y);
    // Camera space +x is left, NDC +x is right.
    let local = vec2f(-ndc.x * half.x, ndc.y * half.y);
    let origin = param_vec3(p + 3u) * local.x + param_vec3(p + 6u) * local.y + param_vec3(p);
    return CameraRay(origin, param_vec3(p + 16u), 1.0);
}
