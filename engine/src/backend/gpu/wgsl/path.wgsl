// The `path` integrator as a megakernel: one invocation renders the
// samples of one pixel, path by path, with the estimator and sampler
// dimensions of integrators/path.rs (next-event estimation with MIS by the
// power heuristic, lights chosen by light_selection.wgsl, Russian roulette
// on throughput without the 1/η² of refraction), and adds Σ w·L and Σ w
// to its pixel (filter importance sampling: w = f/pdf).

// What one dispatch renders: samples [first_sample, first_sample +
// samples) of rows [pixel_offset, pixel_offset + rows); the gather that
// follows it (filter splatting) starts at row gather_offset. The
// wavefront (wavefront.wgsl) renders in a pool of `pool` path slots.
struct FrameUniform {
    width: u32,
    height: u32,
    first_sample: u32,
    samples: u32,
    pixel_offset: u32,
    rows: u32,
    gather_offset: u32,
    pool: u32,
}


@group(0) @binding(0) var<uniform> frame: FrameUniform;
@group(0) @binding(1) var<storage, read> module_params: array<u32>;
@group(0) @binding(2) var<storage, read> nodes: array<vec4f>;
@group(0) @binding(3) var<storage, read> prims: array<vec4f>;
@group(0) @binding(4) var<storage, read> shading: array<vec4f>;
@group(0) @binding(5) var<storage, read> instances: array<vec4f>;
@group(0) @binding(6) var<storage, read_write> film: array<vec4f>;
@group(0) @binding(7) var<storage, read_write> counters: array<atomic<u32>>;
//#if SPLAT
// Each path's radiance and its position in its pixel (two unorm16 in w),
// per layer, for the gather pass.
@group(0) @binding(8) var<storage, read_write> splats: array<vec4f>;
//#endif

// Longest path in segments (16384 for unlimited), and the depth from
// which Russian roulette applies.
override MAX_DEPTH: u32 = 8u;
override RR_DEPTH: u32 = 5u;

// Sampler dimensions of the camera (film position, lens; under MOTION one
// more, the path's time in the shutter) and of each bounce (under MEDIA
// two more: the hero channel and the distance, medium.wgsl).
//#if MOTION
const CAMERA_DIMS: u32 = 5u;
//#else
const CAMERA_DIMS: u32 = 4u;
//#endif
//#if MEDIA
const BOUNCE_DIMS: u32 = 10u;
//#else
const BOUNCE_DIMS: u32 = 8u;
//#endif
const SHADOW_EPSILON: f32 = 1e-4;
const NO_EMITTER: u32 = 0xffffffffu;

// An offset from the pixel centre drawn from the tabulated filter
// (rows: marginal CDF; then per row its CDF; then the signs), and its
// weight f/pdf.
fn filter_cdf(i: u32) -> f32 {
    return param_f32(param_u32(H_FILTER) + i);
}

