// A pyramid of a shadow map's depths, every layer: each texel of level m covers a
// square of 2^(m+2) × 2^(m+2) map texels and holds two things of it.
// - `pyramid_planes`: a plane through the square's depths and how far below and
//   above it they lie: (depth at the square's centre, depth per map texel along x and
//   y, least residual). Every map texel x in the square stores at least
//   plane(x) + least residual.
// - `pyramid_ranges`: the least and the greatest depth the square holds, exactly.
// The penumbra classification (penumbra_classify.wgsl) reads it to ask of a whole
// square at once whether any caster in it can hide part of a light from a receiver:
// none can where no depth lies in front of the receiver's plane (the plane: a tilted
// floor holds no caster of itself, however wide the square), or where the least depth
// is too deep to reach from the square's distance (the range); as a hierarchical
// Z-buffer bounds occlusion (Greene, Kass & Miller, SIGGRAPH 1993).
// Texels past the map's edge (the pyramid's side is a power of two) hold nothing: a
// plane and a least depth above every depth, a greatest below.
//
// Level 0 reads 4 × 4 map texels (`cs_pyramid_first`); each level after it the 2 × 2
// texels of the one before (`cs_pyramid_next`), whose planes bound the new one's
// residuals: within a child square, its plane differs from the parent's by a linear
// function whose least and greatest lie at the square's corners.

// Level 0's pass reads the map (binding 0), the others the levels before theirs (1
// and 2: every finer level, the last the one before); each writes its own level (3
// and 4).
@group(0) @binding(0) var map_depths: texture_depth_2d_array;
@group(0) @binding(1) var finer_planes: texture_2d_array<f32>;
@group(0) @binding(2) var finer_ranges: texture_2d_array<f32>;
@group(0) @binding(3) var pyramid_planes: texture_storage_2d_array<rgba32float, write>;
@group(0) @binding(4) var pyramid_ranges: texture_storage_2d_array<rg32float, write>;

// How level 0 reads the map's depths (`PyramidParams` in pyramid.rs): a cube face's
// distance over range becomes 1 − near / z, z its distance along the face's axis
// (`cube_depth` in penumbra_classify.wgsl), affine across a plane as a 2D map's
// depth is.
struct PyramidParams {
    cube: u32,
    range: f32,
    near: f32,
    _pad: u32,
};
@group(0) @binding(5) var<uniform> pyramid_params: PyramidParams;

// The depth the pyramid holds of map texel `texel` storing `stored`.
fn pyramid_depth(texel: vec2<u32>, stored: f32, resolution: f32) -> f32 {
    if pyramid_params.cube == 0u {
        return stored;
    }
    let ndc = (vec2<f32>(texel) + vec2<f32>(0.5)) / resolution * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0);
    let z = stored * pyramid_params.range * inverseSqrt(1.0 + dot(ndc, ndc));
    return 1.0 - pyramid_params.near / z;
}

// What a texel holding no depth stores.
const PYRAMID_EMPTY_PLANE: vec4<f32> = vec4<f32>(2.0, 0.0, 0.0, 0.0);
const PYRAMID_EMPTY_RANGE: vec2<f32> = vec2<f32>(2.0, -1.0);

// Map texels along each side of a first-level square.
const FIRST_SIDE: u32 = 4u;

