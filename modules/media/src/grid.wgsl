// The `grid` medium: parameters σa, σs, Le, then the grid's resolution
// (3 words), its render-space box (corner, size), the majorant grid's
// cells per axis (3 words), the densities (x fastest) and the majorants.
// Trilinear lookup between voxel centres (`DensityGrid::density`), the
// majorant cells walked by an Amanatides–Woo DDA, distances by spectral
// delta tracking and transmittance by ratio tracking (`medium/tracking.rs`).

fn grid_resolution(p: u32) -> vec3u {
    return vec3u(param_u32(p + 9u), param_u32(p + 10u), param_u32(p + 11u));
}

fn grid_cells(p: u32) -> vec3u {
    return vec3u(param_u32(p + 18u), param_u32(p + 19u), param_u32(p + 20u));
}

fn grid_voxel(p: u32, r: vec3u, x: u32, y: u32, z: u32) -> f32 {
    return param_f32(p + 21u + (z * r.y + y) * r.x + x);
}

// ρ at the render-space point x (0 outside the box).
fn grid_density(p: u32, x: vec3f) -> f32 {
    let u = (x - param_vec3(p + 12u)) / param_vec3(p + 15u);
    if !(all(u >= vec3f(0.0)) && all(u <= vec3f(1.0))) {
        return 0.0;
    }
    let r = grid_resolution(p);
    let v = u * vec3f(r) - vec3f(0.5);
    let i = floor(v);
    let f = v - i;
    let last = vec3i(r) - vec3i(1);
    let lo = vec3u(clamp(vec3i(i), vec3i(0), last));
    let hi = vec3u(clamp(vec3i(i) + vec3i(1), vec3i(0), last));
    let z0 = mix(
        mix(grid_voxel(p, r, lo.x, lo.y, lo.z), grid_voxel(p, r, hi.x, lo.y, lo.z), f.x),
        mix(grid_voxel(p, r, lo.x, hi.y, lo.z), grid_voxel(p, r, hi.x, hi.y, lo.z), f.x),
        f.y,
    );
    let z1 = mix(
        mix(grid_voxel(p, r, lo.x, lo.y, hi.z), grid_voxel(p, r, hi.x, lo.y, hi.z), f.x),
        mix(grid_voxel(p, r, lo.x, hi.y, hi.z), grid_voxel(p, r, hi.x, hi.y, hi.z), f.x),
        f.y,
    );
    return max(mix(z0, z1, f.z), 0.0);
}

// A DDA over the majorant cells along a ray (`DensityGrid::majorants`).
struct GridWalk {
    cell: vec3i,
    next: vec3f,
    delta: vec3f,
    step: vec3i,
    t: f32,
    t1: f32,
    live: bool,
}

fn grid_walk(p: u32, o: vec3f, d: vec3f, t_max: f32) -> GridWalk {
    var w = GridWalk(vec3i(0), vec3f(FLOAT_MAX), vec3f(FLOAT_MAX), vec3i(0), 0.0, t_max, false);
    // In box coordinates u = (x − corner)/size ∈ [0, 1]³ (the same t).
    let size = param_vec3(p + 15u);
    let uo = (o - param_vec3(p + 12u)) / size;
    let ud = d / size;
    for (var a = 0; a < 3; a++) {
        if ud[a] == 0.0 {
            // Parallel to the slabs: inside them or nowhere.
            if uo[a] < 0.0 || uo[a] > 1.0 {
                return w;
            }
            continue;
        }
        let inv = 1.0 / ud[a];
        var near = (0.0 - uo[a]) * inv;
        var far = (1.0 - uo[a]) * inv;
        if near > far {
            let swap = near;
            near = far;
            far = swap;
        }
        if near > w.t {
            w.t = near;
        }
        if far < w.t1 {
            w.t1 = far;
        }
    }
    if !(w.t < w.t1) {
        return w;
    }
    w.live = true;
    let m = vec3f(grid_cells(p));
    let start = uo + ud * w.t;
    for (var a = 0; a < 3; a++) {
        w.cell[a] = clamp(i32(floor(start[a] * m[a])), 0, i32(m[a]) - 1);
        if ud[a] > 0.0 {
            w.step[a] = 1;
            w.next[a] = w.t + (f32(w.cell[a] + 1) / m[a] - start[a]) / ud[a];
            w.delta[a] = 1.0 / (m[a] * ud[a]);
        } else if ud[a] < 0.0 {
            w.step[a] = -1;
            w.next[a] = w.t + (f32(w.cell[a]) / m[a] - start[a]) / ud[a];
            w.delta[a] = -1.0 / (m[a] * ud[a]);
        }
    }
    return w;
}

