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
// A point light's cube map: the same six layers as `shadow_map`, seen as a cube, each
// texel holding the distance to the light over its range.
@group(2) @binding(4) var shadow_cube: texture_depth_cube;
// Nearest-texel comparison sampler, LessEqual: the hard lookup on the cube.
@group(2) @binding(5) var shadow_compare_nearest: sampler_comparison;
// Non-filtering sampler, to gather raw cube depths (PCSS's blocker search).
@group(2) @binding(6) var shadow_gather: sampler;
