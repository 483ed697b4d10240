// Geometry on the GPU: binary BVH traversal (closest and any hit; under
// WIDE_BVH wgsl/cwbvh.wgsl's compressed wide BVH traversal instead), the two
// levels through instances, ray–primitive tests, and hit resolution into
// the interaction the integrator shades (integrators/surface.rs).
//
// Binary nodes are 4 vec4f: both children's boxes, each with a reference (a node
// index, or the first primitive slot of a leaf) and a primitive count
// (0: inner). An inner reference of NO_HIT is an empty child: it becomes
// `next` and is dropped like a missed box. Primitives are PRIM_ROWS vec4f:
// v0 (kind in w: 0 triangle, 1 sphere), v1, v2 (sphere: centre in v0,
// radius in v1.x), then (material, emitter, emitter primitive, primitive
// number) as bits, the primitive number (the CPU's) indexing the shading
// data; under MOTION then v0, v1, v2 at shutter close (upload.rs).

const STACK_SIZE: u32 = 48u;
const NO_HIT: u32 = 0xffffffffu;
const GAMMA3: f32 = 1.7881397e-7;
const GAMMA5: f32 = 2.9802326e-7;
const GAMMA7: f32 = 4.1723263e-7;

//#if STATS
// Traversal work of this invocation (`--gpu-stats`): nodes visited and
// primitives tested.
var<private> stat_nodes: u32 = 0u;
var<private> stat_prims: u32 = 0u;
//#endif

//#if MOTION
const PRIM_ROWS: u32 = 7u;
// The time of the ray being traced in the shutter, τ in [0, 1) (one per
// path: the integrator sets it when the path starts).
var<private> ray_time: f32 = 0.0;
//#else
const PRIM_ROWS: u32 = 4u;
//#endif

struct Hit {
    t: f32,
    slot: u32,
    inst: u32,
    b1: f32,
    b2: f32,
}

fn prim_kind(slot: u32) -> u32 {
    return bitcast<u32>(prims[PRIM_ROWS * slot].w);
}

fn prim_info(slot: u32) -> vec4u {
    return bitcast<vec4u>(prims[PRIM_ROWS * slot + 3u]);
}

// Vertex k of a triangle at the ray's time (blas.rs `primitive`: the
// shutter-open vertex moved linearly towards the shutter-close one).
fn prim_vertex(slot: u32, k: u32) -> vec3f {
    let open = prims[PRIM_ROWS * slot + k].xyz;
//#if MOTION
    let close = prims[PRIM_ROWS * slot + 4u + k].xyz;
    return open + (close - open) * ray_time;
//#else
    return open;
//#endif
}

// Möller–Trumbore; updates `best` where the triangle is closer.
fn hit_triangle(slot: u32, o: vec3f, d: vec3f, best: ptr<function, Hit>) -> bool {
    let v0 = prim_vertex(slot, 0u);
    let e1 = prim_vertex(slot, 1u) - v0;
    let e2 = prim_vertex(slot, 2u) - v0;
    let pv = cross(d, e2);
    let det = dot(e1, pv);
    if det == 0.0 {
        return false;
    }
    let inv = 1.0 / det;
    let tv = o - v0;
    let b1 = dot(tv, pv) * inv;
    if b1 < 0.0 || b1 > 1.0 {
        return false;
    }
    let qv = cross(tv, e1);
    let b2 = dot(d, qv) * inv;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return false;
    }
    let t = dot(e2, qv) * inv;
    if t > 0.0 && t < (*best).t {
        (*best).t = t;
        (*best).slot = slot;
        (*best).b1 = b1;
        (*best).b2 = b2;
        return true;
    }
    return false;
}

