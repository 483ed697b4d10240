// Light selection: the light next-event estimation samples at a shading
// point, and the probability an emitter hit is weighted with under MIS
// (extract/lights.rs). Without SPATIAL_LIGHTS, the light table's fixed
// probabilities (power or uniform: path.wgsl's select_light). With it,
// each light's bounds' importance at the point (LightBounds::importance):
// up to 16 bounded lights, every one evaluated; beyond, a walk down the
// light tree (extract/light_tree.rs); lights without bounds share a fixed
// probability. The tables are light_selection.rs's; sums and walks run in
// the CPU's order, and choose_light and light_pmf_at share every
// function, so the probability a sample reports is the one a hit is
// weighted with.

// (light, probability) for the shading point p and the uniform sample u
// (probability 0: no light reaches p, the sample carries nothing).
fn choose_light(p: vec3f, u: f32) -> vec2f {
//#if SPATIAL_LIGHTS
    return spatial_select(p, u);
//#else
    return select_light(u);
//#endif
}

// The probability that choose_light picks light l for the shading point
// p (the origin of the ray that hit it).
fn light_pmf_at(p: vec3f, l: u32) -> f32 {
//#if SPATIAL_LIGHTS
    return spatial_pmf(p, l);
//#else
    return bitcast<f32>(light_word(l, 3u));
//#endif
}

//#if SPATIAL_LIGHTS
// The head of the tables (light_selection.rs): word k.
fn sel_word(k: u32) -> u32 {
    return param_u32(param_u32(H_LIGHT_SELECTION) + k);
}

const SEL_UNBOUNDED: u32 = 0xfffffffeu;
const SEL_UNSELECTED: u32 = 0xffffffffu;
const SEL_RECORD_WORDS: u32 = 16u;
const SEL_ONE_MINUS_EPSILON: f32 = 0.99999994;

// The first word of record r (a bounded light, or a tree node).
fn sel_record(r: u32) -> u32 {
    return sel_word(7u) + r * SEL_RECORD_WORDS;
}

fn sel_sin_from_cos(c: f32) -> f32 {
    return sqrt(max(1.0 - c * c, 0.0));
}

// cos(max(0, a − b)) and sin(max(0, a − b)) from the sines and cosines.
fn sel_cos_sub(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        return 1.0;
    }
    return cos_a * cos_b + sin_a * sin_b;
}

fn sel_sin_sub(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        return 0.0;
    }
    return sin_a * cos_b - cos_a * sin_b;
}

// LightBounds::importance of the bounds at word r for the point p.
fn sel_importance(r: u32, p: vec3f) -> f32 {
    let lo = param_vec3(r);
    let phi = param_f32(r + 3u);
    let hi = param_vec3(r + 4u);
    let cos_o = param_f32(r + 7u);
    let axis = param_vec3(r + 8u);
    let cos_e = param_f32(r + 11u);
    let centre = (lo + hi) * 0.5;
    let diagonal = hi - lo;
    let to_p = p - centre;
    let dist2 = dot(to_p, to_p);
    let d2 = max(dist2, length(diagonal) * 0.5);
    if d2 <= 0.0 {
        return 0.0;
    }
    if cos_o <= -1.0 && all(lo == hi) {
        return phi * (1.0 / d2);
    }
    let radius2 = dot(diagonal, diagonal) * 0.25;
    let inside = all(p >= lo) && all(p <= hi);
    // One reciprocal of the distance for the box's angle and the axis's
    // cosine (the box's radius is its half diagonal).
    let len = sqrt(dist2);
    let inv_len = 1.0 / len;
    var sin_b = 0.0;
    var cos_b = -1.0;
    if !(inside || dist2 <= radius2) {
        sin_b = length(diagonal) * 0.5 * inv_len;
        cos_b = sqrt(max(1.0 - sin_b * sin_b, 0.0));
    }
    var cos_w = 1.0;
    if len > 0.0 {
        cos_w = dot(to_p, axis) * inv_len;
    }
    if param_u32(r + 12u) != 0u {
        cos_w = abs(cos_w);
    }
    let sin_w = sel_sin_from_cos(cos_w);
    let sin_o = sel_sin_from_cos(cos_o);
    let cos_x = sel_cos_sub(sin_w, cos_w, sin_o, cos_o);
    let sin_x = sel_sin_sub(sin_w, cos_w, sin_o, cos_o);
    let cos_p = sel_cos_sub(sin_x, cos_x, sin_b, cos_b);
    if cos_p <= cos_e {
        return 0.0;
    }
    return max(phi * cos_p * (1.0 / d2), 0.0);
}

