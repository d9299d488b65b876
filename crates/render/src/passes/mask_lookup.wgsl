// The lighting pass's visibility on the mask path: what the shadow-mask pass stored
// for this pixel and light (shadow_mask.wgsl), read instead of looked up again.

// This light's layer of the mask: visibility + 2 × the shadow-map layer that shaded it
// (+ TRACED_LAYER_FLAG where rays decided the pixel, under the traced debug view).
@group(2) @binding(9) var shadow_mask: texture_2d<f32>;

// `pixel_visibility` on the mask path (passes/wgsl_interfaces.rs).
fn mask_pixel_visibility(
    world: vec3<f32>,
    n: vec3<f32>,
    geometric_n: vec3<f32>,
    l: vec3<f32>,
    cone: f32,
    world_dx: vec3<f32>,
    world_dy: vec3<f32>,
    pixel: vec2<f32>,
    view_depth: f32,
) -> vec2<f32> {
    let packed = textureLoad(shadow_mask, vec2<i32>(pixel), 0).x;
    let layer = floor(packed * 0.5);
    return vec2<f32>(packed - 2.0 * layer, layer);
}