//#if SPHERES
// Haines et al.'s precise ray–sphere test (accel/sphere.rs).
fn hit_sphere(slot: u32, o: vec3f, d: vec3f, best: ptr<function, Hit>) -> bool {
    let c = prims[PRIM_ROWS * slot].xyz;
    let r = prims[PRIM_ROWS * slot + 1u].x;
    let f = o - c;
    let a = dot(d, d);
    let b = -dot(f, d);
    let l = f + d * (b / a);
    let disc = r * r - dot(l, l);
    if disc < 0.0 {
        return false;
    }
    let cc = dot(f, f) - r * r;
    let q = b + select(-1.0, 1.0, b >= 0.0) * sqrt(a * disc);
    if q == 0.0 {
        return false;
    }
    let t0 = cc / q;
    let t1 = q / a;
    let near = min(t0, t1);
    let far = max(t0, t1);
    var t = -1.0;
    if near > 0.0 && near < (*best).t {
        t = near;
    } else if far > 0.0 && far < (*best).t {
        t = far;
    }
    if t > 0.0 {
        (*best).t = t;
        (*best).slot = slot;
        (*best).b1 = 0.0;
        (*best).b2 = 0.0;
        return true;
    }
    return false;
}
//#endif

fn hit_primitive(slot: u32, o: vec3f, d: vec3f, best: ptr<function, Hit>) -> bool {
//#if STATS
    stat_prims++;
//#endif
//#if SPHERES
    if prim_kind(slot) == 1u {
        return hit_sphere(slot, o, d, best);
    }
//#endif
    return hit_triangle(slot, o, d, best);
}

// Entry distance of the ray into box [lo, hi], or FLOAT_MAX where it
// misses it within tmax.
fn box_entry(lo: vec3f, hi: vec3f, o: vec3f, inv_d: vec3f, tmax: f32) -> f32 {
    let t0 = (lo - o) * inv_d;
    let t1 = (hi - o) * inv_d;
    let tn = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    let tf = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), min(max(t0.z, t1.z), tmax));
    // Robust traversal (Ize 2013): the far distance grown by 2γ3.
    if tn <= tf * (1.0 + 2.0 * GAMMA3) {
        return tn;
    }
    return FLOAT_MAX;
}

fn safe_inverse(d: vec3f) -> vec3f {
    let tiny = 1e-30;
    return 1.0 / select(d, select(vec3f(-tiny), vec3f(tiny), d >= vec3f(0.0)), abs(d) < vec3f(tiny));
}

//#if WIDE_BVH
// (trace_blas and trace_scene are wgsl/cwbvh.wgsl's)
//#else
// Traverses the bottom level at node `root`; with `any`, returns at the
// first hit.
fn trace_blas(root: u32, o: vec3f, d: vec3f, best: ptr<function, Hit>, any: bool) -> bool {
    let inv_d = safe_inverse(d);
    var stack: array<u32, STACK_SIZE>;
    var sp = 0u;
    var node = root;
    var found = false;
    loop {
//#if STATS
        stat_nodes++;
//#endif
        let a_lo = nodes[4u * node];
        let a_hi = nodes[4u * node + 1u];
        let b_lo = nodes[4u * node + 2u];
        let b_hi = nodes[4u * node + 3u];
        let ta = box_entry(a_lo.xyz, a_hi.xyz, o, inv_d, (*best).t);
        let tb = box_entry(b_lo.xyz, b_hi.xyz, o, inv_d, (*best).t);
        var next = NO_HIT;
        var later = NO_HIT;
        let a_count = bitcast<u32>(a_hi.w);
        let b_count = bitcast<u32>(b_hi.w);
        if ta < FLOAT_MAX {
            let first = bitcast<u32>(a_lo.w);
            if a_count > 0u {
                for (var i = 0u; i < a_count; i++) {
                    if hit_primitive(first + i, o, d, best) {
                        found = true;
                        if any {
                            return true;
                        }
                    }
                }
            } else {
                next = first;
            }
        }
        if tb < FLOAT_MAX {
            let first = bitcast<u32>(b_lo.w);
            if b_count > 0u {
                for (var i = 0u; i < b_count; i++) {
                    if hit_primitive(first + i, o, d, best) {
                        found = true;
                        if any {
                            return true;
                        }
                    }
                }
            } else if next == NO_HIT {
                next = first;
            } else if tb < ta {
                later = next;
                next = first;
            } else {
                later = first;
            }
        }
        if later != NO_HIT && sp < STACK_SIZE {
            stack[sp] = later;
            sp++;
        }
        if next == NO_HIT {
            if sp == 0u {
                break;
            }
            sp--;
            next = stack[sp];
        }
        node = next;
    }
    return found;
}
//#endif

