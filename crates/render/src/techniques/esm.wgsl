// Exponential shadow maps (Annen, Mertens, Seidel, Flerackers & Kautz, "Exponential
// shadow maps", GI 2008): the depth test H(d_occluder − d) is approximated by
// exp(c·(d_occluder − d)), clamped to 1, which is separable: filtering exp(c·d_occluder)
// filters the test. The map stores d itself and every filter (blur, mipmaps and the
// bilinear lookup here) averages in log space, log Σ w·exp(c·d) = c·d_max + log Σ
// w·exp(c·(d − d_max)), so large c cannot overflow (Salvi, "Rendering filtered
// shadows with exponential shadow maps", ShaderX6 2008).
//
// Its parameters (`EsmParams` in esm.rs).
import package::passes::light_binding::light;
import package::techniques::bindings::moment_map;
import package::techniques::common::ShadowQuery;
import package::techniques::filterable::receiver_moment_depth;

struct EsmParams {
    exponent: f32,  // c
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    _pad3: vec4<u32>,
};

fn esm_encode_moments(d: f32, layer: u32) -> vec4<f32> {
    return vec4<f32>(d, 0.0, 0.0, 0.0);
}

fn esm_sample_shadow(q: ShadowQuery) -> f32 {
    let c = light.technique.exponent;
    let dims = vec2<i32>(textureDimensions(moment_map));
    let x = q.coords.xy * vec2<f32>(dims) - vec2<f32>(0.5);
    let base = floor(x);
    let f = x - base;
    let i = vec2<i32>(base);
    let hi = dims - vec2<i32>(1);
    let layer = q.layer * light.map.moment_layers;
    let d00 = textureLoad(moment_map, clamp(i, vec2<i32>(0), hi), layer, 0).x;
    let d10 = textureLoad(moment_map, clamp(i + vec2<i32>(1, 0), vec2<i32>(0), hi), layer, 0).x;
    let d01 = textureLoad(moment_map, clamp(i + vec2<i32>(0, 1), vec2<i32>(0), hi), layer, 0).x;
    let d11 = textureLoad(moment_map, clamp(i + vec2<i32>(1, 1), vec2<i32>(0), hi), layer, 0).x;
    let top = max(max(d00, d10), max(d01, d11));
    let sum = (1.0 - f.x) * (1.0 - f.y) * exp(c * (d00 - top)) + f.x * (1.0 - f.y) * exp(c * (d10 - top))
        + (1.0 - f.x) * f.y * exp(c * (d01 - top)) + f.x * f.y * exp(c * (d11 - top));
    let occluder = top + log(sum) / c;
    return clamp(exp(c * (occluder - receiver_moment_depth(q))), 0.0, 1.0);
}
