// The `independent` sampler: dimension `dim` of a sample is
// hash4(seed, pixel, index, dim), as in independent.rs. Parameters: the
// seed after hash4_first.
fn sample_1d_independent(p: u32, pixel: u32, index: u32, dim: u32) -> f32 {
    let state = hash4_middle(param_u32(p), pixel, index);
    return unit_float(hash4_last(state, dim));
}
