// The camera's depth buffer, binding 0 of the depth reduction's group, which both of
// its passes read: the depth range (depth_reduce.wgsl) and the cascades' sample
// bounds (sample_bounds.wgsl).

@group(0) @binding(0) var depth_buffer: texture_depth_2d;
