// The `stratified` sampler's 1D values, as `Stratified::value_1d` in
// stratified.rs. Parameters: the folded seed, spp.
fn sample_1d_stratified(p: u32, pixel: u32, index: u32, dim: u32) -> f32 {
    let seed = param_u32(p);
    let spp = param_u32(p + 1u);
    let key = hash4_last(hash4_middle(hash4_first(seed), pixel, dim), index / spp);
    let s = smp_permute(index % spp, spp, key);
    let jitter = unit_float(hash_u32(key ^ (index * 0x2c1b3c6du)));
    // The largest f32 below 1.
    return min((f32(s) + jitter) / f32(spp), bitcast<f32>(0x3f7fffffu));
}

// The `stratified` sampler's 2D pairs, as `Stratified::value_2d`: a
// multi-jittered cols × rows pattern. Parameters: the folded seed, spp,
// cols, rows.
fn sample_2d_stratified(p: u32, pixel: u32, index: u32, dim: u32) -> vec2f {
    let seed = param_u32(p);
    let spp = param_u32(p + 1u);
    let m = param_u32(p + 2u);
    let n = param_u32(p + 3u);
    let key = hash4_last(hash4_middle(hash4_first(seed), pixel, dim | 0x80000000u), index / spp);
    let s = smp_permute(index % spp, spp, key);
    let col = s % m;
    let row = s / m;
    // Fine strata: distinct x sub-strata within a column, y within a row.
    let sx = smp_permute(row, n, hash_u32(key ^ (col * 0xa511e9b3u)));
    let sy = smp_permute(col, m, hash_u32(key ^ (row * 0x63d83595u) ^ 0x68e31da4u));
    let jx = unit_float(hash_u32(key ^ (s * 0xa399d265u)));
    let jy = unit_float(hash_u32(key ^ (s * 0x711ad6a5u) ^ 0x5bd1e995u));
    let x = (f32(col) + (f32(sx) + jx) / f32(n)) / f32(m);
    let y = (f32(row) + (f32(sy) + jy) / f32(m)) / f32(n);
    // The largest f32 below 1.
    let below_one = bitcast<f32>(0x3f7fffffu);
    return vec2f(min(x, below_one), min(y, below_one));
}
