// Points on a light with an area, for the trace pass's penumbra rays: the CPU
// reference's stratified patterns (gnomon_reference::sampling, seeded per pixel) and
// its maps from the unit square to the light (visibility.rs's `Emitter::sample`), so
// the GPU estimates the very integral the reference does.

const TAU: f32 = 6.283185307179586;
const FRAC_PI_4: f32 = 0.7853981633974483;

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

// The unit square to the unit disk, keeping strata compact (Shirley & Chiu, "A Low
// Distortion Map Between Disk and Square", JGT 1997).
fn concentric_disk(u: vec2<f32>) -> vec2<f32> {
    let a = 2.0 * u - vec2<f32>(1.0);
    if a.x == 0.0 && a.y == 0.0 {
        return vec2<f32>(0.0);
    }
    var r: f32;
    var theta: f32;
    if abs(a.x) > abs(a.y) {
        r = a.x;
        theta = FRAC_PI_4 * (a.y / a.x);
    } else {
        r = a.y;
        theta = 2.0 * FRAC_PI_4 - FRAC_PI_4 * (a.x / a.y);
    }
    return r * vec2<f32>(cos(theta), sin(theta));
}

// The unit square to directions within `half_angle` of `axis`, uniform in solid
// angle: cos θ = 1 − u (1 − cos θ_max), φ = 2π v.
fn cone_direction(u: vec2<f32>, axis: vec3<f32>, half_angle: f32) -> vec3<f32> {
    let cos_theta = 1.0 - u.x * (1.0 - cos(half_angle));
    let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    let phi = TAU * u.y;
    let basis = orthonormal_pair(axis);
    return normalize(axis * cos_theta + (basis[0] * cos(phi) + basis[1] * sin(phi)) * sin_theta);
}

// The weight of a penumbra ray of length `len` in the light's visibility, relative to
// its other rays: under an inverse-square falloff, each point of a spot's disk is a
// point light of that falloff, so nearer points count for more (the reference's
// `Emitter::weight`). A sphere's rays are uniform in the solid angle it subtends,
// which already makes its light fall off as the inverse square of the distance, so
// they count alike, as do every ray of a constant light's and a sun's.
fn light_sample_weight(len: f32) -> f32 {
    if light.emitter.kind != LIGHT_SPOT {
        return 1.0;
    }
    return distance_falloff(light.emitter.falloff, light.emitter.falloff_window, len);
}

// A shadow ray from `p` toward the point `u` of the light's area: its direction, and
// its length (past every caster for a sun). `light.emitter.size` is the tangent of the
// sun's angular radius, or the spot's disk or point's sphere radius.
fn light_sample(p: vec3<f32>, u: vec2<f32>) -> vec4<f32> {
    if light.emitter.kind == LIGHT_SUN {
        return vec4<f32>(cone_direction(u, -light.emitter.direction, atan(light.emitter.size)), 3.0e38);
    }
    if light.emitter.kind == LIGHT_SPOT {
        // A disk facing along the spot's axis.
        let basis = orthonormal_pair(light.emitter.direction);
        let q = concentric_disk(u) * light.emitter.size;
        let to = light.emitter.position + basis[0] * q.x + basis[1] * q.y - p;
        let len = length(to);
        return vec4<f32>(to / len, len);
    }
    // A sphere of uniform radiance: uniform over the cone it subtends, which is
    // uniform over its visible area; the ray ends where it enters the sphere.
    let to = light.emitter.position - p;
    let dist = length(to);
    let axis = to / dist;
    let radius = light.emitter.size;
    if radius >= dist {
        return vec4<f32>(axis, dist);
    }
    let d = cone_direction(u, axis, asin(radius / dist));
    let along = dot(d, to);
    let entry = along - sqrt(max(radius * radius - (dist * dist - along * along), 0.0));
    return vec4<f32>(d, max(entry, 0.0));
}
