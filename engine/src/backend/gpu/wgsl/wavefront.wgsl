// The `path` integrator as a wavefront (seed 001 §1.3–1.5): the stages of
// path.wgsl's megakernel as separate entry points over a pool of path
// slots whose state lives in `paths` (structure of arrays), linked by
// queues of slot numbers in `queues`. Per iteration:
//
//   plan_extend  takes free slots for new paths (regeneration), sizes the
//                dispatches of generate, extend and shade
//   generate     starts work items (pixel, sample) in the taken slots and
//                appends them to the ray queue after the survivors
//   extend       closest hit of every queued ray
//   shade        escaped light, emission, the shadow-ray record of
//                next-event estimation, the BSDF sample and roulette:
//                survivors are appended, compacted, to the next ray queue;
//                finished paths to the retired queue
//   plan_connect swaps the ray queues, sizes connect and accumulate
//   connect      occlusion of the shadow queue; adds unoccluded light
//   accumulate   writes retired paths to the film or splats (as the
//                megakernel does) and frees their slots
//
// Appends take one atomic per workgroup on the queue's counter (§1.4).
// Each path's radiance gathers its terms in the megakernel's order, with
// its estimator, sampler dimensions and offsets, so both give the same
// image.

// Path state, `frame.pool` entries per row: origin and time; direction and the
// last BSDF pdf; throughput and η²; radiance and filter weight; (work
// item, depth, hit slot, hit instance); (hit t, b1, b2, -). Then the
// shadow records, as many per row: origin and path slot; direction;
// value.
@group(1) @binding(0) var<storage, read_write> paths: array<vec4f>;
// The queues' header (Q_*), then the two ray queues, the retired queue
// and the free slots (a stack), `frame.pool` entries each.
@group(1) @binding(1) var<storage, read_write> queues: array<atomic<u32>>;

const STATE_ROWS: u32 = 6u;
// Header words.
const Q_LIVE: u32 = 0u;          // paths in the current ray queue
const Q_NEXT: u32 = 1u;          // survivors appended to the next one
const Q_SHADOW: u32 = 2u;        // shadow records
const Q_RETIRED: u32 = 3u;       // finished paths
const Q_FREE: u32 = 4u;          // free slots on the stack
const Q_NEXT_ITEM: u32 = 5u;     // first work item not yet started
const Q_ITEMS: u32 = 6u;         // work items of the batch
const Q_PARITY: u32 = 7u;        // which ray queue is current
const Q_GENERATE: u32 = 8u;      // paths generate starts this iteration
const Q_GENERATE_FROM: u32 = 9u; // the free-stack entry it takes first
const Q_GENERATE_ITEM: u32 = 10u;// their first work item
const Q_GENERATE_AT: u32 = 11u;  // their first ray-queue position
const Q_RETIRE_AT: u32 = 12u;    // free-stack entry of the first retired
const HEADER_WORDS: u32 = 16u;

fn pool() -> u32 {
    return frame.pool;
}

fn header(word: u32) -> u32 {
    return atomicLoad(&queues[word]);
}

// First word of ray queue 0 or 1, the retired queue, the free stack.
fn ray_queue(which: u32) -> u32 {
    return HEADER_WORDS + which * pool();
}

fn retired_queue() -> u32 {
    return HEADER_WORDS + 2u * pool();
}

fn free_stack() -> u32 {
    return HEADER_WORDS + 3u * pool();
}

fn state(row: u32, slot: u32) -> u32 {
    return row * pool() + slot;
}

fn shadow_record(row: u32, k: u32) -> u32 {
    return (STATE_ROWS + row) * pool() + k;
}

fn load_path(slot: u32) -> PathState {
    let r0 = paths[state(0u, slot)];
    let r1 = paths[state(1u, slot)];
    let r2 = paths[state(2u, slot)];
    let r3 = paths[state(3u, slot)];
    let r4 = paths[state(4u, slot)];
//#if MOTION
    ray_time = r0.w;
//#endif
    return PathState(r0.xyz, r1.xyz, r2.xyz, r2.w, r3.xyz, r1.w, bitcast<u32>(r4.y));
}

// Writes what shade changes (the ray, throughput, radiance, depth).
fn store_path(slot: u32, p: PathState) {
    paths[state(0u, slot)] = vec4f(p.o, paths[state(0u, slot)].w);
    paths[state(1u, slot)] = vec4f(p.d, p.prev_pdf);
    paths[state(2u, slot)] = vec4f(p.beta, p.eta_scale);
    paths[state(3u, slot)].x = p.radiance.x;
    paths[state(3u, slot)].y = p.radiance.y;
    paths[state(3u, slot)].z = p.radiance.z;
    paths[state(4u, slot)].y = bitcast<f32>(p.depth);
}

