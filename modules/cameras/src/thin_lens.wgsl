// The `thin_lens` camera (thin_lens.rs): rays from a point of the aperture
// disk (the concentric map of `lens`) through the point of the focal plane
// that the pinhole ray of the film position reaches. Parameters: the pose
// (origin, x, y, z axes), the raster scale (2/resolution), tan(fov/2) per
// axis, the aperture radius, the focus distance.
fn camera_ray_thin_lens(p: u32, film: vec2f, lens: vec2f) -> CameraRay {
    let scale = vec2f(param_f32(p + 12u), param_f32(p + 13u));
    let tan_half = vec2f(param_f32(p + 14u), param_f32(p + 15u));
    let radius = param_f32(p + 16u);
    let focus_distance = param_f32(p + 17u);
    let ndc = vec2f(film.x * scale.x - 1.0, 1.0 - film.y * scale.y);
    let plane = vec2f(-ndc.x * tan_half.x, ndc.y * tan_half.y);
    let focus = vec3f(plane * focus_distance, focus_distance);
    let aperture = vec3f(square_to_disk_concentric(lens) * radius, 0.0);
    let x = param_vec3(p + 3u);
    let y = param_vec3(p + 6u);
    let z = param_vec3(p + 9u);
    let origin = x * aperture.x + y * aperture.y + param_vec3(p);
    let d = focus - aperture;
    return CameraRay(origin, normalize(x * d.x + y * d.y + z * d.z), 1.0);
}
