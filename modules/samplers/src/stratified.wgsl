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
