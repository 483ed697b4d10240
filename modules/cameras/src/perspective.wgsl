// The `perspective` camera (perspective.rs). Parameters: the pose origin
// in render space, the pose's x, y, z axes, the raster scale (2/resolution)
// and tan(fov/2) per axis.
fn camera_ray_perspective(p: u32, film: vec2f, lens: vec2f) -> CameraRay {
    let scale = vec2f(param_f32(p + 12u), param_f32(p + 13u));
    let tan_half = vec2f(param_f32(p + 14u), param_f32(p + 15u));
    let ndc = vec2f(film.x * scale.x - 1.0, 1.0 - film.y * scale.y);
    let d = vec3f(-ndc.x * tan_half.x, ndc.y * tan_half.y, 1.0);
    let dir = param_vec3(p + 3u) * d.x + param_vec3(p + 6u) * d.y + param_vec3(p + 9u) * d.z;
    return CameraRay(param_vec3(p), normalize(dir), 1.0);
}
