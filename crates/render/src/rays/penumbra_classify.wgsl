// The mask pass's answer for a light with an area on a 2D map (a sun's map or
// cascades, a spot's map) or a point light's cube, when its penumbrae are traced: lit, where no caster the
// map holds can hide any part of the light from the receiver; in umbra, where one
// caster the map holds hides all of it; unsure everywhere else, which the trace
// pass then answers with a penumbra beam (penumbra_beam.wgsl). No technique's
// estimate is made: under a light with an area the rays decide every pixel the map
// cannot, so the map only has to say where they need not run.
//
// It reads the map's min-max pyramid (depth_pyramid.wgsl) in squares that double
// around the receiver, so that a search over the cone's whole reach costs a load per
// level, and a square's least depth bounds every caster in it: the answer "no
// caster" is never given where the map holds one (a test holds the pyramid to
// that).
//
// A caster at stored depth s, r texels to the side of the receiver, can hide part of
// the light only if the cone from the receiver to the light is at least r texels wide
// at the caster's distance: the cone narrows from `emitter_cone_radius(d, 0)` at the
// light to nothing at the receiver, linearly, and a texel widens linearly with
// distance (`texel_world_size_at`), so the farthest a caster r texels aside may
// stand from the light is one division (`farthest_reaching`), and the deepest depth
// it may store one conversion (`deepest_reaching`).
//
// Umbra, when the map's surface over a square that holds the cone's whole cross-
// section at the surface's nearest depth lies within a thin slab in front of the
// receiver: each ray of the cone then starts behind that surface and leaves the
// slab in front of it, inside the square, so it crosses the surface. A slab thin
// for its square (`UMBRA_SLOPE`) keeps out the silhouettes where a ray could pass
// beside a caster, not through it: a caster's edge seen over what lies behind it is
// a jump in depth as deep as the gap between them.
import package::constants::MAP_CLEARED;
import package::passes::light_binding::{light, light_depth_from_distance, light_distance_from_depth, texel_shape};
import package::passes::light_kinds::{emitter_above_plane, emitter_cone_radius};
import package::techniques::bindings::shadow_map;

// The pyramid of `shadow_map` (rays/pyramid.rs, depth_pyramid.wgsl), in the light's
// shadow group beside the mask: each square's plane and least residual, and its
// least and greatest depth.
@group(2) @binding(10) var pyramid_planes_read: texture_2d_array<f32>;
@group(2) @binding(11) var pyramid_ranges_read: texture_2d_array<f32>;


// Map texels a side of one texel of the pyramid's first level
// (`pyramid::FIRST_LEVEL_TEXELS`).
const PYRAMID_FIRST_TEXELS: f32 = 4.0;

// What the classification answers, as the visibility it stores: lit and umbra are
// the map's answers; a visibility strictly between 0 and 1 is what
// refine_classify.wgsl lists for the trace pass.
const CLASSIFIED_LIT: f32 = 1.0;
const CLASSIFIED_UMBRA: f32 = 0.0;
const CLASSIFIED_UNSURE: f32 = 0.5;
// Unsure because the receiver's own horizon cuts the light (a terminator), where no
// caster the map holds reaches: a band a pixel or two wide whose visibility falls
// fast, which a neighbour's answer would not fill; the mask pass beams it in every
// frame it is not answered (penumbra_mask.wgsl).
const CLASSIFIED_HORIZON: f32 = 0.25;

// The steepest a caster's surface over an umbra's square may be, as depth along the
// light over distance across it: up to 63° from facing the light.
const UMBRA_SLOPE: f32 = 2.0;

// A receiver as the classification sees it, in texels of its layer: where it lies
// (texel centres at whole numbers), its own depth, and its plane's depth gradient.
struct Receiver {
    texel: vec2<f32>,
    depth: f32,
    gradient: vec2<f32>,
    // Its distance from the light along the layer's axis.
    distance: f32,
    layer: u32,
    // Whether the layer is a cube face, whose depths the pyramid holds as
    // `cube_depth` (depth_pyramid.wgsl) rather than as the face stores them.
    cube: bool,
};

