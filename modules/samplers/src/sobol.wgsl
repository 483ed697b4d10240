// The `sobol` sampler's 1D values, as `Sobol::value_1d` in sobol.rs: the
// first Sobol dimension (the bit reversal) at an Owen-scrambled index,
// itself Owen-scrambled. Parameters: the folded seed.
fn sample_1d_sobol(p: u32, pixel: u32, index: u32, dim: u32) -> f32 {
    let key = hash4_last(hash4_middle(hash4_first(param_u32(p)), pixel, dim), 0xa54ff53au);
    let i = smp_owen_scramble(index, key);
    return unit_float(smp_owen_scramble(reverseBits(i), hash_u32(key)));
}

// The second Sobol dimension of `index` (sobol.rs `sobol_1`): the XOR of
// the direction numbers v₀ = 2³¹, vᵢ = vᵢ₋₁ ⊕ (vᵢ₋₁ ≫ 1) of the set bits,
// without branches (a shuffled index has random high bits: a loop that
// stopped at the last set bit would diverge across a workgroup).
fn smp_sobol_1(index: u32) -> u32 {
    var x = 0u;
    var v = 0x80000000u;
    for (var bit = 0u; bit < 32u; bit++) {
        x ^= v & (0u - ((index >> bit) & 1u));
        v ^= v >> 1u;
    }
    return x;
}

// The `sobol` sampler's 2D pairs, as `Sobol::value_2d`: the first two
// Sobol dimensions at a shuffled index, each Owen-scrambled.
fn sample_2d_sobol(p: u32, pixel: u32, index: u32, dim: u32) -> vec2f {
    let key = hash4_last(hash4_middle(hash4_first(param_u32(p)), pixel, dim), 0x3c6ef372u);
    let i = smp_owen_scramble(index, key);
    let x = smp_owen_scramble(reverseBits(i), hash_u32(key ^ 1u));
    let y = smp_owen_scramble(smp_sobol_1(i), hash_u32(key ^ 2u));
    return vec2f(unit_float(x), unit_float(y));
}
