// The shadow resources a technique may read, declared once for every pass that reads
// them: in the group and from the binding that the pass's generated constants name
// (`ShadowBindings` in techniques/mod.rs): group 2 from binding 0 in Gnomon's
// lighting, mask and moment passes; the host's group from binding 2 in the shadow
// receiver, after its light and camera (receiver.wgsl).
import package::variant::{SHADOW_BINDING, SHADOW_GROUP};

// One layer per cascade (a single layer without cascades).
@group(SHADOW_GROUP) @binding(SHADOW_BINDING) var shadow_map: texture_depth_2d_array;
// Linear comparison sampler, LessEqual: lit when the receiver's depth ≤ the stored one.
@group(SHADOW_GROUP) @binding(SHADOW_BINDING + 1u) var shadow_compare: sampler_comparison;
// The filterable techniques' map: RGBA layers of functions of depth, blurred and
// optionally mipmapped. A 1×1 placeholder for the depth-comparison techniques.
@group(SHADOW_GROUP) @binding(SHADOW_BINDING + 2u) var moment_map: texture_2d_array<f32>;
@group(SHADOW_GROUP) @binding(SHADOW_BINDING + 3u) var moment_sampler: sampler;
// A point light's cube map: the same six layers as `shadow_map`, seen as a cube, each
// texel holding the distance to the light over its range.
@group(SHADOW_GROUP) @binding(SHADOW_BINDING + 4u) var shadow_cube: texture_depth_cube;
// Nearest-texel comparison sampler, LessEqual: the hard lookup on the cube.
@group(SHADOW_GROUP) @binding(SHADOW_BINDING + 5u) var shadow_compare_nearest: sampler_comparison;
// Non-filtering sampler, to gather raw cube depths (PCSS's blocker search).
@group(SHADOW_GROUP) @binding(SHADOW_BINDING + 6u) var shadow_gather: sampler;