//#if INSTANCES
// Instances are 10 vec4f: the rows of render → object, of the normal
// matrix and of object → render, then (bottom-level root, material or
// NO_HIT, motion record or NO_HIT, 0) as bits. A moving instance's rows
// are unused: its placement is made from its motion record at the ray's
// time.
fn instance_row(inst: u32, row: u32) -> vec4f {
    return instances[10u * inst + row];
}

fn instance_meta(inst: u32) -> vec4u {
    return bitcast<vec4u>(instances[10u * inst + 9u]);
}
//#endif

// An affine transform: x ↦ l·x + t.
struct Affine {
    l: mat3x3f,
    t: vec3f,
}

fn affine_point(a: Affine, p: vec3f) -> vec3f {
    return a.l * p + a.t;
}

// The transform whose 3×4 matrix has rows r0, r1, r2 (translation in w).
fn affine_from_rows(r0: vec4f, r1: vec4f, r2: vec4f) -> Affine {
    return Affine(transpose(mat3x3f(r0.xyz, r1.xyz, r2.xyz)), vec3f(r0.w, r1.w, r2.w));
}

// a after b.
fn affine_compose(a: Affine, b: Affine) -> Affine {
    return Affine(a.l * b.l, a.l * b.t + a.t);
}

//#if MOTION
// The inverse of an invertible affine transform.
fn affine_inverse(a: Affine) -> Affine {
    let c0 = a.l[0];
    let c1 = a.l[1];
    let c2 = a.l[2];
    let r0 = cross(c1, c2);
    let r1 = cross(c2, c0);
    let r2 = cross(c0, c1);
    let inv_det = 1.0 / dot(c0, r0);
    let l = transpose(mat3x3f(r0, r1, r2)) * inv_det;
    return Affine(l, -(l * a.t));
}

// The rotation matrix of the unit quaternion q (x, y, z, w).
fn quat_matrix(q: vec4f) -> mat3x3f {
    let x2 = q.x + q.x;
    let y2 = q.y + q.y;
    let z2 = q.z + q.z;
    let xx = q.x * x2;
    let xy = q.x * y2;
    let xz = q.x * z2;
    let yy = q.y * y2;
    let yz = q.y * z2;
    let zz = q.z * z2;
    let wx = q.w * x2;
    let wy = q.w * y2;
    let wz = q.w * z2;
    return mat3x3f(
        vec3f(1.0 - (yy + zz), xy + wz, xz - wy),
        vec3f(xy - wz, 1.0 - (xx + zz), yz + wx),
        vec3f(xz + wy, yz - wx, 1.0 - (xx + yy)),
    );
}

// Shortest-path slerp (world/animation.rs `slerp`).
fn quat_slerp(a: vec4f, b0: vec4f, s: f32) -> vec4f {
    var b = b0;
    var c = dot(a, b);
    if c < 0.0 {
        c = -c;
        b = -b;
    }
    if c > 1.0 - 1e-6 {
        return normalize(a + (b - a) * s);
    }
    let angle = acos(clamp(c, -1.0, 1.0));
    let sin_angle = sin(angle);
    return normalize(a * (sin((1.0 - s) * angle) / sin_angle) + b * (sin(s * angle) / sin_angle));
}

