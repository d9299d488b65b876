// The depth-only baseline: world-space positions, one matrix, no instance data and no
// fragment stage. The least a rasterizer can be asked to do to draw a depth map.

@group(0) @binding(0) var<uniform> clip_from_world: mat4x4<f32>;

@vertex
fn vs_baseline(@location(0) world: vec3<f32>) -> @builtin(position) vec4<f32> {
    return clip_from_world * vec4<f32>(world, 1.0);
}