// Index of the first entry of cdf[at .. at + n] above u (n ≥ 1).
fn find_interval(at: u32, n: u32, u: f32) -> u32 {
    var lo = 0u;
    var hi = n - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if filter_cdf(at + mid) <= u {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

fn filter_sample(u: vec2f) -> vec3f {
    let res = param_u32(H_FILTER_RES);
    let row = find_interval(0u, res, u.y);
    let row_lo = select(0.0, filter_cdf(row - 1u), row > 0u);
    let row_hi = filter_cdf(row);
    let fy = clamp((u.y - row_lo) / max(row_hi - row_lo, 1e-30), 0.0, 1.0);
    let at = res + row * res;
    let col = find_interval(at, res, u.x);
    let col_lo = select(0.0, filter_cdf(at + col - 1u), col > 0u);
    let col_hi = filter_cdf(at + col);
    let fx = clamp((u.x - col_lo) / max(col_hi - col_lo, 1e-30), 0.0, 1.0);
    let cell = vec2f(f32(col) + fx, f32(row) + fy) / f32(res);
    let offset = (2.0 * cell - vec2f(1.0)) * param_f32(H_FILTER_RADIUS);
    let sgn = filter_cdf(res + res * res + row * res + col);
    return vec3f(offset, param_f32(H_FILTER_INTEGRAL) * sgn);
}

fn power_heuristic(a: f32, b: f32) -> f32 {
    let a2 = a * a;
    let b2 = b * b;
    return select(0.0, a2 / (a2 + b2), a2 + b2 > 0.0);
}

fn bsdf_hit_weight(depth: u32, bsdf_pdf: f32, light_pdf: f32) -> f32 {
    if depth == 0u || bsdf_pdf == 0.0 {
        return 1.0;
    }
    return power_heuristic(bsdf_pdf, light_pdf);
}

fn light_word(l: u32, i: u32) -> u32 {
    return param_u32(param_u32(H_LIGHTS) + 4u * l + i);
}

// (light, probability) for the uniform sample u, as LightTable::select.
fn select_light(u: f32) -> vec2f {
    let n = param_u32(H_LIGHT_COUNT);
    var lo = 0u;
    var hi = n - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if param_f32(param_u32(H_LIGHT_CDF) + mid) <= u {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return vec2f(f32(lo), bitcast<f32>(light_word(lo, 3u)));
}

//#if ENVIRONMENT
// Radiance of the lights at infinity along the escaped direction `dir`,
// MIS-weighted against light sampling (integrators/path.rs add_escaped).
fn escaped_radiance(origin: vec3f, dir: vec3f, depth: u32, prev_pdf: f32) -> vec3f {
    var sum = vec3f(0.0);
    let n = param_u32(H_ENVIRONMENT_COUNT);
    for (var k = 0u; k < n; k++) {
        let l = param_u32(param_u32(H_ENVIRONMENT) + k);
        let e = light_escaped(l, dir);
        let pmf = light_pmf_at(origin, l);
        sum += e.radiance * bsdf_hit_weight(depth, prev_pdf, pmf * e.pdf);
    }
    return sum;
}
//#endif

fn sampled_point_error(p: vec3f) -> vec3f {
    return abs(p) * GAMMA7;
}

// A camera path between two segments: its ray, throughput, the radiance
// it has gathered, and what MIS and roulette need of its last bounce.
struct PathState {
    o: vec3f,
    d: vec3f,
    beta: vec3f,
    eta_scale: f32,
    radiance: vec3f,
    prev_pdf: f32,
    depth: u32,
}

// Starts sample `index` of pixel (px, py) at its camera ray (under MOTION
// also sets ray_time, the path's time in the shutter); returns its filter
// weight (splatting: its position in the pixel, packed).
fn start_path(px: u32, py: u32, index: u32, path: ptr<function, PathState>) -> f32 {
    let pixel = py * frame.width + px;
//#if SPLAT
    // Uniform in the pixel; the gather pass weights it by the filter.
    let in_pixel = sample_2d(pixel, index, 0u);
    let film_pos = vec2f(f32(px), f32(py)) + in_pixel;
    let fs = vec3f(0.0, 0.0, bitcast<f32>(pack2x16unorm(in_pixel)));
//#else
    let fs = filter_sample(sample_2d(pixel, index, 0u));
    let film_pos = vec2f(f32(px), f32(py)) + vec2f(0.5) + fs.xy;
//#endif
    let ray = camera_ray(film_pos, sample_2d(pixel, index, 2u));
    var o = ray.origin;
    var d = ray.dir;
//#if MOTION
    // Each path lives at one time of the shutter (a box shutter); the
    // camera ray moves to where the camera is then (path.rs).
    ray_time = sample_1d(pixel, index, 4u);
    let camera_motion = param_u32(H_CAMERA_MOTION);
    if camera_motion != NO_HIT {
        let m = motion_affine(camera_motion, ray_time);
        o = affine_point(m, o);
        d = normalize(m.l * d);
    }
//#endif
    *path = PathState(o, d, vec3f(ray.weight), 1.0, vec3f(0.0), 0.0, 0u);
    return fs.z;
}

// Adds what the path's ray sees where it leaves the scene.
fn add_escaped(path: ptr<function, PathState>) {
//#if ENVIRONMENT
    (*path).radiance += (*path).beta * escaped_radiance((*path).o, normalize((*path).d), (*path).depth, (*path).prev_pdf);
//#endif
}

// Adds the emission at the path's hit `it`, MIS-weighted against light
// sampling.
fn add_emitted(path: ptr<function, PathState>, it: Interaction) {
//#if AREA_LIGHTS
    if it.emitter != NO_EMITTER {
        let e = light_hit(it.emitter, EmitterHit((*path).o, it.p, it.ng, it.emitter_prim));
        let pmf = light_pmf_at((*path).o, it.emitter);
        (*path).radiance += (*path).beta * e.radiance * bsdf_hit_weight((*path).depth, (*path).prev_pdf, pmf * e.pdf);
    }
//#endif
}

// The shading point of the hit `it` seen along d, in its local frame.
fn shading_point(it: Interaction, d: vec3f) -> ShadingPoint {
    return ShadingPoint(frame_to_local(it.frame, -d), it.uv, frame_to_local(it.frame, it.dp_du), frame_to_local(it.frame, it.dp_dv));
}

//#if LIGHTS
// The shadow ray of next-event estimation: the segment origin + t·dir,
// t in (0, 1 − SHADOW_EPSILON), and what it adds where unoccluded (zero:
// no shadow ray).
struct LightConnection {
    origin: vec3f,
    dir: vec3f,
    value: vec3f,
}

// Next-event estimation at the path's hit `it`: a light (choose_light), a
// point on it, and the shadow ray towards it.
fn connect_light(pixel: u32, index: u32, path: PathState, it: Interaction, sp: ShadingPoint) -> LightConnection {
    let base = CAMERA_DIMS + path.depth * BOUNCE_DIMS;
    let none = LightConnection(vec3f(0.0), vec3f(0.0), vec3f(0.0));
    var light = 0u;
    var light_prob = 1.0;
    if param_u32(H_LIGHT_COUNT) > 1u {
        let choice = choose_light(it.p, sample_1d(pixel, index, base));
        light = u32(choice.x);
        light_prob = choice.y;
    }
    let ls = light_sample(light, it.p, sample_2d(pixel, index, base + 1u));
    let to_light = ls.p - it.p;
    let to_light_len = length(to_light);
    var wi_world = vec3f(0.0);
    if to_light_len > 0.0 {
        wi_world = to_light / to_light_len;
    }
    let wi_local = frame_to_local(it.frame, wi_world);
    if !(ls.pdf > 0.0 && material_has_smooth_lobes(it.material)
        && dot(wi_world, it.ng) * wi_local.z > 0.0) {
        return none;
    }
    let e = bsdf_eval(it.material, sp, wi_local);
    if all(e.value == vec3f(0.0)) {
        return none;
    }
    let light_pdf = light_prob * ls.pdf;
    var weight = light_pdf / (light_pdf * light_pdf + e.pdf * e.pdf);
    if light_word(light, 2u) != 0u {
        weight = 1.0 / light_pdf;
    }
    let value = path.beta * e.value * ls.radiance * weight;
    if all(value == vec3f(0.0)) || !is_finite_vec3(value) {
        return none;
    }
    let origin = offset_origin(it.p, it.err, it.ng, wi_world);
    var target_point = ls.p;
    if any(ls.n != vec3f(0.0)) {
        target_point = offset_origin(ls.p, sampled_point_error(ls.p), ls.n, -wi_world);
    }
    return LightConnection(origin, target_point - origin, value);
}
//#endif

// Continues the path from its hit `it` by sampling the BSDF, with Russian
// roulette; false where the path ends there.
fn scatter(pixel: u32, index: u32, path: ptr<function, PathState>, it: Interaction, sp: ShadingPoint) -> bool {
    let base = CAMERA_DIMS + (*path).depth * BOUNCE_DIMS;
    let u1 = sample_1d(pixel, index, base + 3u);
    let bs = bsdf_sample(it.material, sp, vec3f(u1, sample_2d(pixel, index, base + 4u)));
    if bs.pdf <= 0.0 || all(bs.weight == vec3f(0.0)) {
        return false;
    }
    let wi = frame_to_world(it.frame, bs.wi);
    if dot(wi, it.ng) * bs.wi.z <= 0.0 {
        return false;
    }
    var beta = (*path).beta * bs.weight;
    let beta_max = max(beta.x, max(beta.y, beta.z));
    if beta_max <= 0.0 || !is_finite_vec3(beta) {
        return false;
    }
    let eta_scale = (*path).eta_scale * bs.eta * bs.eta;
    let survival = beta_max * eta_scale;
//#if MEDIA
    // Roulette counts real vertices, not `null` crossings.
    let depth = vertices;
//#else
    let depth = (*path).depth;
//#endif
    if depth + 1u >= RR_DEPTH && survival < 1.0 {
        if sample_1d(pixel, index, base + 6u) >= survival {
            return false;
        }
        beta /= survival;
    }
    (*path).beta = beta;
    (*path).eta_scale = eta_scale;
    (*path).prev_pdf = select(bs.pdf, 0.0, bs.delta);
    (*path).o = offset_origin(it.p, it.err, it.ng, wi);
    (*path).d = wi;
    (*path).depth++;
    return true;
}

//#if MEDIA
// (trace_path with media and `null` boundaries is medium.wgsl's.)
//#else
// Radiance of one camera path, and its filter weight in w (splatting: its
// position in the pixel, packed); adds the rays
// it traced to `rays` (camera and continuation) and `shadow_rays`.
fn trace_path(px: u32, py: u32, index: u32, rays: ptr<function, u32>, shadow_rays: ptr<function, u32>) -> vec4f {
    let pixel = py * frame.width + px;
    var path: PathState;
    let filter_weight = start_path(px, py, index, &path);
    loop {
        *rays += 1u;
        let hit = closest_hit(path.o, path.d);
        if hit.slot == NO_HIT {
            add_escaped(&path);
            break;
        }
        let it = interaction(hit, path.o, path.d);
        add_emitted(&path, it);
        if path.depth + 1u >= MAX_DEPTH {
            break;
        }
        let sp = shading_point(it, path.d);
//#if LIGHTS
        let c = connect_light(pixel, index, path, it, sp);
        if any(c.value != vec3f(0.0)) {
            *shadow_rays += 1u;
            if !occluded(c.origin, c.dir, 1.0 - SHADOW_EPSILON) {
                path.radiance += c.value;
            }
        }
//#endif
        if !scatter(pixel, index, &path, it, sp) {
            break;
        }
    }
    return vec4f(path.radiance, filter_weight);
}
//#endif

// Adds one path's radiance r.xyz with filter weight r.w to film entry
// `at` (or stores it in splat entry `at` for the gather pass); false
// where the radiance is NaN or infinite (recorded as black).
fn record_sample(at: u32, r: vec4f) -> bool {
    let finite = is_finite_vec3(r.xyz);
//#if SPLAT
    splats[at] = vec4f(select(vec3f(0.0), r.xyz, finite), r.w);
//#else
    if finite {
        film[at] += vec4f(r.xyz * r.w, r.w);
    } else {
        film[at].w += r.w;
    }
//#endif
    return finite;
}

// Counts of the workgroup, added to the counters once: invalid samples,
// camera and continuation rays, shadow rays (and with STATS, nodes
// visited and primitives tested).
var<workgroup> group_invalid: atomic<u32>;
var<workgroup> group_rays: atomic<u32>;
var<workgroup> group_shadow: atomic<u32>;
//#if STATS
var<workgroup> group_nodes: atomic<u32>;
var<workgroup> group_prims: atomic<u32>;
//#endif

// One invocation traces one path: pixel (x, y + pixel_offset), sample
// first_sample + z, added to film layer z (each invocation of a dispatch
// owns its film entry, so no atomics; the host sums the layers).
@compute @workgroup_size(8, 8, 1)
fn render(@builtin(global_invocation_id) gid: vec3u, @builtin(local_invocation_index) local: u32) {
    let px = gid.x;
    let py = gid.y + frame.pixel_offset;
    let in_frame = px < frame.width && py < frame.height && gid.z < frame.samples;
    var rays = 0u;
    var shadow_rays = 0u;
    if in_frame {
        let r = trace_path(px, py, frame.first_sample + gid.z, &rays, &shadow_rays);
        let at = (gid.z * frame.height + py) * frame.width + px;
        if !record_sample(at, r) {
            atomicAdd(&group_invalid, 1u);
        }
        atomicAdd(&group_rays, rays);
        atomicAdd(&group_shadow, shadow_rays);
//#if STATS
        atomicAdd(&group_nodes, stat_nodes);
        atomicAdd(&group_prims, stat_prims);
//#endif
    }
    workgroupBarrier();
    if local == 0u {
        atomicAdd(&counters[0], atomicLoad(&group_invalid));
        atomicAdd(&counters[1], atomicLoad(&group_rays));
        atomicAdd(&counters[2], atomicLoad(&group_shadow));
//#if STATS
        atomicAdd(&counters[3], atomicLoad(&group_nodes));
        atomicAdd(&counters[4], atomicLoad(&group_prims));
//#endif
    }
}

//#if SPLAT
// The filter's weight at offset d from a pixel centre (the CPU's
// FilterTable: a 64×64 table over the quadrant [0, r]²).
fn splat_weight(d: vec2f) -> f32 {
    let cell = abs(d) * param_f32(H_SPLAT_SCALE);
    if cell.x >= 64.0 || cell.y >= 64.0 {
        return 0.0;
    }
    let c = vec2u(cell);
    return param_f32(param_u32(H_SPLAT) + c.y * 64u + c.x);
}

// The gather pass of filter splatting: each invocation owns one pixel and
// adds the dispatch's samples from the pixels in the filter's reach (rows
// of the dispatch's band only), weighted by the filter, to it.
@compute @workgroup_size(8, 8, 1)
fn gather(@builtin(global_invocation_id) gid: vec3u) {
    let x = i32(gid.x);
    let y = i32(gid.y + frame.gather_offset);
    let w = i32(frame.width);
    let h = i32(frame.height);
    if x >= w || y >= h {
        return;
    }
    let reach = i32(param_u32(H_SPLAT_REACH));
    let y0 = max(y - reach, i32(frame.pixel_offset));
    let y1 = min(y + reach, i32(frame.pixel_offset + frame.rows) - 1);
    let x0 = max(x - reach, 0);
    let x1 = min(x + reach, w - 1);
    let centre = vec2f(f32(x), f32(y)) + vec2f(0.5);
    var sum = vec4f(0.0);
    for (var z = 0u; z < frame.samples; z++) {
        for (var sy = y0; sy <= y1; sy++) {
            let row = (i32(z) * h + sy) * w;
            for (var sx = x0; sx <= x1; sx++) {
                let s = splats[row + sx];
                let p = vec2f(f32(sx), f32(sy)) + unpack2x16unorm(bitcast<u32>(s.w));
                let wt = splat_weight(p - centre);
                sum += vec4f(s.xyz * wt, wt);
            }
        }
    }
    film[y * w + x] += sum;
}
//#endif
