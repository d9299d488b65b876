// `hard`: Williams (1978). Point-sample the nearest texel and compare once.
import package::techniques::bindings::shadow_map;
import package::techniques::common::ShadowQuery;

fn hard_sample_shadow(q: ShadowQuery) -> f32 {
    let size = vec2<i32>(textureDimensions(shadow_map));
    let texel = clamp(vec2<i32>(floor(q.coords.xy * vec2<f32>(size))), vec2<i32>(0), size - vec2<i32>(1));
    let occluder_depth = textureLoad(shadow_map, texel, q.layer, 0);
    // Lit when the receiver is no farther from the light than the nearest occluder.
    return select(0.0, 1.0, q.coords.z <= occluder_depth);
}