// A receiver outside its layer, or seen edge-on from the light: the map cannot say.
// Its texel lies past every layer's edge.
const UNPLACED_TEXEL: f32 = -1e9;
fn unplaced_receiver(layer: u32, cube: bool) -> Receiver {
    return Receiver(vec2<f32>(UNPLACED_TEXEL), 0.0, vec2<f32>(0.0), 1.0, layer, cube);
}

// A cube face's depth at distance `z` along its axis: 1 − near / z, which like a
// perspective map's depth is affine across a plane seen from the light (the distance
// over range the face stores is not), and grows with distance.
fn cube_depth(z: f32) -> f32 {
    return 1.0 - light.map.near / z;
}

// The depth the classification weighs for a point at distance `at` along its
// layer's axis, and the inverse.
fn layer_depth(cube: bool, at: f32) -> f32 {
    if cube {
        return cube_depth(at);
    }
    return light_depth_from_distance(at);
}

fn layer_distance(cube: bool, depth: f32) -> f32 {
    if cube {
        return light.map.near / max(1.0 - depth, 1e-30);
    }
    return light_distance_from_depth(depth);
}

// Map texel `texel`'s depth as the classification weighs it: a cube face's distance
// over range made `cube_depth` along the texel's centre ray.
fn stored_depth(r: Receiver, texel: vec2<i32>) -> f32 {
    let stored = textureLoad(shadow_map, texel, r.layer, 0);
    if !r.cube {
        return stored;
    }
    let ndc = (vec2<f32>(texel) + vec2<f32>(0.5)) / light.map.resolution * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0);
    return cube_depth(stored * light.emitter.range * inverseSqrt(1.0 + dot(ndc, ndc)));
}

// How far to the side of the receiver a caster can reach the cone: its radius is
// `cone_at_light` × (1 − at / distance) at distance `at` along the layer's axis, and
// a texel there is `texel_at_light` + `texel_growth` × at wide (the smaller of its
// two sides).
struct Reach {
    cone_at_light: f32,
    distance: f32,
    texel_at_light: f32,
    texel_growth: f32,
    cube: bool,
};

// A 2D layer's reach: the cone is `emitter_cone_radius`'s.
fn map_reach(r: Receiver) -> Reach {
    let smaller = min(texel_shape(r.layer).x, texel_shape(r.layer).y);
    return Reach(
        emitter_cone_radius(light.emitter, r.distance, 0.0),
        r.distance,
        light.cascades[r.layer].texel_world * smaller,
        light.map.texel_per_distance * smaller,
        false,
    );
}

// A cube face's reach, for a receiver `offset` from the light: a face texel at
// distance `at` along its axis is 2 at / resolution wide across it, and the cone
// from the receiver to the sphere (radius `size`) lies, where it crosses the plane
// at `at`, within size (1 + tan θ) (d − at) / (d − size) of the line to the light's
// centre, θ the angle between the receiver's direction and the face's axis and d its
// distance along it: the sphere's points lie within its radius of the centre across
// the axis and along it.
fn cube_reach(r: Receiver, offset: vec3<f32>) -> Reach {
    let size = light.emitter.size;
    let d = r.distance;
    let across = sqrt(max(dot(offset, offset) - d * d, 0.0));
    let cone = size * (1.0 + across / d) * d / max(d - size, 1e-30);
    return Reach(cone, d, 0.0, 2.0 / light.map.resolution, true);
}

// The farthest from the light a caster `texels` to the side may stand and still
// reach the cone (negative where none can): A (1 − at / d) ≥ texels × (t0 + k at).
fn farthest_reaching(reach: Reach, texels: f32) -> f32 {
    let r = max(texels, 0.0);
    return (reach.cone_at_light - r * reach.texel_at_light)
        / (reach.cone_at_light / reach.distance + r * reach.texel_growth);
}

// The deepest depth of a caster `texels` to the side that can reach the cone (below
// every depth where none can).
fn deepest_reaching(reach: Reach, texels: f32) -> f32 {
    let at = farthest_reaching(reach, texels);
    if at <= light.map.near {
        return -1.0;
    }
    return layer_depth(reach.cube, at);
}

// The cone's radius in texels at distance `at` along the layer's axis.
fn cone_texels(reach: Reach, at: f32) -> f32 {
    let cone = reach.cone_at_light * max(1.0 - at / reach.distance, 0.0);
    return cone / (reach.texel_at_light + reach.texel_growth * at);
}

