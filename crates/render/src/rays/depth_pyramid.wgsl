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
// Level 0 reads 4 × 4 map texels, in four gathers (`cs_pyramid_first`); each level
// after it the 2 × 2 texels of the one before (`cs_pyramid_next`), whose planes bound
// the new one's residuals: within a child square, its plane differs from the
// parent's by a linear function whose least and greatest lie at the square's
// corners.

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
// Nearest, clamped: level 0 reads the map 2 × 2 texels at a time, by
// `textureGather`, a quarter of the calls 16 loads would make.
@group(0) @binding(6) var map_gather: sampler;

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


// A first-level square's 2 × 2 quarter `q` (0 to 3: x + 2y), read by one gather:
// its texels' depths as the pyramid holds them, in the order (0, 0), (1, 0), (0, 1),
// (1, 1), their offsets from the square's centre, and which of them lie inside the
// map and which a caster covers (bits 0 to 3 in that order). Held in vectors, not an
// array a loop indexes: on lavapipe such an array lives in memory, each access a
// gather and a scatter, and level 0 cost 75-90 ms of a moving spot's frame so.
struct Quarter {
    depths: vec4<f32>,
    x: vec4<f32>,
    y: vec4<f32>,
    inside: u32,
    present: u32,
};

fn read_quarter(id: vec3<u32>, q: u32, map: vec2<u32>) -> Quarter {
    let corner = id.xy * FIRST_SIDE + 2u * vec2<u32>(q & 1u, q >> 1u);
    // Nearest texels round the point between the four centres; past the map's edge
    // the sampler clamps, and those texels are left out.
    let g = textureGather(map_depths, map_gather, (vec2<f32>(corner) + vec2<f32>(1.0)) / vec2<f32>(map), id.z);
    // The gather orders them (0, 1), (1, 1), (1, 0), (0, 0).
    let stored = vec4<f32>(g.w, g.z, g.x, g.y);
    let resolution = f32(map.x);
    let depths = vec4<f32>(
        pyramid_depth(corner, stored.x, resolution),
        pyramid_depth(corner + vec2<u32>(1u, 0u), stored.y, resolution),
        pyramid_depth(corner + vec2<u32>(0u, 1u), stored.z, resolution),
        pyramid_depth(corner + vec2<u32>(1u, 1u), stored.w, resolution),
    );
    let inside_x = vec4<bool>(corner.x < map.x, corner.x + 1u < map.x, corner.x < map.x, corner.x + 1u < map.x);
    let inside_y = vec4<bool>(corner.y < map.y, corner.y < map.y, corner.y + 1u < map.y, corner.y + 1u < map.y);
    let inside = inside_x & inside_y;
    let present = inside & (stored < vec4<f32>(MAP_CLEARED));
    let base = vec2<f32>(2.0 * f32(q & 1u), 2.0 * f32(q >> 1u)) - vec2<f32>(1.5);
    return Quarter(
        depths,
        vec4<f32>(0.0, 1.0, 0.0, 1.0) + base.x,
        vec4<f32>(0.0, 0.0, 1.0, 1.0) + base.y,
        mask_bits(inside),
        mask_bits(present),
    );
}

// A quarter's four flags as its bits 0 to 3, and back.
fn mask_bits(b: vec4<bool>) -> u32 {
    return dot(select(vec4<u32>(0u), vec4<u32>(1u, 2u, 4u, 8u), b), vec4<u32>(1u));
}

fn bits_set(bits: u32) -> vec4<bool> {
    return (vec4<u32>(bits) & vec4<u32>(1u, 2u, 4u, 8u)) != vec4<u32>(0u);
}

// The least-squares normal equations' sums over the covered texels: their count,
// offsets `su`, products `suu` (Σu², Σuv, Σv²), depths less a reference `sd`, and
// offsets times those depths `sud` (`solved_plane`).
struct PlaneSums {
    n: f32,
    su: vec2<f32>,
    suu: vec3<f32>,
    sd: f32,
    sud: vec2<f32>,
};

const NO_SUMS: PlaneSums = PlaneSums(0.0, vec2<f32>(0.0), vec3<f32>(0.0), 0.0, vec2<f32>(0.0));