@compute @workgroup_size(8, 8, 1)
fn cs_pyramid_first(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(pyramid_planes);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let map = textureDimensions(map_depths);
    var depths: array<f32, 16>;
    var valid = 0u;
    var sum = 0.0;
    var range = PYRAMID_EMPTY_RANGE;
    for (var k = 0u; k < 16u; k++) {
        let texel = id.xy * FIRST_SIDE + vec2<u32>(k % 4u, k / 4u);
        if all(texel < map) {
            let d = pyramid_depth(texel, textureLoad(map_depths, texel, id.z, 0), f32(map.x));
            depths[k] = d;
            valid |= 1u << k;
            sum += d;
            range = vec2<f32>(min(range.x, d), max(range.y, d));
        }
    }
    if valid == 0u {
        textureStore(pyramid_planes, id.xy, id.z, PYRAMID_EMPTY_PLANE);
        textureStore(pyramid_ranges, id.xy, id.z, vec4<f32>(PYRAMID_EMPTY_RANGE, 0.0, 0.0));
        return;
    }
    // The least-squares plane over the square's 16 texel centres, offsets ±0.5, ±1.5
    // from its centre (Σ u² = 20 along each axis); flat through the mean where the
    // map's edge cuts the square.
    var plane = vec3<f32>(sum / f32(countOneBits(valid)), 0.0, 0.0);
    if valid == 0xffffu {
        var gradient = vec2<f32>(0.0);
        for (var k = 0u; k < 16u; k++) {
            let offset = vec2<f32>(f32(k % 4u), f32(k / 4u)) - vec2<f32>(1.5);
            gradient += offset * depths[k];
        }
        plane = vec3<f32>(plane.x, gradient / 20.0);
    }
    var lowest = 3.0e38;
    for (var k = 0u; k < 16u; k++) {
        if (valid & (1u << k)) != 0u {
            let offset = vec2<f32>(f32(k % 4u), f32(k / 4u)) - vec2<f32>(1.5);
            lowest = min(lowest, depths[k] - (plane.x + dot(plane.yz, offset)));
        }
    }
    textureStore(pyramid_planes, id.xy, id.z, vec4<f32>(plane, lowest));
    textureStore(pyramid_ranges, id.xy, id.z, vec4<f32>(range, 0.0, 0.0));
}

@compute @workgroup_size(8, 8, 1)
fn cs_pyramid_next(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(pyramid_planes);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    // The level before, and its squares' side in map texels.
    let finer = i32(textureNumLevels(finer_planes)) - 1;
    let child_side = f32(FIRST_SIDE << u32(finer));
    var planes: array<vec4<f32>, 4>;
    var centres = vec4<f32>(0.0);
    var full = true;
    var range = PYRAMID_EMPTY_RANGE;
    var any_depth = false;
    for (var k = 0u; k < 4u; k++) {
        let texel = id.xy * 2u + vec2<u32>(k & 1u, k >> 1u);
        planes[k] = textureLoad(finer_planes, texel, id.z, finer);
        let r = textureLoad(finer_ranges, texel, id.z, finer).xy;
        let holds = r.x <= r.y;
        full = full && holds;
        any_depth = any_depth || holds;
        range = vec2<f32>(min(range.x, r.x), max(range.y, r.y));
        centres[k] = planes[k].x;
    }
    if !any_depth {
        textureStore(pyramid_planes, id.xy, id.z, PYRAMID_EMPTY_PLANE);
        textureStore(pyramid_ranges, id.xy, id.z, vec4<f32>(PYRAMID_EMPTY_RANGE, 0.0, 0.0));
        return;
    }
    // Through the children's centres (±child_side / 2 from the new centre), or flat
    // through the middle of the range where some child holds nothing.
    var plane = vec3<f32>(0.5 * (range.x + range.y), 0.0, 0.0);
    if full {
        let right = centres[1] + centres[3] - centres[0] - centres[2];
        let down = centres[2] + centres[3] - centres[0] - centres[1];
        plane = vec3<f32>(0.25 * (centres[0] + centres[1] + centres[2] + centres[3]), vec2<f32>(right, down) / (2.0 * child_side));
    }
    var lowest = 3.0e38;
    for (var k = 0u; k < 4u; k++) {
        let texel = id.xy * 2u + vec2<u32>(k & 1u, k >> 1u);
        let r = textureLoad(finer_ranges, texel, id.z, finer).xy;
        if r.x > r.y {
            continue;
        }
        let offset = (vec2<f32>(f32(k & 1u), f32(k >> 1u)) - vec2<f32>(0.5)) * child_side;
        // The child's plane less the new one over the child's square: least at a
        // corner, half a side from its centre.
        let at_centre = planes[k].x - (plane.x + dot(plane.yz, offset));
        let tilt = abs(planes[k].y - plane.y) + abs(planes[k].z - plane.z);
        lowest = min(lowest, planes[k].w + at_centre - tilt * 0.5 * child_side);
    }
    textureStore(pyramid_planes, id.xy, id.z, vec4<f32>(plane, lowest));
    textureStore(pyramid_ranges, id.xy, id.z, vec4<f32>(range, 0.0, 0.0));
}
