// The `sobol` sampler's 1D values, as `Sobol::value_1d` in sobol.rs: the
// first Sobol dimension (the bit reversal) at an Owen-scrambled index,
// itself Owen-scrambled. Parameters: the folded seed.
fn sample_1d_sobol(p: u32, pixel: u32, index: u32, dim: u32) -> f32 {
    let key = hash4_last(hash4_middle(hash4_first(param_u32(p)), pixel, dim), 0xa54ff53au);
    let i = smp_owen_scramble(index, key);
    return unit_float(smp_owen_scramble(reverseBits(i), hash_u32(key)));
}

// The second Sobol dimension of `index`, bit-reversed (sobol.rs
// `sobol_1_reversed`): Pascal's triangle mod 2 as five superset-XOR steps.
fn smp_sobol_1_reversed(index: u32) -> u32 {
    var w = index;
    w ^= (w >> 1u) & 0x55555555u;
    w ^= (w >> 2u) & 0x33333333u;
    w ^= (w >> 4u) & 0x0f0f0f0fu;
    w ^= (w >> 8u) & 0x00ff00ffu;
    w ^= w >> 16u;
    return w;
}

// The `sobol` sampler's 2D pairs, as `Sobol::value_2d`: the first two
// Sobol dimensions at a shuffled index, each Owen-scrambled.
fn sample_2d_sobol(p: u32, pixel: u32, index: u32, dim: u32) -> vec2f {
    let key = hash4_last(hash4_middle(hash4_first(param_u32(p)), pixel, dim), 0x3c6ef372u);
    let i = smp_owen_scramble(index, key);
    let x = smp_owen_scramble(reverseBits(i), hash_u32(key ^ 1u));
    let y = smp_owen_scramble(reverseBits(smp_sobol_1_reversed(i)), hash_u32(key ^ 2u));
    return vec2f(unit_float(x), unit_float(y));
}