// Σ importance at p over the bounded lights, in their order.
fn sel_total(p: vec3f) -> f32 {
    var total = 0.0;
    for (var s = 0u; s < sel_word(0u); s++) {
        let w = sel_importance(sel_record(s), p);
        if w > 0.0 {
            total += w;
        }
    }
    return total;
}

// The probability of descending from tree node `node` into its first
// child at p (negative: neither child reaches p).
fn sel_first_probability(node: u32, p: vec3f) -> f32 {
    let a = sel_importance(sel_record(node + 1u), p);
    let b = sel_importance(sel_record(param_u32(sel_record(node) + 13u)), p);
    let total = a + b;
    if !(total > 0.0) {
        return -1.0;
    }
    return a / total;
}

fn spatial_select(p: vec3f, u: f32) -> vec2f {
    let p_unbounded = bitcast<f32>(sel_word(2u));
    let failed = vec2f(f32(sel_word(4u)), 0.0);
    if u < p_unbounded {
        let n = sel_word(1u);
        let k = min(u32(u / p_unbounded * f32(n)), n - 1u);
        return vec2f(f32(param_u32(sel_word(5u) + k)), p_unbounded / f32(n));
    }
    let nb = sel_word(0u);
    if nb == 0u {
        return vec2f(0.0);
    }
    let share = 1.0 - p_unbounded;
    if sel_word(3u) != 0u {
        // The tree: a child in proportion to importance, level by level.
        var v = clamp((u - p_unbounded) / share, 0.0, SEL_ONE_MINUS_EPSILON);
        var node = 0u;
        var pmf = 1.0;
        loop {
            let r = sel_record(node);
            if param_u32(r + 14u) != 0u {
                if sel_importance(r, p) > 0.0 {
                    return vec2f(f32(param_u32(r + 13u)), share * pmf);
                }
                return failed;
            }
            let p_first = sel_first_probability(node, p);
            if p_first < 0.0 {
                return failed;
            }
            if v < p_first {
                v = min(v / p_first, SEL_ONE_MINUS_EPSILON);
                pmf *= p_first;
                node = node + 1u;
            } else {
                v = clamp((v - p_first) / (1.0 - p_first), 0.0, SEL_ONE_MINUS_EPSILON);
                pmf *= 1.0 - p_first;
                node = param_u32(r + 13u);
            }
        }
    }
    let total = sel_total(p);
    if total <= 0.0 {
        return failed;
    }
    let target_sum = (u - p_unbounded) / share * total;
    var acc = 0.0;
    var last = failed;
    for (var s = 0u; s < nb; s++) {
        let r = sel_record(s);
        let w = sel_importance(r, p);
        if w <= 0.0 {
            continue;
        }
        acc += w;
        last = vec2f(f32(param_u32(r + 13u)), w);
        if target_sum < acc {
            break;
        }
    }
    return vec2f(last.x, share * last.y / total);
}

fn spatial_pmf(p: vec3f, l: u32) -> f32 {
    let entry = sel_word(6u) + 4u * l;
    let slot = param_u32(entry);
    let p_unbounded = bitcast<f32>(sel_word(2u));
    if slot == SEL_UNBOUNDED {
        return p_unbounded / f32(sel_word(1u));
    }
    if slot == SEL_UNSELECTED {
        return 0.0;
    }
    let share = 1.0 - p_unbounded;
    if sel_word(3u) != 0u {
        // The light's recorded branch, with select's arithmetic.
        let depth = param_u32(entry + 3u);
        var node = 0u;
        var pmf = 1.0;
        for (var d = 0u; d < depth; d++) {
            let p_first = sel_first_probability(node, p);
            if p_first < 0.0 {
                return 0.0;
            }
            let bits = param_u32(entry + 1u + d / 32u);
            if ((bits >> (d % 32u)) & 1u) == 0u {
                pmf *= p_first;
                node = node + 1u;
            } else {
                pmf *= 1.0 - p_first;
                node = param_u32(sel_record(node) + 13u);
            }
        }
        if sel_importance(sel_record(node), p) > 0.0 {
            return share * pmf;
        }
        return 0.0;
    }
    let total = sel_total(p);
    if total > 0.0 {
        return share * sel_importance(sel_record(slot), p) / total;
    }
    return 0.0;
}
//#endif