// The receiver plane's depth gradient per texel, from the map steps of its two
// screen tangents `a` and `b` (u, v, depth), by the 2×2 inverse; None (a vector of
// NaN) where the plane is seen edge-on from the light.
fn plane_gradient(a: vec3<f32>, b: vec3<f32>) -> vec2<f32> {
    let det = a.x * b.y - a.y * b.x;
    if !(abs(det) > 1e-20) {
        return vec2<f32>(0.0);
    }
    return vec2<f32>(b.y * a.z - a.y * b.z, a.x * b.z - b.x * a.z) / det / light.map.resolution;
}

// Whether a texel at `offset` from the receiver storing `stored` may hide part of
// the light: in front of the receiver's plane by more than `tolerance`, and near
// enough the light to reach the cone from there (a texel's geometry may lie up to a
// texel nearer the receiver than its centre).
fn may_hide(r: Receiver, reach: Reach, offset: vec2<f32>, stored: f32, tolerance: f32) -> bool {
    let plane = r.depth + dot(r.gradient, offset);
    let aside = max(abs(offset.x), abs(offset.y)) - 1.0;
    return stored < plane - tolerance && stored <= deepest_reaching(reach, aside);
}

// One square of the pyramid's level `level`, in map texels (texel centres at whole
// numbers): its edges, its plane (depth at its centre, per texel along x and y, least
// residual) and its least and greatest depth.
struct Square {
    lo: vec2<f32>,
    hi: vec2<f32>,
    plane: vec4<f32>,
    range: vec2<f32>,
};

fn pyramid_square(layer: u32, level: u32, texel: vec2<i32>) -> Square {
    let side = PYRAMID_FIRST_TEXELS * f32(1u << level);
    let lo = vec2<f32>(texel) * side - vec2<f32>(0.5);
    let plane = textureLoad(pyramid_planes_read, texel, layer, i32(level));
    let range = textureLoad(pyramid_ranges_read, texel, layer, i32(level)).xy;
    return Square(lo, lo + vec2<f32>(side), plane, range);
}

// The pyramid's texel of level `level` that holds map texel position `p`.
fn pyramid_texel(p: vec2<f32>, level: u32) -> vec2<i32> {
    let side = PYRAMID_FIRST_TEXELS * f32(1u << level);
    return vec2<i32>(floor((p + vec2<f32>(0.5)) / side));
}

// What a square says of the casters that may hide part of the light from the
// receiver.
const SQUARE_CLEAR: u32 = 0u;
const SQUARE_HIDES: u32 = 1u;
const SQUARE_UNDECIDED: u32 = 2u;

// Whether square `q` holds no caster that can reach the cone, holds one, or cannot
// say. Clear where nothing it holds lies in front of the receiver's plane (its
// plane, lowered by its least residual, lies behind the receiver's everywhere over
// it: a tilted floor's own squares, however wide), or where its least depth is deeper
// than any caster as near the receiver as its nearest edge, or the edge of what was
// weighed before (`covered`), may reach from. Hides where its least depth is in front
// of the receiver's plane everywhere over it and near enough the light to reach from
// its farthest corner.
//
// A square was also cleared where its own lowered plane, in the world, had the whole
// light above its horizon and the receiver in front of it (or behind it by less than
// a sun's rays climb out of before they reach the square): a floor's far squares
// under a low sun. On `florence` under a 2° sun 35° up it called 58 pixels of
// 57,600 lit where the map alone and the beams find umbra (8 without it), for a
// reason not yet found, and it is gone until one is.
fn weigh_square(r: Receiver, reach: Reach, q: Square, tolerance: f32, covered: f32) -> u32 {
    let centre = 0.5 * (q.lo + q.hi);
    let half = 0.5 * (q.hi.x - q.lo.x);
    let receiver_at_centre = r.depth + dot(r.gradient, centre - r.texel);
    let tilt = abs(q.plane.y - r.gradient.x) + abs(q.plane.z - r.gradient.y);
    if q.plane.w + q.plane.x - receiver_at_centre - tilt * half >= -tolerance {
        return SQUARE_CLEAR;
    }
    let near_edge = max(q.lo - r.texel, r.texel - q.hi);
    let aside = max(max(near_edge.x, near_edge.y), 0.0);
    if q.range.x > deepest_reaching(reach, max(aside - 0.5, covered - 1.0)) {
        return SQUARE_CLEAR;
    }
    let corner = max(abs(q.lo - r.texel), abs(q.hi - r.texel));
    let far = max(corner.x, corner.y);
    // The receiver's plane is least over the square at one of its corners.
    let plane_low = receiver_at_centre - (abs(r.gradient.x) + abs(r.gradient.y)) * half;
    if q.range.x < plane_low - tolerance && q.range.x <= deepest_reaching(reach, far) {
        return SQUARE_HIDES;
    }
    return SQUARE_UNDECIDED;
}

