// What both shadow-ray tracers share (imported by trace_bvh.wgsl, Gnomon's own BVH
// walked by the shader, and trace_query.wgsl, the adapter's acceleration structures
// through ray queries): the alpha test of cut-out casters against their texture's
// alpha at mip 0, as the CPU reference (reference/texture.rs) samples it, and the
// ray's origin moved off its surface by Wächter & Binder's offset (Ray Tracing Gems,
// ch. 6). Each tracer implements `ray_first_hit` under its own name
// (`bvh_ray_first_hit`, `query_ray_first_hit`); the shader's generated module binds
// the one its pass chose (`rays::trace_wgsl`), and `ray_blocked` asks it.
//
// Bindings 4–6 of group TRACE_GROUP, which `trace_wgsl` sets: 3 in the compute
// passes, where 0 and 1 are left to the material texture that passes sharing
// scene_common.wgsl declare, and 1 in the forward lighting pass, beside the camera.
// Binding 2 (and 3) are the tracer's own.
import package::variant::{NO_TEXTURE, TRACE_GROUP, ray_first_hit};

struct AlphaTest {
    uv0: vec2<f32>,
    uv1: vec2<f32>,
    uv2: vec2<f32>,
    // Index into bvh_alpha_textures, or NO_TEXTURE.
    texture: u32,
    base_alpha: f32,
    cutoff: f32,
    _pad: u32,
};

struct AlphaTexture {
    first_word: u32,
    width: u32,
    height: u32,
    // 0 repeat, 1 mirrored repeat, 2 clamp to edge.
    wrap_u: u32,
    wrap_v: u32,
    nearest: u32,
    _pad0: u32,
    _pad1: u32,
};

@group(TRACE_GROUP) @binding(4) var<storage, read> bvh_alpha: array<AlphaTest>;
@group(TRACE_GROUP) @binding(5) var<storage, read> bvh_alpha_textures: array<AlphaTexture>;
@group(TRACE_GROUP) @binding(6) var<storage, read> bvh_alpha_texels: array<u32>;

// A texel index along an axis of `n` texels, wrapped as `mode` says.
fn wrap_texel(i: i32, n: i32, mode: u32) -> i32 {
    if mode == 2u {
        return clamp(i, 0, n - 1);
    }
    if mode == 1u {
        let m = ((i % (2 * n)) + 2 * n) % (2 * n);
        return select(m, 2 * n - 1 - m, m >= n);
    }
    return ((i % n) + n) % n;
}

fn alpha_texel(t: AlphaTexture, x: i32, y: i32) -> f32 {
    let w = i32(t.width);
    let h = i32(t.height);
    let index = u32(wrap_texel(y, h, t.wrap_v) * w + wrap_texel(x, w, t.wrap_u));
    let word = bvh_alpha_texels[t.first_word + index / 4u];
    return f32((word >> (8u * (index % 4u))) & 0xffu) / 255.0;
}

// The texture's alpha at `uv`, nearest or bilinear as its sampler asks, at mip 0
// (texel centres at half-integers), as reference/texture.rs samples it.
fn sample_alpha(t: AlphaTexture, uv: vec2<f32>) -> f32 {
    let size = vec2<f32>(f32(t.width), f32(t.height));
    if t.nearest == 1u {
        let p = floor(uv * size);
        return alpha_texel(t, i32(p.x), i32(p.y));
    }
    let p = uv * size - vec2<f32>(0.5);
    let base = floor(p);
    let f = p - base;
    let x = i32(base.x);
    let y = i32(base.y);
    let top = mix(alpha_texel(t, x, y), alpha_texel(t, x + 1, y), f.x);
    let bottom = mix(alpha_texel(t, x, y + 1), alpha_texel(t, x + 1, y + 1), f.x);
    return mix(top, bottom, f.y);
}

// Whether alpha test `index` (into bvh_alpha) keeps the point of its triangle whose
// barycentric weights of the vertices 0, 1 and 2 are `weights / total`: whether a
// ray that meets the triangle there is blocked. (The watertight test's weights are
// its unnormalized edge functions, over their sum.)
fn alpha_blocks(index: u32, weights: vec3<f32>, total: f32) -> bool {
    let test = bvh_alpha[index];
    let uv = (test.uv0 * weights.x + test.uv1 * weights.y + test.uv2 * weights.z) / total;
    var alpha = test.base_alpha;
    if test.texture != NO_TEXTURE {
        alpha *= sample_alpha(bvh_alpha_textures[test.texture], uv);
    }
    return alpha >= test.cutoff;
}

// Whether a shadow caster blocks the segment from `origin` along the unit
// `direction` before `t_max`.
fn ray_blocked(origin: vec3<f32>, direction: vec3<f32>, t_max: f32) -> bool {
    return ray_first_hit(origin, direction, t_max) >= 0.0;
}

// Moves a surface point off its surface along the geometric normal `n` (facing the
// side the ray leaves from) by a few units in the last place of its coordinates
// (Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray
// Tracing Gems, ch. 6, 2019), as reference/tracer.rs does.
fn offset_ray_origin(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let of_i = vec3<i32>(n * 256.0);
    let p_i = bitcast<vec3<f32>>(bitcast<vec3<i32>>(p) + select(of_i, -of_i, p < vec3<f32>(0.0)));
    return select(p_i, p + n / 65536.0, abs(p) < vec3<f32>(1.0 / 32.0));
}
