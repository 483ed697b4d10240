// What `normal_map` and `bump` share on the GPU (perturb.rs): the flip of
// invalid normals, the frame around a perturbed normal and the microfacet
// shadowing term.

// `perturb::sanitise`: unit normal, +z for a degenerate one or one below
// the surface.
fn perturb_sanitise(n: vec3f) -> vec3f {
    let u = try_normalize(n);
    if u.z > 1e-3 {
        return u;
    }
    return vec3f(0.0, 0.0, 1.0);
}

// `perturb::flip_invalid`: n mirrored about the shading normal where the
// viewer wo is below it.
fn perturb_flip_invalid(n: vec3f, wo: vec3f) -> vec3f {
    if wo.z * dot(wo, n) <= 0.0 {
        return vec3f(-n.x, -n.y, n.z);
    }
    return n;
}

// `perturb::frame_around`: the frame around n whose tangent is the local
// x axis made orthogonal to it.
fn perturb_frame_around(n: vec3f) -> mat3x3f {
    let f = frame_with_tangent(n, vec3f(1.0, 0.0, 0.0));
    if frame_usable(f) {
        return f;
    }
    return frame_from_normal(n);
}

fn perturb_tan2_theta(v: vec3f) -> f32 {
    let cos2 = v.z * v.z;
    return max(1.0 - cos2, 0.0) / cos2;
}

// `perturb::shadowing_alpha2`.
fn perturb_shadowing_alpha2(n: vec3f) -> f32 {
    return min(0.125 * perturb_tan2_theta(n), 1.0);
}

// `perturb::shadowing`: Conty Estevez et al. 2019's term for the light
// direction wi.
fn perturb_shadowing(alpha2: f32, wi: vec3f) -> f32 {
    if alpha2 <= 0.0 {
        return 1.0;
    }
    return 2.0 / (1.0 + sqrt(1.0 + alpha2 * perturb_tan2_theta(wi)));
}

// The point s as seen in frame f.
fn perturb_seen(f: mat3x3f, s: ShadingPoint) -> ShadingPoint {
    return ShadingPoint(frame_to_local(f, s.wo), s.uv, frame_to_local(f, s.dp_du), frame_to_local(f, s.dp_dv));
}
