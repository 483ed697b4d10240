// The `sobol` sampler's 1D values, as `Sobol::value_1d` in sobol.rs: the
// first Sobol dimension (the bit reversal) at an Owen-scrambled index,
// itself Owen-scrambled. Parameters: the folded seed.
fn sample_1d_sobol(p: u32, pixel: u32, index: u32, dim: u32) -> f32 {
    let key = hash4_last(hash4_middle(hash4_first(param_u32(p)), pixel, dim), 0xa54ff53au);
    let i = smp_owen_scramble(index, key);
    return unit_float(smp_owen_scramble(reverseBits(i), hash_u32(key)));
}
