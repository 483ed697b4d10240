// The `spherical` camera (spherical.rs): longitude along the film's x,
// latitude along its y, from the pose's origin. Parameters: the pose
// (origin, x, y, z axes), the film resolution (2).
fn camera_ray_spherical(p: u32, film: vec2f, lens: vec2f) -> CameraRay {
    let resolution = vec2f(param_f32(p + 12u), param_f32(p + 13u));
    let phi = (film.x / resolution.x - 0.5) * (2.0 * PI);
    let lambda = (0.5 - film.y / resolution.y) * PI;
    let d = vec3f(-cos(lambda) * sin(phi), sin(lambda), cos(lambda) * cos(phi));
    let dir = param_vec3(p + 3u) * d.x + param_vec3(p + 6u) * d.y + param_vec3(p + 9u) * d.z;
    return CameraRay(param_vec3(p), normalize(dir), 1.0);
}