fn work_item(slot: u32) -> u32 {
    return bitcast<u32>(paths[state(4u, slot)].x);
}

// Pixel (x, y) and sample z of a work item: items run along rows, then
// rows, then the batch's samples (so an item is its film or splat entry).
fn item_pixel(item: u32) -> vec3u {
    let row = item / frame.width;
    return vec3u(item % frame.width, row % frame.height, row / frame.height);
}

var<workgroup> group_count: atomic<u32>;
var<workgroup> group_base: u32;

// Position in the queue whose counter is header word `counter` for an
// invocation that `wants` one (else unused): one atomic per workgroup on
// the counter. Every invocation of the workgroup calls it.
fn group_append(counter: u32, wants: bool, local: u32) -> u32 {
    var at = 0u;
    if wants {
        at = atomicAdd(&group_count, 1u);
    }
    workgroupBarrier();
    if local == 0u {
        group_base = atomicAdd(&queues[counter], atomicLoad(&group_count));
        atomicStore(&group_count, 0u);
    }
    workgroupBarrier();
    return group_base + at;
}

// Adds n per invocation to counters[which], one atomic per workgroup.
// Every invocation of the workgroup calls it.
fn group_add(which: u32, n: u32, local: u32) {
    if n > 0u {
        atomicAdd(&group_count, n);
    }
    workgroupBarrier();
    if local == 0u {
        let sum = atomicLoad(&group_count);
        if sum > 0u {
            atomicAdd(&counters[which], sum);
        }
        atomicStore(&group_count, 0u);
    }
    workgroupBarrier();
}

// Counts the invocation's ray (where it `traced` one) in
// counters[which], and under STATS its traversal work.
fn count_ray(which: u32, traced: bool, local: u32) {
    group_add(which, select(0u, 1u, traced), local);
//#if STATS
    group_add(3u, stat_nodes, local);
    group_add(4u, stat_prims, local);
//#endif
}

// Dispatch sizes (x, 1, 1) per stage: generate, extend and shade,
// connect, accumulate.
@group(2) @binding(0) var<storage, read_write> indirect: array<u32>;
const WAVE_GROUP: u32 = 64u;

fn set_dispatch(at: u32, invocations: u32) {
    indirect[at] = (invocations + WAVE_GROUP - 1u) / WAVE_GROUP;
    indirect[at + 1u] = 1u;
    indirect[at + 2u] = 1u;
}

// Regeneration: as many new paths as there are free slots and work items
// left, appended to the ray queue after last iteration's survivors.
@compute @workgroup_size(1)
fn plan_extend() {
    let live = header(Q_LIVE);
    let free = header(Q_FREE);
    let next_item = header(Q_NEXT_ITEM);
    let n = min(free, header(Q_ITEMS) - next_item);
    atomicStore(&queues[Q_GENERATE], n);
    atomicStore(&queues[Q_GENERATE_FROM], free - n);
    atomicStore(&queues[Q_GENERATE_ITEM], next_item);
    atomicStore(&queues[Q_GENERATE_AT], live);
    atomicStore(&queues[Q_FREE], free - n);
    atomicStore(&queues[Q_NEXT_ITEM], next_item + n);
    atomicStore(&queues[Q_LIVE], live + n);
    atomicStore(&queues[Q_NEXT], 0u);
    atomicStore(&queues[Q_SHADOW], 0u);
    atomicStore(&queues[Q_RETIRED], 0u);
    set_dispatch(0u, n);
    set_dispatch(3u, live + n);
}

@compute @workgroup_size(64)
fn generate(@builtin(global_invocation_id) gid: vec3u) {
    let i = gid.x;
    if i >= header(Q_GENERATE) {
        return;
    }
    let slot = atomicLoad(&queues[free_stack() + header(Q_GENERATE_FROM) + i]);
    let item = header(Q_GENERATE_ITEM) + i;
    let at = item_pixel(item);
    var p: PathState;
    let filter_weight = start_path(at.x, at.y, frame.first_sample + at.z, &p);
    var time = 0.0;
//#if MOTION
    time = ray_time;
//#endif
    paths[state(0u, slot)] = vec4f(p.o, time);
    paths[state(1u, slot)] = vec4f(p.d, p.prev_pdf);
    paths[state(2u, slot)] = vec4f(p.beta, p.eta_scale);
    paths[state(3u, slot)] = vec4f(p.radiance, filter_weight);
    paths[state(4u, slot)] = vec4f(bitcast<f32>(item), bitcast<f32>(p.depth), 0.0, 0.0);
    let queue = ray_queue(header(Q_PARITY));
    atomicStore(&queues[queue + header(Q_GENERATE_AT) + i], slot);
}

