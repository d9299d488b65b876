// A min-max pyramid of a shadow map's depths, every layer: level m holds, in each
// texel, the least and the greatest depth of the 2^(m+2) × 2^(m+2) map texels it
// covers (red and green). The penumbra classification (penumbra_classify.wgsl)
// reads it to ask "is any caster in this region?" and "does one caster cover this
// region?" of a whole square of the map in one load, as a hierarchical Z-buffer
// does for occlusion (Greene, Kass & Miller, "Hierarchical Z-buffer visibility",
// SIGGRAPH 1993). Texels past the map's edge (the pyramid's side is a power of two)
// hold nothing: a least depth above every depth and a greatest below.
//
// Level 0 reads 4 × 4 map texels (`cs_pyramid_first`); each level after it the 2 × 2
// texels of the one before (`cs_pyramid_next`).

// Level 0's pass reads the map (binding 0), the others the level before (1); each
// writes its own level (2).
@group(0) @binding(0) var map_depths: texture_depth_2d_array;
@group(0) @binding(1) var finer: texture_2d_array<f32>;
@group(0) @binding(2) var coarser: texture_storage_2d_array<rg32float, write>;

// What a texel holding no depth stores.
const PYRAMID_EMPTY: vec2<f32> = vec2<f32>(2.0, -1.0);

fn pyramid_widen(range: vec2<f32>, depth: f32) -> vec2<f32> {
    return vec2<f32>(min(range.x, depth), max(range.y, depth));
}

@compute @workgroup_size(8, 8, 1)
fn cs_pyramid_first(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(coarser);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let map = textureDimensions(map_depths);
    var range = PYRAMID_EMPTY;
    for (var j = 0u; j < 4u; j++) {
        for (var i = 0u; i < 4u; i++) {
            let texel = id.xy * 4u + vec2<u32>(i, j);
            if all(texel < map) {
                range = pyramid_widen(range, textureLoad(map_depths, texel, id.z, 0));
            }
        }
    }
    textureStore(coarser, id.xy, id.z, vec4<f32>(range, 0.0, 0.0));
}

@compute @workgroup_size(8, 8, 1)
fn cs_pyramid_next(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(coarser);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    var range = PYRAMID_EMPTY;
    for (var k = 0u; k < 4u; k++) {
        let texel = id.xy * 2u + vec2<u32>(k & 1u, k >> 1u);
        let r = textureLoad(finer, texel, id.z, 0).xy;
        range = vec2<f32>(min(range.x, r.x), max(range.y, r.y));
    }
    textureStore(coarser, id.xy, id.z, vec4<f32>(range, 0.0, 0.0));
}
