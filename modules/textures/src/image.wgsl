// The `image` texture (bitmap.rs, wrap.rs): bilinear or nearest lookups
// with a wrap mode, texel indices computed exactly as Rust's i64 ones.
// Parameters: width, height, filtering (0 bilinear, 1 nearest), wrap mode
// (0 repeat, 1 clamp, 2 mirror), the palette's size k, then k palette
// values and one word per texel (8-bit palette indices of r, g, b in bits
// 0, 8, 16), or, where k = 0, three floats per texel; row-major, top row
// first. The texels are the linear values the Rust side decoded at load.

// Texel coordinates clamped to ±2⁴⁰, NaN read as 0 (texel_coordinate).
fn image_coordinate(c: f32) -> f32 {
    if (bitcast<u32>(c) & 0x7fffffffu) > 0x7f800000u {
        return 0.0;
    }
    return clamp(c, -1099511627776.0, 1099511627776.0);
}

// The Euclidean remainder of the integer-valued x (|x| ≤ 2⁴⁰) by m
// (1 ≤ m ≤ 2²⁴), exactly. (Straight-line code: loops here, inlined at
// every texel fetch, make some shader compilers' loop analysis explode.)
fn image_rem(x: f32, m: u32) -> u32 {
    let a = abs(x);
    var r = 0u;
    if a < 16777216.0 {
        r = u32(a) % m;
    } else {
        // a = mantissa · 2^shift with 1 ≤ shift ≤ 17: r < 2²⁴, so
        // shifting r by up to 8 bits at a time cannot overflow.
        let bits = bitcast<u32>(a);
        var shift = (bits >> 23u) - 150u;
        r = ((bits & 0x7fffffu) | 0x800000u) % m;
        let k0 = min(shift, 8u);
        r = (r << k0) % m;
        shift -= k0;
        let k1 = min(shift, 8u);
        r = (r << k1) % m;
        r = (r << (shift - k1)) % m;
    }
    if x < 0.0 && r != 0u {
        r = m - r;
    }
    return r;
}

// WrapMode::apply of the texel index x + d (x integer-valued, d 0 or 1)
// on an axis of n texels.
fn image_wrap(x: f32, d: u32, n: u32, mode: u32) -> u32 {
    if mode == 1u {
        if x < 0.0 {
            return 0u;
        }
        if x >= f32(n) {
            return n - 1u;
        }
        return min(u32(x) + d, n - 1u);
    }
    if mode == 2u {
        let k = (image_rem(x, 2u * n) + d) % (2u * n);
        return select(k, 2u * n - 1u - k, k >= n);
    }
    return (image_rem(x, n) + d) % n;
}

fn image_texel(p: u32, x: f32, dx: u32, y: f32, dy: u32) -> vec3f {
    let w = param_u32(p);
    let mode = param_u32(p + 3u);
    let k = param_u32(p + 4u);
    let t = image_wrap(y, dy, param_u32(p + 1u), mode) * w + image_wrap(x, dx, w, mode);
    if k == 0u {
        return param_vec3(p + 5u + 3u * t);
    }
    let word = param_u32(p + 5u + k + t);
    return vec3f(
        param_f32(p + 5u + (word & 255u)),
        param_f32(p + 5u + ((word >> 8u) & 255u)),
        param_f32(p + 5u + ((word >> 16u) & 255u)),
    );
}

fn texture_image(p: u32, uv: vec2f) -> vec3f {
    let x = image_coordinate(uv.x * f32(param_u32(p)));
    let y = image_coordinate(uv.y * f32(param_u32(p + 1u)));
    if param_u32(p + 2u) == 1u {
        return image_texel(p, floor(x), 0u, floor(y), 0u);
    }
    let xs = x - 0.5;
    let ys = y - 0.5;
    let x0 = floor(xs);
    let y0 = floor(ys);
    let fx = xs - x0;
    let fy = ys - y0;
    let top = image_texel(p, x0, 0u, y0, 0u) * (1.0 - fx) + image_texel(p, x0, 1u, y0, 0u) * fx;
    let bottom = image_texel(p, x0, 0u, y0, 1u) * (1.0 - fx) + image_texel(p, x0, 1u, y0, 1u) * fx;
    return top * (1.0 - fy) + bottom * fy;
}
