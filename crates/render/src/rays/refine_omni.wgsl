// A point light's dual paraboloids: only the filter's disagreement marks a pixel
// unsure (refine_classify.wgsl). The footprint test (refine_footprint.wgsl) reads
// texels through a layer's projection, which a paraboloid's warp has none of.
fn paraboloid_map_unsure(world: vec3<f32>, n: vec3<f32>, geometric_n: vec3<f32>, l: vec3<f32>, layer: u32) -> bool {
    return false;
}
