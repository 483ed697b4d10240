// The hashed permutations of scramble.rs, shared by the sampler types.

// The element at position `i0` of the permutation of 0..n chosen by `key`
// (Kensler 2013), as `permute` in scramble.rs.
fn smp_permute(i0: u32, n: u32, key: u32) -> u32 {
    if n <= 1u {
        return 0u;
    }
    var w = n - 1u;
    w |= w >> 1u;
    w |= w >> 2u;
    w |= w >> 4u;
    w |= w >> 8u;
    w |= w >> 16u;
    var i = i0;
    loop {
        i ^= key;
        i *= 0xe170893du;
        i ^= key >> 16u;
        i ^= (i & w) >> 4u;
        i ^= key >> 8u;
        i *= 0x0929eb3fu;
        i ^= key >> 23u;
        i ^= (i & w) >> 1u;
        i *= 1u | (key >> 27u);
        i *= 0x6935fa69u;
        i ^= (i & w) >> 11u;
        i *= 0x74dcb303u;
        i ^= (i & w) >> 2u;
        i *= 0x9e501cc3u;
        i ^= (i & w) >> 2u;
        i *= 0xc860a3dfu;
        i &= w;
        i ^= i >> 5u;
        if i < n {
            break;
        }
    }
    return (i + key) % n;
}

// Base-2 Owen scrambling of the 32-bit fraction `x` (Laine–Karras hash with
// Burley's constants on the reversed bits), as `nested_uniform_scramble`.
fn smp_owen_scramble(x0: u32, seed: u32) -> u32 {
    var x = reverseBits(x0) + seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return reverseBits(x);
}