@compute @workgroup_size(64)
fn extend(@builtin(global_invocation_id) gid: vec3u, @builtin(local_invocation_index) local: u32) {
    let i = gid.x;
    let live = i < header(Q_LIVE);
    if live {
        let slot = atomicLoad(&queues[ray_queue(header(Q_PARITY)) + i]);
        let p = load_path(slot);
        let hit = closest_hit(p.o, p.d);
        paths[state(4u, slot)].z = bitcast<f32>(hit.slot);
        paths[state(4u, slot)].w = bitcast<f32>(hit.inst);
        paths[state(5u, slot)] = vec4f(hit.t, hit.b1, hit.b2, 0.0);
    }
    count_ray(1u, live, local);
}

@compute @workgroup_size(64)
fn shade(@builtin(global_invocation_id) gid: vec3u, @builtin(local_invocation_index) local: u32) {
    let i = gid.x;
    let live = i < header(Q_LIVE);
    let parity = header(Q_PARITY);
    var slot = 0u;
    var continues = false;
    var shadow = false;
//#if LIGHTS
    var c = LightConnection(vec3f(0.0), vec3f(0.0), vec3f(0.0));
//#endif
    if live {
        slot = atomicLoad(&queues[ray_queue(parity) + i]);
        var p = load_path(slot);
        let item = work_item(slot);
        let at = item_pixel(item);
        let pixel = at.y * frame.width + at.x;
        let index = frame.first_sample + at.z;
        let r4 = paths[state(4u, slot)];
        let r5 = paths[state(5u, slot)];
        let hit = Hit(r5.x, bitcast<u32>(r4.z), bitcast<u32>(r4.w), r5.y, r5.z);
        if hit.slot == NO_HIT {
            add_escaped(&p);
        } else {
            let it = interaction(hit, p.o, p.d);
            add_emitted(&p, it);
            if p.depth + 1u < MAX_DEPTH {
                let sp = shading_point(it, p.d);
//#if LIGHTS
                c = connect_light(pixel, index, p, it, sp);
                shadow = any(c.value != vec3f(0.0));
//#endif
                continues = scatter(pixel, index, &p, it, sp);
            }
        }
        store_path(slot, p);
    }
    let next = group_append(Q_NEXT, continues, local);
    if continues {
        atomicStore(&queues[ray_queue(1u - parity) + next], slot);
    }
    let retired = group_append(Q_RETIRED, live && !continues, local);
    if live && !continues {
        atomicStore(&queues[retired_queue() + retired], slot);
    }
//#if LIGHTS
    let k = group_append(Q_SHADOW, shadow, local);
    if shadow {
        paths[shadow_record(0u, k)] = vec4f(c.origin, bitcast<f32>(slot));
        paths[shadow_record(1u, k)] = vec4f(c.dir, 0.0);
        paths[shadow_record(2u, k)] = vec4f(c.value, 0.0);
    }
//#endif
}

// The survivors' queue becomes the current one; retired slots will go
// on the free stack.
@compute @workgroup_size(1)
fn plan_connect() {
    atomicStore(&queues[Q_LIVE], header(Q_NEXT));
    atomicStore(&queues[Q_PARITY], 1u - header(Q_PARITY));
    let free = header(Q_FREE);
    let retired = header(Q_RETIRED);
    atomicStore(&queues[Q_RETIRE_AT], free);
    atomicStore(&queues[Q_FREE], free + retired);
    set_dispatch(6u, header(Q_SHADOW));
    set_dispatch(9u, retired);
}

@compute @workgroup_size(64)
fn connect(@builtin(global_invocation_id) gid: vec3u, @builtin(local_invocation_index) local: u32) {
    let k = gid.x;
    let queued = k < header(Q_SHADOW);
    if queued {
        let r0 = paths[shadow_record(0u, k)];
        let slot = bitcast<u32>(r0.w);
//#if MOTION
        ray_time = paths[state(0u, slot)].w;
//#endif
        if !occluded(r0.xyz, paths[shadow_record(1u, k)].xyz, 1.0 - SHADOW_EPSILON) {
            let at = state(3u, slot);
            let radiance = paths[at].xyz + paths[shadow_record(2u, k)].xyz;
            paths[at] = vec4f(radiance, paths[at].w);
        }
    }
    count_ray(2u, queued, local);
}

@compute @workgroup_size(64)
fn accumulate(@builtin(global_invocation_id) gid: vec3u, @builtin(local_invocation_index) local: u32) {
    let i = gid.x;
    let retired = i < header(Q_RETIRED);
    var invalid = 0u;
    if retired {
        let slot = atomicLoad(&queues[retired_queue() + i]);
        if !record_sample(work_item(slot), paths[state(3u, slot)]) {
            invalid = 1u;
        }
        atomicStore(&queues[free_stack() + header(Q_RETIRE_AT) + i], slot);
    }
    group_add(0u, invalid, local);
}