// `sums` with a quarter's covered texels added.
fn add_quarter(sums: PlaneSums, q: Quarter, reference: f32) -> PlaneSums {
    let m = select(vec4<f32>(0.0), vec4<f32>(1.0), bits_set(q.present));
    let d = (q.depths - vec4<f32>(reference)) * m;
    let one = vec4<f32>(1.0);
    return PlaneSums(
        sums.n + dot(m, one),
        sums.su + vec2<f32>(dot(q.x, m), dot(q.y, m)),
        sums.suu + vec3<f32>(dot(q.x * q.x, m), dot(q.x * q.y, m), dot(q.y * q.y, m)),
        sums.sd + dot(d, one),
        sums.sud + vec2<f32>(dot(q.x, d), dot(q.y, d)),
    );
}

// The least residual below `plane` of a quarter's covered texels (3.0e38 where none).
fn quarter_lowest(q: Quarter, plane: vec3<f32>) -> f32 {
    let residual = q.depths - (vec4<f32>(plane.x) + plane.y * q.x + plane.z * q.y);
    let r = select(vec4<f32>(3.0e38), residual, bits_set(q.present));
    return min(min(r.x, r.y), min(r.z, r.w));
}

// A quarter's first covered texel's depth (any, where none is).
fn quarter_first(q: Quarter) -> f32 {
    return q.depths[firstTrailingBit(q.present) & 3u];
}

// A quarter's least and greatest depth over its texels inside the map, with `range`.
fn quarter_range(q: Quarter, range: vec2<f32>) -> vec2<f32> {
    let inside = bits_set(q.inside);
    let low = select(vec4<f32>(range.x), q.depths, inside);
    let high = select(vec4<f32>(range.y), q.depths, inside);
    return vec2<f32>(
        min(range.x, min(min(low.x, low.y), min(low.z, low.w))),
        max(range.y, max(max(high.x, high.y), max(high.z, high.w))),
    );
}

// The plane (depth at the offsets' origin, per texel along x and y) solving the
// least-squares normal equations of depths about `reference` from their sums, by
// Cramer's rule; `degenerate` where the offsets lie on a line.
fn solved_plane(sums: PlaneSums, reference: f32, degenerate: vec3<f32>) -> vec3<f32> {
    let n = sums.n;
    let su = sums.su;
    let suu = sums.suu;
    let sd = sums.sd;
    let sud = sums.sud;
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
    var sums = NO_SUMS;
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
        sums = PlaneSums(
            sums.n + 1.0,
            sums.su + o,
            sums.suu + vec3<f32>(o.x * o.x, o.x * o.y, o.y * o.y),
            sums.sd + d,
            sums.sud + o * d,
        );
    }
    return solved_plane(sums, reference, flat);
}

@compute @workgroup_size(8, 8, 1)
fn cs_pyramid_first(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(pyramid_planes);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let map = textureDimensions(map_depths);
    let q0 = read_quarter(id, 0u, map);
    let q1 = read_quarter(id, 1u, map);
    let q2 = read_quarter(id, 2u, map);
    let q3 = read_quarter(id, 3u, map);
    let inside = q0.inside | q1.inside | q2.inside | q3.inside;
    let present = q0.present | (q1.present << 4u) | (q2.present << 8u) | (q3.present << 12u);
    let range = quarter_range(q3, quarter_range(q2, quarter_range(q1, quarter_range(q0, PYRAMID_EMPTY_RANGE))));
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
    // The sums are taken about a covered texel's depth, so that they keep the
    // depths' precision.
    let reference = select(
        select(select(quarter_first(q3), quarter_first(q2), q2.present != 0u), quarter_first(q1), q1.present != 0u),
        quarter_first(q0),
        q0.present != 0u,
    );
    let sums = add_quarter(add_quarter(add_quarter(add_quarter(NO_SUMS, q0, reference), q1, reference), q2, reference), q3, reference);
    // Flat through the mean where the covered texels lie on a line or fewer.
    let flat = vec3<f32>(reference + sums.sd / sums.n, 0.0, 0.0);
    var plane = solved_plane(sums, reference, flat);
    if countOneBits(present) < 16u && !(abs(plane.y) > 0.0 || abs(plane.z) > 0.0) {
        plane = widened_plane(id, plane, reference);
    }
    let lowest = min(min(quarter_lowest(q0, plane), quarter_lowest(q1, plane)), min(quarter_lowest(q2, plane), quarter_lowest(q3, plane)));
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