// Whether any of the 4 × 4 map texels of a first-level square `q` may hide part of
// the light, each against its own plane depth; one no caster covers cannot.
fn first_level_hides(r: Receiver, reach: Reach, q: Square, tolerance: f32) -> bool {
    let base = vec2<i32>(q.lo + vec2<f32>(0.5));
    for (var k = 0; k < 16; k++) {
        let texel = base + vec2<i32>(k % 4, k / 4);
        if textureLoad(shadow_map, texel, r.layer, 0) >= MAP_CLEARED {
            continue;
        }
        if may_hide(r, reach, vec2<f32>(texel) - r.texel, stored_depth(r, texel), tolerance) {
            return true;
        }
    }
    return false;
}

// The most squares one search of `square_may_hide` weighs below the square it
// starts from. Of the truly lit pixels under `spheres`' point light, a budget of 64
// left 39 % to the beams, 256 leaves 36 %: the squares cost far less than the beams
// they spare.
const DESCENT_SQUARES: u32 = 256u;

// Whether square `texel` of level `level` may hold a caster that hides part of the
// light from receiver `r`: weighed whole (`weigh_square`), and where it cannot say,
// its four children in turn, down to the map's texels (`first_level_hides`), as a
// hierarchical Z-buffer's query descends (Greene, Kass & Miller 1993). A coarse
// square that holds a receiver's floor and a post far behind it can say nothing of
// either; its children each can. Squares within `covered` of the receiver were
// weighed before. Past `DESCENT_SQUARES` the square counts as hiding: the pixel is
// beamed.
//
// The walk keeps no stack: a quadtree's next square is its next sibling, or its
// nearest ancestor's (`next_square`). WGSL zeroes a function's array where it is
// declared, and on lavapipe a stack of 40 squares, zeroed for each of a pixel's up
// to 40 searches, cost more than the squares it held: a moving frame's mask pass
// under `contact`'s spot took 499 ms with it, 230 ms with one stack a pixel.
fn square_may_hide(r: Receiver, reach: Reach, level: u32, texel: vec2<i32>, tolerance: f32, covered: f32) -> bool {
    let root = i32(level);
    var at = vec3<i32>(texel, root);
    var budget = DESCENT_SQUARES;
    let weighed = vec2<f32>(covered + 0.5);
    loop {
        let q = pyramid_square(r.layer, u32(at.z), at.xy);
        var verdict = SQUARE_CLEAR;
        if !(covered > 0.0 && all(q.lo >= r.texel - weighed) && all(q.hi <= r.texel + weighed)) {
            verdict = weigh_square(r, reach, q, tolerance, covered);
        }
        if verdict == SQUARE_HIDES {
            return true;
        }
        if verdict == SQUARE_UNDECIDED {
            if at.z > 0 {
                if budget < 4u {
                    return true;
                }
                budget -= 4u;
                at = vec3<i32>(2 * at.xy, at.z - 1);
                continue;
            }
            if first_level_hides(r, reach, q, tolerance) {
                return true;
            }
        }
        at = next_square(at, root);
        if at.z > root {
            return false;
        }
    }
    return false;
}

// The square a quadtree walk weighs after `at` (x, y, level) when it does not
// descend into it: its next sibling (children in the order (0, 0), (1, 0), (0, 1),
// (1, 1)), or its parent's, or theirs; past the last, a square above level `root`.
fn next_square(at: vec3<i32>, root: i32) -> vec3<i32> {
    var next = at;
    while next.z < root {
        if (next.x & 1) == 0 {
            return next + vec3<i32>(1, 0, 0);
        }
        if (next.y & 1) == 0 {
            return next + vec3<i32>(-1, 1, 0);
        }
        next = vec3<i32>(next.xy >> vec2<u32>(1u), next.z + 1);
    }
    return vec3<i32>(next.xy, root + 1);
}

