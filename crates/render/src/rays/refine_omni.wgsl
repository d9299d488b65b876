// A point light's cube or paraboloid map: only the filter's disagreement marks a
// pixel unsure (refine_classify.wgsl); the footprint test of refine_map.wgsl is for 2D layers.
fn map_unsure(world: vec3<f32>, n: vec3<f32>, geometric_n: vec3<f32>, l: vec3<f32>, layer: u32) -> bool {
    return false;
}
