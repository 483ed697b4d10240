// What `ward` and `ashikhmin_shirley` share, as half_vector.rs: the
// glossy lobe's sampling probability from the albedos.

// In proportion to the luminances (even when both are black).
fn half_vector_specular_probability(diffuse: vec3f, specular: vec3f) -> f32 {
    let s = rgb_luminance(specular);
    let d = rgb_luminance(diffuse);
    if s + d > 0.0 {
        return s / (s + d);
    }
    return 0.5;
}
