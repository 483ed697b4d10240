// Compressed wide BVH traversal (Ylitie, Karras and Laine 2017), closest
// and any hit, in place of geometry.wgsl's binary traversal under WIDE_BVH:
// `trace_blas` for a bottom level, `trace_scene` for the top level over
// instances (then `trace_blas` per instance). Mirrors obvhs' own traversal
// (its `traverse!` macro): a node group is (first child node, the hit
// inner children's bits in the high byte — at 24 + (slot ^ octant), so
// that the highest bit is the nearest child in the ray's octant — and the
// node's inner-child mask in the low byte); a node's hit leaf children
// set the bits of their items in the low 24 bits of its hit mask, tested
// before the traversal descends.
//
// Nodes are 5 vec4f (obvhs' 80-byte CwBvhNode, cwbvh.rs): the grid origin
// p with the exponent bytes e and the inner mask in w; (first child node,
// first item slot, meta bytes of children 0–3, of 4–7); then per axis the
// quantized minima of children 0–3, 4–7 and maxima of 0–3, 4–7 as bytes.
// A child's box on an axis is p + q·2^e; the ray is moved into the grid
// instead: t = q·(2^e/d) + (p − o)/d.

// Node groups on the stack at most (a wide BVH is shallow: obvhs
// validates its depth against 32).
const WIDE_STACK_SIZE: u32 = 32u;

// The ray's octant as obvhs codes it (`ray_get_octant_inv4`): per byte,
// 4 where x ≥ 0, 2 where y ≥ 0, 1 where z ≥ 0.
fn octant_inv4(inv_d: vec3f) -> u32 {
    return select(0u, 0x04040404u, inv_d.x >= 0.0)
        | select(0u, 0x02020202u, inv_d.y >= 0.0)
        | select(0u, 0x01010101u, inv_d.z >= 0.0);
}

// The four bytes of w as floats.
fn bytes4(w: u32) -> vec4f {
    return vec4f((vec4u(w) >> vec4u(0u, 8u, 16u, 24u)) & vec4u(0xffu));
}

// 2^(byte k of w − 127): a node's grid scale on one axis.
fn grid_scale(w: u32, k: u32) -> f32 {
    return bitcast<f32>(((w >> (8u * k)) & 0xffu) << 23u);
}

// Which of four children (half h of a node whose quantized planes are
// x, y, z) the ray meets within tmax. `sd` is 2^e/d, `po` is (p − o)/d,
// `err` bounds their rounding in t.
fn wide_children(x: vec4u, y: vec4u, z: vec4u, h: u32, sd: vec3f, po: vec3f, neg: vec3<bool>, tmax: f32, err: f32) -> vec4<bool> {
    let lo_x = bytes4(select(x.x, x.y, h == 1u));
    let hi_x = bytes4(select(x.z, x.w, h == 1u));
    let lo_y = bytes4(select(y.x, y.y, h == 1u));
    let hi_y = bytes4(select(y.z, y.w, h == 1u));
    let lo_z = bytes4(select(z.x, z.y, h == 1u));
    let hi_z = bytes4(select(z.z, z.w, h == 1u));
    // Near and far planes by the direction's sign.
    let tnx = fma(select(lo_x, hi_x, neg.x), vec4f(sd.x), vec4f(po.x));
    let tfx = fma(select(hi_x, lo_x, neg.x), vec4f(sd.x), vec4f(po.x));
    let tny = fma(select(lo_y, hi_y, neg.y), vec4f(sd.y), vec4f(po.y));
    let tfy = fma(select(hi_y, lo_y, neg.y), vec4f(sd.y), vec4f(po.y));
    let tnz = fma(select(lo_z, hi_z, neg.z), vec4f(sd.z), vec4f(po.z));
    let tfz = fma(select(hi_z, lo_z, neg.z), vec4f(sd.z), vec4f(po.z));
    let tn = max(max(tnx, tny), max(tnz, vec4f(0.0)));
    let tf = min(min(tfx, tfy), min(tfz, vec4f(tmax)));
    // Robust traversal: the far distance grown by the rounding bound.
    return tn <= tf + vec4f(err);
}

// The hit-mask bits of four children (meta bytes m) the ray meets: an
// inner child's bit at 24 + (slot ^ octant), a leaf's item bits at its
// items' offsets (obvhs' `get_child_and_index_bits`).
fn wide_bits(m: u32, oct: u32, hit: vec4<bool>) -> u32 {
    let inner = ((m & (m << 1u)) & 0x10101010u) >> 4u;
    let bit_index = (m ^ (oct & (inner * 0xffu))) & 0x1f1f1f1fu;
    let child_bits = (m >> 5u) & 0x07070707u;
    var bits = 0u;
    for (var j = 0u; j < 4u; j++) {
        if hit[j] {
            bits |= extractBits(child_bits, 8u * j, 8u) << extractBits(bit_index, 8u * j, 8u);
        }
    }
    return bits;
}

