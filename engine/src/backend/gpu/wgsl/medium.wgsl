// The path integrator with participating media and `null` boundaries
// (integrators/medium.rs), in the megakernel: only kernels whose frame
// has media or `null` boundaries include it (feature MEDIA), and its
// trace_path replaces path.wgsl's.
//
// Per segment, a path in a medium samples a distance before its hit
// (medium_flight: closed forms, or delta tracking for grids, with the
// bounce's two extra sampler dimensions: hero channel and distance).
// Paths that scatter become medium events: an interaction along the ray
// whose material is MEDIUM_EVENT + medium, which the generated
// dispatchers send to the medium's phase function (media.rs), so
// next-event estimation and the continuation are path.wgsl's, MIS
// between phase and light sampling included. Shadow rays return a
// transmittance through media and `null` boundaries. A `null` crossing is
// not a vertex: max_depth and roulette count `vertices`, the real ones,
// and emitter hits are weighted by MIS from the last real vertex.

const NO_MEDIUM: u32 = 0xffffffffu;
// Materials from here on are medium events, one per medium.
const MEDIUM_EVENT: u32 = 0x80000000u;
// `null` boundaries a path or a shadow ray may cross (MAX_CROSSINGS).
const MAX_CROSSINGS: u32 = 256u;

// Real scattering vertices of the current path so far (surfaces other
// than `null`, medium events).
var<private> vertices: u32 = 0u;

fn media_table(i: u32) -> u32 {
    return param_u32(param_u32(H_MEDIA) + i);
}

fn is_null(material: u32) -> bool {
    return (media_table(4u + 4u * material) & 2u) != 0u;
}

// The medium a ray enters leaving a surface of `material` (MediaTable::
// after_crossing): the side of the geometric normal it heads to where the
// material bounds media, else the medium it was in.
fn after_crossing(material: u32, current: u32, d_dot_ng: f32) -> u32 {
    let at = 4u + 4u * material;
    if (media_table(at) & 1u) == 0u {
        return current;
    }
    return select(media_table(at + 1u), media_table(at + 2u), d_dot_ng > 0.0);
}

// A scattering event at p in `medium` on a ray of unit direction d: its
// normal and frame lie along the ray, so every side test passes and the
// continuation starts exactly at p.
fn event_interaction(p: vec3f, d: vec3f, medium: u32) -> Interaction {
    let f = frame_from_normal(d);
    return Interaction(p, vec3f(0.0), d, f, vec2f(0.0), f[0], f[1], MEDIUM_EVENT + medium, NO_EMITTER, 0u);
}

// The transmittance of the shadow segment origin + t·dir, t in
// (0, 1 − SHADOW_EPSILON), starting in `medium`: the media's between
// `null` boundaries, zero where anything else blocks it.
fn shadow_transmittance(start: vec3f, dir: vec3f, medium_at_start: u32, key: u32) -> vec3f {
    let end = start + dir * (1.0 - SHADOW_EPSILON);
    // Ratio tracking's numbers, keyed by the ray.
    var rng = stream_new(bitcast<u32>(start.x), bitcast<u32>(start.y), bitcast<u32>(start.z), bitcast<u32>(end.x) ^ key);
    var origin = start;
    var medium = medium_at_start;
    var tr = vec3f(1.0);
    for (var i = 0u; i < MAX_CROSSINGS; i++) {
        let d = end - origin;
        let hit = closest_hit_before(origin, d, 1.0);
        let blocked = hit.slot != NO_HIT;
        if medium != NO_MEDIUM {
            let len = length(d);
            tr *= medium_transmittance(medium, origin, d / len, select(1.0, hit.t, blocked) * len, &rng);
            if max(tr.x, max(tr.y, tr.z)) <= 0.0 {
                return vec3f(0.0);
            }
        }
        if !blocked {
            return tr;
        }
        let it = interaction(hit, origin, d);
        if !is_null(it.material) {
            return vec3f(0.0);
        }
        medium = after_crossing(it.material, medium, dot(d, it.ng));
        origin = offset_origin(it.p, it.err, it.ng, d);
    }
    return vec3f(0.0);
}

// Radiance of one camera path through media, and its filter weight in w;
// adds the rays it traced to `rays` and `shadow_rays`.
fn trace_path(px: u32, py: u32, index: u32, rays: ptr<function, u32>, shadow_rays: ptr<function, u32>) -> vec4f {
    let pixel = py * frame.width + px;
    var path: PathState;
    let filter_weight = start_path(px, py, index, &path);
    var medium = media_table(0u);
    // The last vertex that was not a `null` crossing, and the direction
    // density sampled there (0: a delta lobe).
    var scatter_origin = path.o;
    var scatter_pdf = 0.0;
    var crossings = 0u;
    vertices = 0u;
    loop {
        *rays += 1u;
        let hit = closest_hit(path.o, path.d);
        var it: Interaction;
        var event = false;
        if medium != NO_MEDIUM {
            let dim = CAMERA_DIMS + path.depth * BOUNCE_DIMS + 8u;
            let u = vec2f(sample_1d(pixel, index, dim), sample_1d(pixel, index, dim + 1u));
            let len = length(path.d);
            let d = path.d / len;
            let t_max = select(hit.t * len, FLOAT_MAX, hit.slot == NO_HIT);
            var rng = stream_new(pixel, index, dim, bitcast<u32>(u.y));
            let f = medium_flight(medium, path.o, d, t_max, path.beta, u, &rng);
            path.radiance += f.emitted;
            path.beta = f.beta;
            if max(f.beta.x, max(f.beta.y, f.beta.z)) <= 0.0 {
                // Absorbed (or a zero weight): the path ends here.
                break;
            }
            if f.scattered {
                event = true;
                it = event_interaction(path.o + d * f.t, d, medium);
            }
        }
        if !event {
            if hit.slot == NO_HIT {
                add_escaped(&path);
                break;
            }
            it = interaction(hit, path.o, path.d);
            // Emitter hits are weighted from the last real vertex.
            var seen = path;
            seen.o = scatter_origin;
            add_emitted(&seen, it);
            path.radiance = seen.radiance;
        }
        let crossing = !event && is_null(it.material);
        if crossing {
            if crossings >= MAX_CROSSINGS {
                break;
            }
        } else if vertices + 1u >= MAX_DEPTH {
            break;
        }
        let sp = shading_point(it, path.d);
//#if LIGHTS
        let c = connect_light(pixel, index, path, it, sp);
        if any(c.value != vec3f(0.0)) {
            *shadow_rays += 1u;
            var start = medium;
            if !event {
                start = after_crossing(it.material, medium, dot(c.dir, it.ng));
            }
            path.radiance += c.value * shadow_transmittance(c.origin, c.dir, start, index);
        }
//#endif
        if !scatter(pixel, index, &path, it, sp) {
            break;
        }
        if !event {
            medium = after_crossing(it.material, medium, dot(path.d, it.ng));
            if crossing {
                path.prev_pdf = scatter_pdf;
                crossings += 1u;
                continue;
            }
        }
        vertices += 1u;
        scatter_origin = it.p;
        scatter_pdf = path.prev_pdf;
    }
    return vec4f(path.radiance, filter_weight);
}