// The walk's next segment (t0, t1, majorant ρ̄), or a negative majorant
// where the walk has ended.
fn grid_walk_next(p: u32, w: ptr<function, GridWalk>) -> vec3f {
    let m = vec3i(grid_cells(p));
    let r = grid_resolution(p);
    loop {
        if !(*w).live {
            return vec3f(0.0, 0.0, -1.0);
        }
        let n = (*w).next;
        var a = 2;
        if n.x <= n.y && n.x <= n.z {
            a = 0;
        } else if n.y <= n.z {
            a = 1;
        }
        let t0 = (*w).t;
        let end = min(n[a], (*w).t1);
        let c = (*w).cell;
        let index = u32((c.z * m.y + c.y) * m.x + c.x);
        let bound = param_f32(p + 21u + r.x * r.y * r.z + index);
        if end >= (*w).t1 {
            (*w).live = false;
        } else {
            (*w).t = end;
            (*w).cell[a] += (*w).step[a];
            (*w).next[a] += (*w).delta[a];
            let ca = (*w).cell[a];
            if ca < 0 || ca >= m[a] {
                (*w).live = false;
            }
        }
        if end > t0 {
            return vec3f(t0, end, bound);
        }
    }
    return vec3f(0.0, 0.0, -1.0);
}

// Tentative collisions along a walk: exponential steps at the rate
// μ̄ = ρ̄·top of each majorant segment.
struct Collisions {
    walk: GridWalk,
    t: f32,
    end: f32,
    mu: f32,
}

fn grid_collisions(p: u32, o: vec3f, d: vec3f, t_max: f32) -> Collisions {
    return Collisions(grid_walk(p, o, d, t_max), 0.0, 0.0, 0.0);
}

// Moves `c` to its next tentative collision (c.t, at rate c.mu); false
// where the walk has ended.
fn grid_next_collision(p: u32, c: ptr<function, Collisions>, top: f32, rng: ptr<function, Stream>) -> bool {
    loop {
        if (*c).mu > 0.0 {
            // 1 − u in (0, 1]: the logarithm is finite.
            (*c).t -= log(1.0 - stream_next(rng)) / (*c).mu;
            if (*c).t < (*c).end {
                return true;
            }
        }
        var walk = (*c).walk;
        let seg = grid_walk_next(p, &walk);
        (*c).walk = walk;
        if seg.z < 0.0 {
            return false;
        }
        (*c).t = seg.x;
        (*c).end = seg.y;
        (*c).mu = seg.z * top;
    }
    return false;
}

// Spectral delta tracking (`delta_track`): tentative collisions at the
// grey majorant rate μ̄ = ρ̄·max σt, absorption, scattering or a null
// collision chosen by the channel averages of σa·β, σs·β and σn·β
// (Kutz et al. 2017), emission σa·Le/μ̄ gathered at every one.
fn medium_flight_grid(p: u32, o: vec3f, d: vec3f, t_max: f32, beta: vec3f, u: vec2f, rng: ptr<function, Stream>) -> MediumFlight {
    let sigma_a = medium_sigma_a(p);
    let sigma_s = medium_sigma_s(p);
    let sigma_t = sigma_a + sigma_s;
    let emission = medium_emission(p);
    let top = max(sigma_t.x, max(sigma_t.y, sigma_t.z));
    var out = MediumFlight(t_max, false, beta, vec3f(0.0));
    if top <= 0.0 {
        return out;
    }
    let emits = max(emission.x, max(emission.y, emission.z)) > 0.0 && max(sigma_a.x, max(sigma_a.y, sigma_a.z)) > 0.0;
    var c = grid_collisions(p, o, d, t_max);
    loop {
        if !grid_next_collision(p, &c, top, rng) {
            break;
        }
        let t = c.t;
        let mu = c.mu;
        let rho = grid_density(p, o + d * t);
        let sa = sigma_a * rho;
        let ss = sigma_s * rho;
        let sn = max(vec3f(mu) - sigma_t * rho, vec3f(0.0));
        let b = out.beta;
        if emits {
            out.emitted += b * sa * emission / mu;
        }
        let pa = channel_average(sa * b);
        let ps = channel_average(ss * b);
        let pn = channel_average(sn * b);
        let total = pa + ps + pn;
        let x = stream_next(rng) * total;
        if total <= 0.0 || x < pa {
            // Absorbed: the path ends here.
            out.beta = vec3f(0.0);
            out.t = t;
            return out;
        }
        if x < pa + ps {
            out.beta = b * ss * (total / (mu * ps));
            out.t = t;
            out.scattered = true;
            return out;
        }
        out.beta = b * sn * (total / (mu * pn));
    }
    return out;
}

// Ratio tracking (`ratio_track`), with pbrt-v4's roulette once the
// estimate falls under 0.05.
fn medium_transmittance_grid(p: u32, o: vec3f, d: vec3f, t_max: f32, rng: ptr<function, Stream>) -> vec3f {
    let sigma_t = medium_sigma_a(p) + medium_sigma_s(p);
    let top = max(sigma_t.x, max(sigma_t.y, sigma_t.z));
    var tr = vec3f(1.0);
    if top <= 0.0 {
        return tr;
    }
    var c = grid_collisions(p, o, d, t_max);
    loop {
        if !grid_next_collision(p, &c, top, rng) {
            break;
        }
        tr *= max(vec3f(1.0) - sigma_t * (grid_density(p, o + d * c.t) / c.mu), vec3f(0.0));
        let m = max(tr.x, max(tr.y, tr.z));
        if m <= 0.0 {
            return vec3f(0.0);
        }
        if m < 0.05 {
            if stream_next(rng) < 0.75 {
                return vec3f(0.0);
            }
            tr *= 4.0;
        }
    }
    return tr;
}
