// Shadow pass: depth only, from the light. No fragment stage, so the cheapest path
// the rasterizer has; bias and culling come from the pipeline state.

@vertex
fn vs_shadow(v: VertexIn, @builtin(instance_index) instance_index: u32) -> @builtin(position) vec4<f32> {
    let inst = instances[instance_index];
    let world = inst.world_from_object * vec4<f32>(v.position, 1.0);
    return light.clip_from_world * world;
}
