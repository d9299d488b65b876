// A pyramid of a shadow map's depths, every layer: each texel of level m covers a
// square of 2^(m+2) × 2^(m+2) map texels and holds two things of it.
// - `pyramid_planes`: a plane through the square's depths and how far below and
//   above it they lie: (depth at the square's centre, depth per map texel along x and
//   y, least residual). Every map texel x in the square that a caster covers stores
//   at least plane(x) + least residual.
// - `pyramid_ranges`: the least and the greatest depth the square holds, exactly.
// The penumbra classification (penumbra_classify.wgsl) reads it to ask of a whole
// square at once whether any caster in it can hide part of a light from a receiver:
// none can where no depth lies in front of the receiver's plane (the plane: a tilted
// floor holds no caster of itself, however wide the square), or where the least depth
// is too deep to reach from the square's distance (the range); as a hierarchical
// Z-buffer bounds occlusion (Greene, Kass & Miller, SIGGRAPH 1993).
// Texels past the map's edge (the pyramid's side is a power of two) hold nothing: a
// plane and a least depth above every depth, a greatest below. Map texels no caster
// covers (`MAP_CLEARED`) are left out of the planes, not the ranges.
//
// Level 0 reads 4 × 4 map texels (`cs_pyramid_first`); each level after it the 2 × 2
// texels of the one before (`cs_pyramid_next`), whose planes bound the new one's
// residuals: within a child square, its plane differs from the parent's by a linear
// function whose least and greatest lie at the square's corners.

import package::constants::MAP_CLEARED;

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


// The least-squares plane (depth at the square's centre, per texel along x and y)
// through the depths `depths` at the texels `present` (bit k: texel k of the 4 × 4,
// at offsets ±0.5, ±1.5 from the centre), from the normal equations by Cramer's rule,
// about the first present depth `reference` so that their sums keep the depths'
// precision. Flat through the mean where the texels lie on a line or fewer.
fn first_level_plane(depths: array<f32, 16>, present: u32, reference: f32) -> vec3<f32> {
    var n = 0.0;
    var su = vec2<f32>(0.0);
    var suu = vec3<f32>(0.0); // Σu², Σuv, Σv²
    var sd = 0.0;
    var sud = vec2<f32>(0.0);
    for (var k = 0u; k < 16u; k++) {
        if (present & (1u << k)) == 0u {
            continue;
        }
        let o = vec2<f32>(f32(k % 4u), f32(k / 4u)) - vec2<f32>(1.5);
        let d = depths[k] - reference;
        n += 1.0;
        su += o;
        suu += vec3<f32>(o.x * o.x, o.x * o.y, o.y * o.y);
        sd += d;
        sud += o * d;
    }
    return solved_plane(n, su, suu, sd, sud, reference, vec3<f32>(reference + sd / n, 0.0, 0.0));
}

// The plane (depth at the offsets' origin, per texel along x and y) solving the
// least-squares normal equations of `n` depths about `reference`, from their sums
// (offsets `su`, their products `suu` = Σu², Σuv, Σv², depths `sd`, offsets times
// depths `sud`) by Cramer's rule; `degenerate` where the offsets lie on a line.
fn solved_plane(n: f32, su: vec2<f32>, suu: vec3<f32>, sd: f32, sud: vec2<f32>, reference: f32, degenerate: vec3<f32>) -> vec3<f32> {
    let det = n * (suu.x * suu.z - suu.y * suu.y) - su.x * (su.x * suu.z - suu.y * su.y) + su.y * (su.x * suu.y - suu.x * su.y);
    if !(abs(det) > 1e-3) {
        return degenerate;
    }
    let p0 = sd * (suu.x * suu.z - suu.y * suu.y) - su.x * (sud.x * suu.z - suu.y * sud.y) + su.y * (sud.x * suu.y - suu.x * sud.y);
    let gx = n * (sud.x * suu.z - suu.y * sud.y) - sd * (su.x * suu.z - suu.y * su.y) + su.y * (su.x * sud.y - sud.x * su.y);
    let gy = n * (suu.x * sud.y - sud.x * suu.y) - su.x * (su.x * sud.y - sud.x * su.y) + sd * (su.x * suu.y - suu.x * su.y);
    return vec3<f32>(reference + p0 / det, gx / det, gy / det);
}

// Map texels along each side of the window `widened_plane` fits over.
const WIDE_SIDE: u32 = 8u;