// Intersects the ray with node `node`'s children: its node group of the
// children met (first child node, their bits and the inner-child mask),
// the first item slot and the bits of the items met.
fn wide_node(node: u32, o: vec3f, inv_d: vec3f, oct: u32, tmax: f32) -> vec4u {
//#if STATS
    stat_nodes++;
//#endif
    let at = 5u * node;
    let head = nodes[at];
    let refs = bitcast<vec4u>(nodes[at + 1u]);
    let ew = bitcast<u32>(head.w);
    let scale = vec3f(grid_scale(ew, 0u), grid_scale(ew, 1u), grid_scale(ew, 2u));
    // 2^e/d is exact; (p − o)/d and the fma round relative to |po| and
    // |q·sd| ≤ 255|sd|, and the conversion placed each plane within half
    // an ulp of 255·2^e of the child's exact box (cwbvh.rs): `err`, about
    // twice their sum, bounds the error of every child's distances.
    let sd = scale * inv_d;
    let po = (head.xyz - o) * inv_d;
    let size = 255.0 * abs(sd) + abs(po);
    let err = 2.0 * GAMMA5 * max(max(size.x, size.y), size.z);
    let neg = inv_d < vec3f(0.0);
    let x = bitcast<vec4u>(nodes[at + 2u]);
    let y = bitcast<vec4u>(nodes[at + 3u]);
    let z = bitcast<vec4u>(nodes[at + 4u]);
    let near = wide_children(x, y, z, 0u, sd, po, neg, tmax, err);
    let far = wide_children(x, y, z, 1u, sd, po, neg, tmax, err);
    let hits = wide_bits(refs.z, oct, near) | wide_bits(refs.w, oct, far);
    return vec4u(refs.x, (hits & 0xff000000u) | (ew >> 24u), refs.y, hits & 0x00ffffffu);
}

// The next node to visit: the nearest left in `group`, else in the group
// on top of the stack; NO_HIT when none is left. Pushes what is left of
// the group.
fn wide_pop(group: ptr<function, vec2u>, stack: ptr<function, array<vec2u, WIDE_STACK_SIZE>>, sp: ptr<function, u32>, oct: u32) -> u32 {
    if ((*group).y & 0xff000000u) == 0u {
        if *sp == 0u {
            return NO_HIT;
        }
        *sp -= 1u;
        *group = (*stack)[*sp];
    }
    let g = *group;
    let bit = firstLeadingBit(g.y);
    let slot = (bit - 24u) ^ (oct & 0xffu);
    let node = g.x + countOneBits(g.y & ~(0xffffffffu << slot));
    let rest = vec2u(g.x, g.y & ~(1u << bit));
    if (rest.y & 0xff000000u) != 0u && *sp < WIDE_STACK_SIZE {
        (*stack)[*sp] = rest;
        *sp += 1u;
    }
    return node;
}

// Traverses the bottom level at node `root`; with `any`, returns at the
// first hit.
fn trace_blas(root: u32, o: vec3f, d: vec3f, best: ptr<function, Hit>, any: bool) -> bool {
    let inv_d = safe_inverse(d);
    let oct = octant_inv4(inv_d);
    var stack: array<vec2u, WIDE_STACK_SIZE>;
    var sp = 0u;
    var group = vec2u(root, 0x80000000u);
    var found = false;
    loop {
        let node = wide_pop(&group, &stack, &sp, oct);
        if node == NO_HIT {
            break;
        }
        let n = wide_node(node, o, inv_d, oct, (*best).t);
        group = n.xy;
        var items = n.w;
        while items != 0u {
            let k = firstLeadingBit(items);
            items &= ~(1u << k);
            if hit_primitive(n.z + k, o, d, best) {
                found = true;
                if any {
                    return true;
                }
            }
        }
    }
    return found;
}

//#if INSTANCES
// Traverses the top level from its root (the header's), and the bottom
// level of each instance met in the instance's space.
fn trace_scene(o: vec3f, d: vec3f, best: ptr<function, Hit>, any: bool) -> bool {
    let inv_d = safe_inverse(d);
    let oct = octant_inv4(inv_d);
    var stack: array<vec2u, WIDE_STACK_SIZE>;
    var sp = 0u;
    var group = vec2u(param_u32(H_ROOT), 0x80000000u);
    var found = false;
    loop {
        let node = wide_pop(&group, &stack, &sp, oct);
        if node == NO_HIT {
            break;
        }
        let n = wide_node(node, o, inv_d, oct, (*best).t);
        group = n.xy;
        var items = n.w;
        while items != 0u {
            let k = firstLeadingBit(items);
            items &= ~(1u << k);
            let inst = n.z + k;
            // The ray in the instance's space (same t).
            let to_object = instance_to_object(inst);
            if trace_blas(instance_meta(inst).x, affine_point(to_object, o), to_object.l * d, best, any) {
                (*best).inst = inst;
                found = true;
                if any {
                    return true;
                }
            }
        }
    }
    return found;
}
//#endif
