// The stratified patterns of the trace pass's penumbra rays: the CPU reference's
// (gnomon_reference::sampling, seeded per pixel), so that with the same maps from the
// unit square to the light (`emitter_sample`, passes/light_kinds.wgsl) the GPU
// estimates the very integral the reference does.

// A 32-bit integer hash ("lowbias32"), seeding a pixel's pattern.
fn lowbias32(value: u32) -> u32 {
    var x = value;
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

// A pseudo-random permutation of [0, len), chosen by `pattern` (A. Kensler,
// "Correlated Multi-Jittered Sampling", Pixar Technical Memo 13-01, listing 3).
fn cmj_permute(index: u32, len: u32, pattern: u32) -> u32 {
    var w = len - 1u;
    w |= w >> 1u;
    w |= w >> 2u;
    w |= w >> 4u;
    w |= w >> 8u;
    w |= w >> 16u;
    var i = index;
    loop {
        i ^= pattern;
        i *= 0xe170893du;
        i ^= pattern >> 16u;
        i ^= (i & w) >> 4u;
        i ^= pattern >> 8u;
        i *= 0x0929eb3fu;
        i ^= pattern >> 23u;
        i ^= (i & w) >> 1u;
        i *= 1u | (pattern >> 27u);
        i *= 0x6935fa69u;
        i ^= (i & w) >> 11u;
        i *= 0x74dcb303u;
        i ^= (i & w) >> 2u;
        i *= 0x9e501cc3u;
        i ^= (i & w) >> 2u;
        i *= 0xc860a3dfu;
        i &= w;
        i ^= i >> 5u;
        if i < len {
            break;
        }
    }
    return (i + pattern) % len;
}

// A hashed float in [0, 1) for index `i` of `pattern` (Kensler, listing 4).
fn cmj_float(index: u32, pattern: u32) -> f32 {
    var i = index ^ pattern;
    i ^= i >> 17u;
    i ^= i >> 10u;
    i *= 0xb36534e5u;
    i ^= i >> 12u;
    i ^= i >> 21u;
    i *= 0x93fc4795u;
    i ^= 0xdf6e307fu;
    i ^= i >> 17u;
    i *= 1u | (pattern >> 18u);
    // The top 24 bits: exactly representable, so the float stays below 1.
    return f32(i >> 8u) * (1.0 / 16777216.0);
}

// The m × n grid of `count` samples, m the largest divisor of `count` at most its
// square root: a grid with more cells than samples would leave a stratum of the
// light unsampled, a bias.
fn cmj_grid(count: u32) -> vec2<u32> {
    var m = max(u32(sqrt(f32(count))), 1u);
    // sqrt's rounding may land one above the true root.
    if m * m > count {
        m -= 1u;
    }
    while count % m != 0u {
        m -= 1u;
    }
    return vec2<u32>(m, count / m);
}

// Sample `s` of `count` of the correlated multi-jittered pattern `pattern`, in the
// m × n `grid` of cmj_grid(count): stratified in the grid and in both 1D
// projections (Kensler, listing 6), as the reference's `cmj`.
fn cmj(s: u32, count: u32, grid: vec2<u32>, pattern: u32) -> vec2<f32> {
    let m = grid.x;
    let n = grid.y;
    let p = cmj_permute(s, count, pattern * 0x51633e2du);
    let sx = p % m;
    let sy = p / m;
    let px = cmj_permute(sx, m, pattern * 0x68bc21ebu);
    let py = cmj_permute(sy, n, pattern * 0x02e5be93u);
    let jx = cmj_float(p, pattern * 0x967a889bu);
    let jy = cmj_float(p, pattern * 0x368cc8b7u);
    let u = vec2<f32>(
        (f32(sx) + (f32(py) + jx) / f32(n)) / f32(m),
        (f32(sy) + (f32(px) + jy) / f32(m)) / f32(n),
    );
    return min(u, vec2<f32>(1.0 - 1.1920929e-7));
}