// Whether any caster the map holds may hide part of the light from receiver `r`:
// squares that double (the 2 × 2 of each level that hold it), each weighed
// (`square_may_hide`) against what a caster beyond the squares weighed before may
// reach from, until no caster deeper than the layer's nearest can reach farther.
// Squares past the layer's edge hold nothing of it: a receiver of a point light's
// cube may lie outside the face searched (penumbra_cube.wgsl).
fn casters_reach(r: Receiver, reach: Reach, nearest: f32, tolerance: f32, levels: u32) -> bool {
    // Texel centres within this (Chebyshev) distance of the receiver are weighed.
    var covered = 0.0;
    for (var level = 0u; level < levels; level++) {
        if level > 0u && deepest_reaching(reach, covered - 1.0) < nearest {
            break;
        }
        let side = PYRAMID_FIRST_TEXELS * f32(1u << level);
        let first = pyramid_texel(r.texel - vec2<f32>(0.5 * side), level);
        let dims = vec2<i32>(textureDimensions(pyramid_ranges_read, level));
        for (var k = 0; k < 4; k++) {
            let square = first + vec2<i32>(k % 2, k / 2);
            if any(square < vec2<i32>(0)) || any(square >= dims) {
                continue;
            }
            if square_may_hide(r, reach, level, square, tolerance, covered) {
                return true;
            }
        }
        covered = 0.5 * side - 0.5;
    }
    return false;
}

// Layer `layer`'s nearest depth, as the classification weighs it: no caster in it
// stands nearer the light.
fn layer_nearest(layer: u32) -> f32 {
    return textureLoad(pyramid_ranges_read, vec2<i32>(0), layer, i32(pyramid_levels()) - 1).x;
}

// The pyramid's levels, its last a single texel over the whole layer.
fn pyramid_levels() -> u32 {
    return textureNumLevels(pyramid_ranges_read);
}

// How far in front of receiver `r`'s plane, in depth, a texel must stand to hide
// anything: half a texel's rise along the plane, and the depths' rounding.
fn receiver_tolerance(r: Receiver) -> f32 {
    return 0.5 * (abs(r.gradient.x) + abs(r.gradient.y)) + 4.0 * 1.1920929e-7;
}

// Whether receiver `r` was placed in its layer (`unplaced_receiver`).
fn receiver_placed(r: Receiver) -> bool {
    return r.texel.x > 0.5 * UNPLACED_TEXEL;
}

// A texel's smaller side over its side along each of the map's axes, for receiver
// `r`'s layer (a cube face's texels are square).
fn texel_sides(r: Receiver) -> vec2<f32> {
    if r.cube {
        return vec2<f32>(1.0);
    }
    let shape = texel_shape(r.layer);
    return vec2<f32>(min(shape.x, shape.y)) / shape;
}

// The classification of receiver `r` on a 2D layer (`CLASSIFIED_*`), whose reach is
// `reach`.
fn classify_receiver(r: Receiver, reach: Reach, seen_normal: vec3<f32>, world: vec3<f32>) -> f32 {
    let size = light.map.resolution;
    let levels = pyramid_levels();
    // The farthest any caster can reach: from the layer's nearest depth.
    let nearest = layer_nearest(r.layer);
    // In texels along each of the map's axes: `cone_texels` counts the smaller of a
    // texel's sides, and a low sun's map of a wide floor has long, thin texels.
    let widest = max(cone_texels(reach, max(layer_distance(r.cube, nearest), light.map.near)) * texel_sides(r) + 1.0, vec2<f32>(2.5));
    // What lies past the layer's edge is unknown.
    if any(r.texel - widest < vec2<f32>(-0.5)) || any(r.texel + widest > vec2<f32>(size - 0.5)) {
        return CLASSIFIED_UNSURE;
    }
    let reached = casters_reach(r, reach, nearest, receiver_tolerance(r), levels);
    return classified(r, reach, reached, seen_normal, world);
}

