// `pcf-cross`, a technique defined outside the renderer (tests/custom_technique.rs and
// the library guide's example): the mean of five hardware 2×2 comparison taps, at the
// lookup and `reach` texels away along each axis.

// Its parameters (`CrossParams` in custom_technique.rs), as `light.technique`.
struct CrossParams {
    reach: f32,  // texels from the lookup to each arm's tap
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    _pad3: vec4<u32>,
};

fn sample_shadow(q: ShadowQuery) -> f32 {
    let step = light.technique.reach / light.map.resolution;
    var lit = textureSampleCompareLevel(shadow_map, shadow_compare, q.coords.xy, q.layer, q.coords.z);
    let axes = array<vec2<f32>, 4>(vec2<f32>(1.0, 0.0), vec2<f32>(-1.0, 0.0), vec2<f32>(0.0, 1.0), vec2<f32>(0.0, -1.0));
    for (var i = 0u; i < 4u; i++) {
        lit += textureSampleCompareLevel(shadow_map, shadow_compare, q.coords.xy + axes[i] * step, q.layer, q.coords.z);
    }
    return lit / 5.0;
}