// The object → render transform of the motion record at row `at` of
// `instances` at shutter time tau (instance.rs `Motion::matrix`): outer ·
// T·R·S(τ) · inner, translation and scale linear in τ, rotation by slerp.
fn motion_affine(at: u32, tau: f32) -> Affine {
    let outer = affine_from_rows(instances[at], instances[at + 1u], instances[at + 2u]);
    let inner = affine_from_rows(instances[at + 3u], instances[at + 4u], instances[at + 5u]);
    let t = mix(instances[at + 6u].xyz, instances[at + 9u].xyz, tau);
    let q = quat_slerp(instances[at + 7u], instances[at + 10u], tau);
    let sc = mix(instances[at + 8u].xyz, instances[at + 11u].xyz, tau);
    let r = quat_matrix(q);
    let pose = Affine(mat3x3f(r[0] * sc.x, r[1] * sc.y, r[2] * sc.z), t);
    return affine_compose(outer, affine_compose(pose, inner));
}
//#endif

//#if INSTANCES
// Render → object space of instance `inst` at the ray's time.
fn instance_to_object(inst: u32) -> Affine {
//#if MOTION
    let motion = instance_meta(inst).z;
    if motion != NO_HIT {
        return affine_inverse(motion_affine(motion, ray_time));
    }
//#endif
    return affine_from_rows(instance_row(inst, 0u), instance_row(inst, 1u), instance_row(inst, 2u));
}

// An instance's placement at the ray's time (instance.rs `Placement`).
struct Placement {
    to_object: Affine,
    normals: mat3x3f,
    to_render: Affine,
}

fn instance_placement(inst: u32) -> Placement {
//#if MOTION
    let motion = instance_meta(inst).z;
    if motion != NO_HIT {
        let to_render = motion_affine(motion, ray_time);
        let to_object = affine_inverse(to_render);
        return Placement(to_object, transpose(to_object.l), to_render);
    }
//#endif
    let to_object = affine_from_rows(instance_row(inst, 0u), instance_row(inst, 1u), instance_row(inst, 2u));
    let normals = transpose(mat3x3f(instance_row(inst, 3u).xyz, instance_row(inst, 4u).xyz, instance_row(inst, 5u).xyz));
    let to_render = affine_from_rows(instance_row(inst, 6u), instance_row(inst, 7u), instance_row(inst, 8u));
    return Placement(to_object, normals, to_render);
}

//#if WIDE_BVH
//#else
fn trace_scene(o: vec3f, d: vec3f, best: ptr<function, Hit>, any: bool) -> bool {
    let inv_d = safe_inverse(d);
    var stack: array<u32, STACK_SIZE>;
    var sp = 0u;
    var node = param_u32(H_ROOT);
    var found = false;
    loop {
//#if STATS
        stat_nodes++;
//#endif
        let a_lo = nodes[4u * node];
        let a_hi = nodes[4u * node + 1u];
        let b_lo = nodes[4u * node + 2u];
        let b_hi = nodes[4u * node + 3u];
        let ta = box_entry(a_lo.xyz, a_hi.xyz, o, inv_d, (*best).t);
        let tb = box_entry(b_lo.xyz, b_hi.xyz, o, inv_d, (*best).t);
        var next = NO_HIT;
        var later = NO_HIT;
        for (var side = 0u; side < 2u; side++) {
            let lo = select(b_lo, a_lo, side == 0u);
            let hi = select(b_hi, a_hi, side == 0u);
            let t = select(tb, ta, side == 0u);
            if t == FLOAT_MAX {
                continue;
            }
            let first = bitcast<u32>(lo.w);
            let count = bitcast<u32>(hi.w);
            if count > 0u {
                for (var i = 0u; i < count; i++) {
                    let inst = first + i;
                    // The ray in the instance's space (same t).
                    let to_object = instance_to_object(inst);
                    let oo = affine_point(to_object, o);
                    let od = to_object.l * d;
                    if trace_blas(instance_meta(inst).x, oo, od, best, any) {
                        (*best).inst = inst;
                        found = true;
                        if any {
                            return true;
                        }
                    }
                }
            } else if next == NO_HIT {
                next = first;
            } else if t < ta {
                later = next;
                next = first;
            } else {
                later = first;
            }
        }
        if later != NO_HIT && sp < STACK_SIZE {
            stack[sp] = later;
            sp++;
        }
        if next == NO_HIT {
            if sp == 0u {
                break;
            }
            sp--;
            next = stack[sp];
        }
        node = next;
    }
    return found;
}
//#endif
//#endif