// What receiver `r` is, once the search has said whether any caster may hide part of
// the light from it (`reached`): lit, or beside its own horizon, where none can;
// umbra where one caster hides all of it; unsure otherwise.
fn classified(r: Receiver, reach: Reach, reached: bool, seen_normal: vec3<f32>, world: vec3<f32>) -> f32 {
    if !reached {
        return select(CLASSIFIED_HORIZON, CLASSIFIED_LIT, emitter_above_plane(light.emitter, world, seen_normal));
    }
    return select(CLASSIFIED_UNSURE, CLASSIFIED_UMBRA, covered_by_one_caster(r, reach, receiver_tolerance(r), pyramid_levels()));
}

// The most windows `covered_by_one_caster` reads, each wider than the one before.
const UMBRA_WINDOWS: i32 = 6;

// Whether one caster the map holds hides all of the light from receiver `r` (the
// umbra's proof at the top of this file): over a window round the receiver, the
// map's depths lie in a slab in front of the receiver, thin for the window, whose
// nearest depth's cone fits in the window. The window starts a first-level square
// in radius and grows to the radius the cone at its slab's nearest depth needs (at
// least a quarter more each time); each is read from the coarsest level whose
// squares are at most half its radius (at most 10 × 10 of them), so that it
// overshoots its radius by at most half. A window of a power of two's radius, read
// in squares of that radius, overshot the cone by up to four times, and a caster
// little wider than its own cone never proved an umbra.
fn covered_by_one_caster(r: Receiver, reach: Reach, tolerance: f32, levels: u32) -> bool {
    let receiver_texel = reach.texel_at_light + reach.texel_growth * r.distance;
    // In front of the receiver by more than its plane's tolerance and two texels
    // along the light.
    let front = layer_depth(r.cube, r.distance - 2.0 * receiver_texel) - tolerance;
    var radius = PYRAMID_FIRST_TEXELS;
    for (var window = 0; window < UMBRA_WINDOWS; window++) {
        let coarsest = floor(log2(radius / (2.0 * PYRAMID_FIRST_TEXELS)));
        let level = u32(clamp(coarsest, 0.0, f32(levels - 1u)));
        let lo = pyramid_texel(r.texel - vec2<f32>(radius), level);
        let hi = pyramid_texel(r.texel + vec2<f32>(radius), level);
        let dims = vec2<i32>(textureDimensions(pyramid_ranges_read, level));
        if any(lo < vec2<i32>(0)) || any(hi >= dims) {
            return false;
        }
        var range = vec2<f32>(2.0, -1.0);
        for (var y = lo.y; y <= hi.y; y++) {
            for (var x = lo.x; x <= hi.x; x++) {
                let square = pyramid_square(r.layer, level, vec2<i32>(x, y));
                range = vec2<f32>(min(range.x, square.range.x), max(range.y, square.range.y));
            }
        }
        if range.y >= front {
            return false;
        }
        let near_at = layer_distance(r.cube, range.x);
        let far_at = layer_distance(r.cube, range.y);
        let texel = reach.texel_at_light + reach.texel_growth * near_at;
        let across = f32(max(hi.x - lo.x, hi.y - lo.y) + 1) * PYRAMID_FIRST_TEXELS * f32(1u << level);
        if far_at - near_at > UMBRA_SLOPE * across * texel {
            return false;
        }
        let needed = cone_texels(reach, near_at) + 1.0;
        if needed <= radius {
            return true;
        }
        radius = max(needed, 1.25 * radius);
    }
    return false;
}

// The camera-facing geometric normal of the plane through the screen derivatives
// `world_dx` and `world_dy`, on the side of `n`.
fn seen_plane_normal(n: vec3<f32>, world_dx: vec3<f32>, world_dy: vec3<f32>) -> vec3<f32> {
    let plane = cross(world_dx, world_dy);
    if !(dot(plane, plane) > 0.0) {
        return n;
    }
    return normalize(plane) * select(-1.0, 1.0, dot(plane, n) >= 0.0);
}

// The map is never unsure past the classification: `penumbra_map_lookup` answered
// unsure by a visibility of one half, which refine_classify.wgsl lists.
fn classified_map_unsure(world: vec3<f32>, n: vec3<f32>, geometric_n: vec3<f32>, l: vec3<f32>, layer: u32) -> bool {
    return false;
}
