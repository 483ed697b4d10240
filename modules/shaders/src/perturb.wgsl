// A material shaded around a perturbed normal (perturb.rs `Perturbed`), a
// template made into WGSL per (normal source, nested type) by
// `Perturbed::gpu`: `$SELF` becomes this wrapper's identifier, `$M` the
// nested material's functions. Parameters: the offset of the nested
// material's parameters from these, flags (1: flip invalid normals, 2:
// shadowing), the normal source's parameters (at offset 2), then the
// nested material's.

// The perturbed normal at s (flipped where asked).
fn perturbed_frame_normal_$SELF(p: u32, s: ShadingPoint) -> vec3f {
    let n = perturbed_normal_$SELF(p + 2u, s);
    if (param_u32(p + 1u) & 1u) != 0u {
        return perturb_flip_invalid(n, s.wo);
    }
    return n;
}

fn bsdf_sample_$SELF(p: u32, s: ShadingPoint, u: vec3f) -> BsdfSample {
    let n = perturbed_frame_normal_$SELF(p, s);
    let f = perturb_frame_around(n);
    var r = bsdf_sample_$M(p + param_u32(p), perturb_seen(f, s), u);
    let wi = frame_to_world(f, r.wi);
    if wi.z * r.wi.z <= 0.0 || r.pdf <= 0.0 {
        return bsdf_sample_failed();
    }
    r.wi = wi;
    if (param_u32(p + 1u) & 2u) != 0u {
        r.weight *= perturb_shadowing(perturb_shadowing_alpha2(n), wi);
    }
    return r;
}

fn bsdf_eval_$SELF(p: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval {
    let n = perturbed_frame_normal_$SELF(p, s);
    let f = perturb_frame_around(n);
    let wi_p = frame_to_local(f, wi);
    var e = bsdf_eval_$M(p + param_u32(p), perturb_seen(f, s), wi_p);
    if wi.z * wi_p.z <= 0.0 {
        return bsdf_eval_zero();
    }
    if (param_u32(p + 1u) & 2u) != 0u {
        e.value *= perturb_shadowing(perturb_shadowing_alpha2(n), wi);
    }
    return e;
}