fn closest_hit(o: vec3f, d: vec3f) -> Hit {
    return closest_hit_before(o, d, FLOAT_MAX);
}

// The closest hit on o + t·d with t < tmax.
fn closest_hit_before(o: vec3f, d: vec3f, tmax: f32) -> Hit {
    var best = Hit(tmax, NO_HIT, 0u, 0.0, 0.0);
//#if INSTANCES
    trace_scene(o, d, &best, false);
//#else
    trace_blas(param_u32(H_ROOT), o, d, &best, false);
//#endif
    return best;
}

// Whether anything lies on the segment o + t·d, t in (0, tmax).
fn occluded(o: vec3f, d: vec3f, tmax: f32) -> bool {
    var best = Hit(tmax, NO_HIT, 0u, 0.0, 0.0);
//#if INSTANCES
    return trace_scene(o, d, &best, true);
//#else
    return trace_blas(param_u32(H_ROOT), o, d, &best, true);
//#endif
}

// ---- Hits resolved into interactions ----

struct Interaction {
    p: vec3f,
    err: vec3f,
    ng: vec3f,
    // Shading frame: s, t, n.
    frame: mat3x3f,
    uv: vec2f,
    // ∂p/∂u and ∂p/∂v with their real lengths under TANGENT_FRAMES, else
    // the frame's s and t.
    dp_du: vec3f,
    dp_dv: vec3f,
    material: u32,
    emitter: u32,
    emitter_prim: u32,
}

// Rows of shading data per primitive: vertex normals and texture
// coordinates, then (TANGENT_FRAMES) the MikkTSpace vertex tangents.
//#if TANGENT_FRAMES
const SHADING_ROWS: u32 = 7u;
//#else
const SHADING_ROWS: u32 = 4u;
//#endif

fn shading_row(sh: u32, row: u32) -> vec4f {
    return shading[SHADING_ROWS * sh + row];
}

// Shading normal bent above the geometric tangent plane (surface.rs).
fn above_tangent_plane(ns: vec3f, ng: vec3f) -> vec3f {
    let c = dot(ns, ng);
    if c >= 0.01 {
        return ns;
    }
    return normalize(ns + ng * (0.01 - c));
}

// The frame's unit tangents as the derivatives of a surface without them.
fn set_unit_derivatives(it: ptr<function, Interaction>) {
    (*it).dp_du = (*it).frame[0];
    (*it).dp_dv = (*it).frame[1];
}

//#if TANGENT_FRAMES
// `Frame::around_z`: the tangent along ẑ × n, or the x axis made
// orthogonal to n near ±z.
fn frame_around_z(n: vec3f) -> mat3x3f {
    if n.x * n.x + n.y * n.y > 1e-6 {
        let f = frame_with_tangent(n, vec3f(-n.y, n.x, 0.0));
        if frame_usable(f) {
            return f;
        }
    }
    let f = frame_with_tangent(n, vec3f(1.0, 0.0, 0.0));
    if frame_usable(f) {
        return f;
    }
    return frame_from_normal(n);
}

