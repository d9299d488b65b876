// `pcf-cross`, a technique defined outside the renderer (tests/custom_technique.rs and
// the library guide's example): the mean of five hardware 2×2 comparison taps, at the
// lookup and one texel away along each axis.
fn sample_shadow(q: ShadowQuery) -> f32 {
    let texel = 1.0 / light.map.resolution;
    var lit = textureSampleCompareLevel(shadow_map, shadow_compare, q.coords.xy, q.layer, q.coords.z);
    let axes = array<vec2<f32>, 4>(vec2<f32>(1.0, 0.0), vec2<f32>(-1.0, 0.0), vec2<f32>(0.0, 1.0), vec2<f32>(0.0, -1.0));
    for (var i = 0u; i < 4u; i++) {
        lit += textureSampleCompareLevel(shadow_map, shadow_compare, q.coords.xy + axes[i] * texel, q.layer, q.coords.z);
    }
    return lit / 5.0;
}
