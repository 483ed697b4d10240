// The `halton` sampler, as `Halton::value_1d` in halton.rs. Parameters: the
// folded seed, then the 128 prime bases.
//
// The Rust sums the permuted digits d_k · b^-k in f64 while b^k < 2^26; the
// same sum is N / b^K with the integers N = Σ d_k · b^(K-k) < b^K < 2^26,
// which this computes exactly and rounds to the nearest f32 (the f64 sum
// rounds the same way but for a rare ulp).
fn sample_1d_halton(p: u32, pixel: u32, index: u32, dim: u32) -> f32 {
    let base = param_u32(p + 1u + dim % 128u);
    var state = hash4_last(hash4_middle(hash4_first(param_u32(p)), pixel, dim), 0x6a09e667u);
    var rest = index;
    var num = 0u;
    var den = 1u;
    // Digits while b^k < 2^26.
    let limit = 0x3ffffffu / base;
    loop {
        if den > limit {
            break;
        }
        let digit = rest % base;
        rest /= base;
        num = num * base + smp_permute(digit, base, state);
        den *= base;
        state = hash_u32(state ^ (digit * 0x9e3779b9u));
    }
    return min(halton_ratio(num, den), bitcast<f32>(0x3f7fffffu));
}

// num / den (num < den < 2^26) rounded to the nearest f32, ties to even:
// binary long division to 24 significant bits, a round bit and a sticky.
fn halton_ratio(num: u32, den: u32) -> f32 {
    if num == 0u {
        return 0.0;
    }
    var r = num;
    var q = 0u;
    var e = 0i;
    // Leading zero bits of the fraction.
    loop {
        r <<= 1u;
        e += 1;
        if r >= den {
            break;
        }
    }
    // The first significant bit, then 24 more (23 mantissa + round).
    r -= den;
    q = 1u;
    for (var k = 0u; k < 24u; k++) {
        r <<= 1u;
        q <<= 1u;
        if r >= den {
            r -= den;
            q |= 1u;
        }
    }
    // q holds 25 bits; value = q · 2^-(e + 24).
    let round_bit = q & 1u;
    var m = q >> 1u;
    if round_bit == 1u && (r != 0u || (m & 1u) == 1u) {
        m += 1u;
    }
    return ldexp(f32(m), -(e + 23));
}