// surface.rs `triangle_frame`: the frame around ns oriented by the
// interpolated vertex tangent, else by ∂p/∂u of the texture coordinates,
// else around z; with the triangle's derivatives (the frame's unit
// tangents where the coordinates give none).
fn triangle_frame(it: ptr<function, Interaction>, ns: vec3f, v0: vec3f, v1: vec3f, v2: vec3f, uv0: vec2f, uv1: vec2f, uv2: vec2f, tangent: vec3f) {
    let uvless = all(uv0 == vec2f(0.0, 0.0)) && all(uv1 == vec2f(1.0, 0.0)) && all(uv2 == vec2f(0.0, 1.0))
        && all(tangent == vec3f(0.0));
    var has_dp = false;
    var dp_du = vec3f(0.0);
    var dp_dv = vec3f(0.0);
    if !uvless {
        let dp0 = v1 - v0;
        let dp1 = v2 - v0;
        let duv0 = uv1 - uv0;
        let duv1 = uv2 - uv0;
        let det = duv0.x * duv1.y - duv0.y * duv1.x;
        if abs(det) > 1e-9 * length(duv0) * length(duv1) {
            let inv = 1.0 / det;
            dp_du = (dp0 * duv1.y - dp1 * duv0.y) * inv;
            dp_dv = (dp1 * duv0.x - dp0 * duv1.x) * inv;
            has_dp = is_finite_vec3(dp_du) && is_finite_vec3(dp_dv);
        }
    }
    var f = frame_with_tangent(ns, tangent);
    if !frame_usable(f) && has_dp {
        f = frame_with_tangent(ns, dp_du);
    }
    if !frame_usable(f) {
        f = frame_around_z(ns);
    }
    (*it).frame = f;
    if has_dp {
        (*it).dp_du = dp_du;
        (*it).dp_dv = dp_dv;
    } else {
        set_unit_derivatives(it);
    }
}

// surface.rs `sphere_frame`: Mitsuba 3's u = φ/2π, v = θ/π in the
// sphere's own axes (`rows`: the rotation into them), n in those axes
// being `local`.
fn sphere_frame(it: ptr<function, Interaction>, n: vec3f, local: vec3f, r0: vec3f, r1: vec3f, r2: vec3f, radius: f32) {
    let rd = sqrt(local.x * local.x + local.y * local.y);
    var dv = vec3f(1.0, 0.0, 0.0);
    if rd > 0.0 {
        dv = vec3f(local.z * local.x / rd, local.z * local.y / rd, -rd);
    }
    let du = vec3f(-local.y, local.x, 0.0);
    (*it).dp_du = (r0 * du.x + r1 * du.y + r2 * du.z) * (2.0 * PI * radius);
    (*it).dp_dv = (r0 * dv.x + r1 * dv.y + r2 * dv.z) * (PI * radius);
    var f = frame_with_tangent(n, (*it).dp_du);
    if !frame_usable(f) {
        f = frame_with_tangent(n, r1);
    }
    if !frame_usable(f) {
        f = frame_around_z(n);
    }
    (*it).frame = f;
}
//#endif

