// The `homogeneous` medium: parameters σa, σs, Le. Distances in closed
// form (core::medium's free_flight), transmittance by Beer–Lambert.

fn medium_flight_homogeneous(p: u32, o: vec3f, d: vec3f, t_max: f32, beta: vec3f, u: vec2f, rng: ptr<function, Stream>) -> MediumFlight {
    return free_flight(p, beta, u, t_max);
}

fn medium_transmittance_homogeneous(p: u32, o: vec3f, d: vec3f, t_max: f32, rng: ptr<function, Stream>) -> vec3f {
    return beer(medium_sigma_a(p) + medium_sigma_s(p), t_max);
}
