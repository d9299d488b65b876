// The shadow resources a technique may read (group 2 of the lighting pass; the
// moment-map encoding pass binds the same declarations).

// One layer per cascade (a single layer without cascades).
@group(2) @binding(0) var shadow_map: texture_depth_2d_array;
// Linear comparison sampler, LessEqual: lit when the receiver's depth ≤ the stored one.
@group(2) @binding(1) var shadow_compare: sampler_comparison;
// The filterable techniques' map: RGBA layers of functions of depth, blurred and
// optionally mipmapped. A 1×1 placeholder for the depth-comparison techniques.
@group(2) @binding(2) var moment_map: texture_2d_array<f32>;
@group(2) @binding(3) var moment_sampler: sampler;