// The interaction in the primitive's own space.
fn local_interaction(hit: Hit, o: vec3f, d: vec3f) -> Interaction {
    var it: Interaction;
    let slot = hit.slot;
    let info = prim_info(slot);
    it.material = info.x;
    it.emitter = info.y;
    it.emitter_prim = info.z;
    let sh = info.w;
//#if SPHERES
    if prim_kind(slot) == 1u {
        let c = prims[PRIM_ROWS * slot].xyz;
        let r = prims[PRIM_ROWS * slot + 1u].x;
        let n = normalize(o + d * hit.t - c);
        it.p = c + n * r;
        it.err = (abs(it.p) + abs(c)) * GAMMA5;
        it.ng = n;
        // The rows of the rotation into the sphere's own axes.
        let r0 = shading_row(sh, 0u).xyz;
        let r1 = shading_row(sh, 1u).xyz;
        let r2 = shading_row(sh, 2u).xyz;
        let local = vec3f(dot(r0, n), dot(r1, n), dot(r2, n));
//#if TEXTURES
        it.uv = vec2f(fract(atan2(local.y, local.x) * INV_PI * 0.5 + 1.0), acos(clamp(local.z, -1.0, 1.0)) * INV_PI);
//#endif
//#if TANGENT_FRAMES
        sphere_frame(&it, n, local, r0, r1, r2, r);
//#else
        it.frame = frame_from_normal(n);
        set_unit_derivatives(&it);
//#endif
        return it;
    }
//#endif
    let v0 = prim_vertex(slot, 0u);
    let v1 = prim_vertex(slot, 1u);
    let v2 = prim_vertex(slot, 2u);
    let b = vec3f(1.0 - hit.b1 - hit.b2, hit.b1, hit.b2);
    let w0 = v0 * b.x;
    let w1 = v1 * b.y;
    let w2 = v2 * b.z;
    it.p = w0 + w1 + w2;
    it.err = (abs(w0) + abs(w1) + abs(w2)) * GAMMA7;
    let ng = normalize(cross(v1 - v0, v2 - v0));
    it.ng = ng;
    var ns = ng;
    let n0 = shading_row(sh, 0u);
    let n1 = shading_row(sh, 1u);
    let n2 = shading_row(sh, 2u);
    if any(n0.xyz != vec3f(0.0)) {
        let sum = n0.xyz * b.x + n1.xyz * b.y + n2.xyz * b.z;
        let l = length(sum);
        if l > 0.0 && is_finite_f32(1.0 / l) {
            ns = above_tangent_plane(sum / l, ng);
        } else {
            ns = above_tangent_plane(ng, ng);
        }
    }
    let uv3 = shading_row(sh, 3u);
    let uv0 = vec2f(n0.w, n1.w);
    let uv1 = vec2f(n2.w, uv3.x);
    let uv2 = uv3.yz;
//#if TEXTURES
    it.uv = uv0 * b.x + uv1 * b.y + uv2 * b.z;
//#endif
//#if TANGENT_FRAMES
    let tangent = shading_row(sh, 4u).xyz * b.x + shading_row(sh, 5u).xyz * b.y + shading_row(sh, 6u).xyz * b.z;
    triangle_frame(&it, ns, v0, v1, v2, uv0, uv1, uv2, tangent);
//#else
    it.frame = frame_from_normal(ns);
    set_unit_derivatives(&it);
//#endif
    return it;
}

fn interaction(hit: Hit, o: vec3f, d: vec3f) -> Interaction {
//#if INSTANCES
    let inst = hit.inst;
    let m = instance_meta(inst);
    let place = instance_placement(inst);
    var it = local_interaction(hit, affine_point(place.to_object, o), place.to_object.l * d);
    if m.y != NO_HIT {
        it.material = m.y;
    }
    // Out to render space with the transform's rounding error (instance.rs).
    let to_render = place.to_render;
    let abs_l = mat3x3f(abs(to_render.l[0]), abs(to_render.l[1]), abs(to_render.l[2]));
    let p = it.p;
    it.p = affine_point(to_render, p);
    it.err = (abs_l * it.err) * (GAMMA3 + 1.0) + (abs_l * abs(p) + abs(to_render.t)) * GAMMA3;
    it.ng = normalize(place.normals * it.ng);
    let ns = above_tangent_plane(normalize(place.normals * it.frame[2]), it.ng);
//#if TANGENT_FRAMES
    it.dp_du = to_render.l * it.dp_du;
    it.dp_dv = to_render.l * it.dp_dv;
    it.frame = frame_with_tangent(ns, to_render.l * it.frame[0]);
    if !frame_usable(it.frame) {
        it.frame = frame_around_z(ns);
    }
//#else
    it.frame = frame_from_normal(ns);
    set_unit_derivatives(&it);
//#endif
    return it;
//#else
    return local_interaction(hit, o, d);
//#endif
}

// The origin of a ray leaving p (error bound err, normal n) towards w
// (accel/offset.rs).
fn offset_origin(p: vec3f, err: vec3f, n: vec3f, w: vec3f) -> vec3f {
    let dist = dot(abs(n), err);
    let side = select(dist, -dist, dot(w, n) < 0.0);
    let offset = n * side;
    let po = p + offset;
    let step = max(abs(po) * 1.1920929e-7, vec3f(1.17549435e-38));
    let up = select(po, po + step, offset > vec3f(0.0));
    return select(up, up - step, offset < vec3f(0.0));
}