// Where a first-level square's covered texels lie on a line or fewer (a caster's
// edge, a wire), the least-squares plane through the covered texels of the 8 × 8
// window about it (`WIDE_SIDE`), or `flat` where those too lie on a line: any plane
// bounds the square's depths once its least residual is taken over them, but one
// flat across a steep floor's edge would differ from its neighbours' by the floor's
// slope across a whole square, and every coarser level's residual would inherit it.
fn widened_plane(id: vec3<u32>, flat: vec3<f32>, reference: f32) -> vec3<f32> {
    let map = textureDimensions(map_depths);
    let origin = vec2<i32>(id.xy * FIRST_SIDE) - vec2<i32>(i32(WIDE_SIDE - FIRST_SIDE) / 2);
    // Offsets from the square's centre.
    let centre = vec2<f32>(0.5 * f32(FIRST_SIDE) - 0.5);
    var n = 0.0;
    var su = vec2<f32>(0.0);
    var suu = vec3<f32>(0.0);
    var sd = 0.0;
    var sud = vec2<f32>(0.0);
    for (var k = 0u; k < WIDE_SIDE * WIDE_SIDE; k++) {
        let texel = origin + vec2<i32>(i32(k % WIDE_SIDE), i32(k / WIDE_SIDE));
        if any(texel < vec2<i32>(0)) || any(vec2<u32>(texel) >= map) {
            continue;
        }
        let stored = textureLoad(map_depths, vec2<u32>(texel), id.z, 0);
        if stored >= MAP_CLEARED {
            continue;
        }
        let o = vec2<f32>(texel - vec2<i32>(id.xy * FIRST_SIDE)) - centre;
        let d = pyramid_depth(vec2<u32>(texel), stored, f32(map.x)) - reference;
        n += 1.0;
        su += o;
        suu += vec3<f32>(o.x * o.x, o.x * o.y, o.y * o.y);
        sd += d;
        sud += o * d;
    }
    return solved_plane(n, su, suu, sd, sud, reference, flat);
}

@compute @workgroup_size(8, 8, 1)
fn cs_pyramid_first(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(pyramid_planes);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let map = textureDimensions(map_depths);
    var depths: array<f32, 16>;
    // Texels inside the map, and of those the ones a caster covers.
    var inside = 0u;
    var present = 0u;
    var reference = 0.0;
    var range = PYRAMID_EMPTY_RANGE;
    for (var k = 0u; k < 16u; k++) {
        let texel = id.xy * FIRST_SIDE + vec2<u32>(k % 4u, k / 4u);
        if all(texel < map) {
            let stored = textureLoad(map_depths, texel, id.z, 0);
            let d = pyramid_depth(texel, stored, f32(map.x));
            depths[k] = d;
            inside |= 1u << k;
            range = vec2<f32>(min(range.x, d), max(range.y, d));
            if stored < MAP_CLEARED {
                if present == 0u {
                    reference = d;
                }
                present |= 1u << k;
            }
        }
    }
    if inside == 0u {
        textureStore(pyramid_planes, id.xy, id.z, PYRAMID_EMPTY_PLANE);
        textureStore(pyramid_ranges, id.xy, id.z, vec4<f32>(PYRAMID_EMPTY_RANGE, 0.0, 0.0));
        return;
    }
    if present == 0u {
        textureStore(pyramid_planes, id.xy, id.z, PYRAMID_EMPTY_PLANE);
        textureStore(pyramid_ranges, id.xy, id.z, vec4<f32>(range, 0.0, 0.0));
        return;
    }
    var plane = first_level_plane(depths, present, reference);
    if countOneBits(present) < 16u && !(abs(plane.y) > 0.0 || abs(plane.z) > 0.0) {
        plane = widened_plane(id, plane, reference);
    }
    var lowest = 3.0e38;
    for (var k = 0u; k < 16u; k++) {
        if (present & (1u << k)) != 0u {
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
    // Children that hold a plane (a caster covers some of their texels).
    var planed = 0u;
    var range = PYRAMID_EMPTY_RANGE;
    for (var k = 0u; k < 4u; k++) {
        let texel = id.xy * 2u + vec2<u32>(k & 1u, k >> 1u);
        planes[k] = textureLoad(finer_planes, texel, id.z, finer);
        let r = textureLoad(finer_ranges, texel, id.z, finer).xy;
        range = vec2<f32>(min(range.x, r.x), max(range.y, r.y));
        if planes[k].x < PYRAMID_EMPTY_PLANE.x {
            planed |= 1u << k;
        }
    }
    if planed == 0u {
        textureStore(pyramid_planes, id.xy, id.z, PYRAMID_EMPTY_PLANE);
        textureStore(pyramid_ranges, id.xy, id.z, vec4<f32>(range, 0.0, 0.0));
        return;
    }
    // Through the children's centres (±child_side / 2 from the new centre) where all
    // four hold one; else the first that does, carried to the new centre: a plane cut
    // by the map's edge or by a gap stays that plane.
    var plane: vec3<f32>;
    if planed == 0xfu {
        let c = vec4<f32>(planes[0].x, planes[1].x, planes[2].x, planes[3].x);
        let right = c[1] + c[3] - c[0] - c[2];
        let down = c[2] + c[3] - c[0] - c[1];
        plane = vec3<f32>(0.25 * (c[0] + c[1] + c[2] + c[3]), vec2<f32>(right, down) / (2.0 * child_side));
    } else {
        let k = firstTrailingBit(planed);
        let offset = (vec2<f32>(f32(k & 1u), f32(k >> 1u)) - vec2<f32>(0.5)) * child_side;
        plane = vec3<f32>(planes[k].x - dot(planes[k].yz, offset), planes[k].yz);
    }
    var lowest = 3.0e38;
    for (var k = 0u; k < 4u; k++) {
        if (planed & (1u << k)) == 0u {
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
