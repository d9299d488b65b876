// Whether a 2D shadow map (a sun's map or cascades, a spot's map) is unsure of a
// pixel. Its footprint is the bilinear 2×2 of the lookup and a ring of
// `UNSURE_RING_TEXELS` around it; each texel's stored depth is compared with the
// receiver's own depth there (following the receiver's plane, so that a tilted
// receiver is not taken for a caster of itself):
// - at or behind the receiver, within `tolerance` (half a texel of the receiver's
//   depth slope, for the plane's fit to a curved surface): the receiver itself or
//   something behind it, evidence of light;
// - in front of it by more than `margin` (the slope bias the map was drawn with, and
//   `UNSURE_DEPTH_TEXELS` texels of depth along the light's ray): a caster, evidence
//   of shadow;
// - in between: a caster touching the receiver, or the receiver's own surface bent
//   toward the light. This is where light leaks and acne live: unsure.
// In the bilinear 2×2 the lookup reads, evidence of light must also lie behind the
// receiver's own bias: a steep caster's larger bias can store it behind a receiver
// it shadows, as just past a fold (refine_footprint.wgsl).
// The pixel is unsure when any texel is, or when the footprint holds both kinds.
//
// Under a light with an area (light.rays.penumbra_rays > 0), the pixel is also unsure
// where the light's own footprint in the map (`area_unsure`) holds casters over part
// of it: the penumbra as the geometry bounds it, not as the technique estimated it.
//
// A caster thinner than a texel, which the map's rasterization missed altogether,
// leaves no depth to disagree with; the map's touched layer (rays/touched.rs), drawn
// conservatively, holds it (`projected_footprint_touched`).
import package::passes::light_binding::{light, light_distance_from_depth, texel_shape, texel_world_size_at};
import package::passes::light_kinds::emitter_cone_radius;
import package::passes::map_visibility::{local_texel_world_size, shadow_coords};
import package::rays::refine_footprint::{Evidence, FootprintBounds, UNSURE_DEPTH_TEXELS, UNSURE_GRAZING_COS, footprint_evidence, leaves_unsure, receiver_bias};
import package::rays::map_step::map_step;
import package::techniques::bindings::{shadow_gather, shadow_map};
import package::variant::REFINE_PENUMBRAE;

// The map's touched layer (rays/touched.rs): per texel, the nearness (1 − depth) of
// the nearest opaque caster touching its square. Binding 12 of the shadow group
// (`passes::TOUCHED_BINDING`).
@group(2) @binding(12) var touched_map: texture_depth_2d_array;

// What touches the 2 × 2 texels round `corner` of layer `layer`, in gather's order.
fn projected_footprint_touched(corner: vec2<f32>, layer: u32) -> vec4<f32> {
    return textureGather(touched_map, shadow_gather, corner, layer);
}

// The receiver's plane in the map, for `footprint_receiver`: depth `depth` at texel
// position `p` (texel centres at whole numbers), changing by `gradient` per texel. A
// map's depth is affine across a plane in an orthographic map, and in a perspective
// one too (z/w is), so this is exact up to rounding.
struct MapPlane {
    p: vec2<f32>,
    depth: f32,
    gradient: vec2<f32>,
};
var<private> map_plane: MapPlane;

// The receiver's depth at the texels (x, y + 1), (x + 1, y + 1), (x + 1, y), (x, y).
fn projected_footprint_receiver(x: i32, y: i32) -> vec4<f32> {
    let g = map_plane.gradient;
    let r = map_plane.depth + dot(g, vec2<f32>(f32(x), f32(y)) - map_plane.p);
    return vec4<f32>(r + g.y, r + g.x + g.y, r + g.x, r);
}

// `layer` is the one the lookup shaded with; `n` is the normal it was offset along;
// `geometric_n` gives the receiver's plane.
fn projected_map_unsure(world: vec3<f32>, n: vec3<f32>, geometric_n: vec3<f32>, l: vec3<f32>, layer: u32) -> bool {
    let c = shadow_coords(layer, world, n, l);
    if c.w < 0.5 {
        // Outside every layer: the map has nothing to say.
        return true;
    }
    let size = light.map.resolution;
    let distance = -(light.light_from_world * vec4<f32>(world, 1.0)).z;
    let texel_world = local_texel_world_size(layer, world, distance);
    // The receiver's plane, through two tangents a texel long, in map coordinates.
    let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(geometric_n.x) > 0.9);
    let tangent = normalize(cross(geometric_n, helper));
    let clip_from_world = light.cascade_clip_from_world[layer];
    let w = (clip_from_world * vec4<f32>(world, 1.0)).w;
    let ndc = vec3<f32>((c.x - 0.5) * 2.0, (0.5 - c.y) * 2.0, c.z);
    let a = map_step(clip_from_world, ndc, w, tangent * texel_world);
    let b = map_step(clip_from_world, ndc, w, cross(geometric_n, tangent) * texel_world);
    let det = a.x * b.y - a.y * b.x;
    if abs(det) < 1e-12 / (size * size) {
        // The receiver is seen edge-on from the light.
        return true;
    }
    // ∂depth/∂(u, v), by the 2×2 inverse, then per texel.
    let gradient = vec2<f32>(b.y * a.z - a.y * b.z, a.x * b.z - b.x * a.z) / det / size;
    let along_ray = abs(map_step(clip_from_world, ndc, w, -l * texel_world).z);
    let slope = abs(gradient.x) + abs(gradient.y);
    let margin = UNSURE_DEPTH_TEXELS * along_ray + (light.bias.slope + 1.0) * slope;
    let own_bias = receiver_bias(max(abs(gradient.x), abs(gradient.y)), c.z);

    // The surface itself, where the lookup's point came from: its plane is parallel
    // to the lookup's, as far behind it as the normal offset moved the point.
    let surface_clip = clip_from_world * vec4<f32>(world, 1.0);
    let surface_ndc = surface_clip.xyz / surface_clip.w;
    let surface_uv = surface_ndc.xy * vec2<f32>(0.5, -0.5) + vec2<f32>(0.5);
    let surface = surface_ndc.z + dot(gradient, (c.xy - surface_uv) * size) - c.z;

    map_plane = MapPlane(c.xy * size - vec2<f32>(0.5), c.z, gradient);
    let grazing = dot(geometric_n, l) < UNSURE_GRAZING_COS;
    let bounds = FootprintBounds(0.5 * slope, margin, own_bias, surface, grazing);
    let footprint = footprint_evidence(c.xy, bounds, layer);
    if leaves_unsure(footprint) {
        return true;
    }
    return REFINE_PENUMBRAE && area_unsure(map_plane, bounds, footprint, layer, distance);
}

// Taps a side of `area_unsure`'s grid over the light's footprint.
const AREA_SEARCH_TAPS: i32 = 6;

// The texel of tap (i, j) of the grid over a search `radius` texels round texel
// position `p` (texel centres at whole numbers), along each of the map's axes.
fn area_search_texel(p: vec2<f32>, radius: vec2<f32>, i: i32, j: i32) -> vec2<i32> {
    let step = (vec2<f32>(f32(i), f32(j)) + vec2<f32>(0.5)) / f32(AREA_SEARCH_TAPS) * 2.0 - vec2<f32>(1.0);
    return vec2<i32>(floor(p + step * radius + vec2<f32>(0.5)));
}

// The grid's spacing in texels over a search `radius` texels, along each of the
// map's axes: a caster seen at a tap may reach as far as the next tap toward the
// receiver.
fn area_search_spacing(radius: vec2<f32>) -> vec2<f32> {
    return max(2.0 * radius / f32(AREA_SEARCH_TAPS), vec2<f32>(1.0));
}

// What a tap of the search over the light's cone holds, its stored depth `stored`
// against the receiver's plane there, `plane`, as the footprint judges a texel
// (`FootprintBounds`'s `tolerance` and `margin`, here in the search's texels):
// light behind the plane or within `tolerance` in front of it, a caster more than
// `margin` in front, and in between either: a caster touching the receiver, or the
// receiver itself. A coarse texel's margin is wide, and a caster's whole lead over
// the receiver can lie inside it (a box's shadow under a 10° sun, read at a level
// whose texels are 8 times the pixel's).
const TAP_LIGHT: u32 = 0u;
const TAP_CASTER: u32 = 1u;
const TAP_EITHER: u32 = 2u;

fn search_tap(stored: f32, plane: f32, tolerance: f32, margin: f32) -> u32 {
    if stored >= plane - tolerance {
        return TAP_LIGHT;
    }
    return select(TAP_EITHER, TAP_CASTER, stored <= plane - margin);
}

// The depth of the nearest caster a tap of `kind` with stored depth `stored` may
// hold: its own, or where the margin ends for a tap that may be either.
fn tap_caster_depth(kind: u32, stored: f32, plane: f32, margin: f32) -> f32 {
    return select(stored, plane - margin, kind == TAP_EITHER);
}

// Whether a pixel whose footprint shows `footprint` (neither unsure nor both) and
// whose search over the light's cone shows `search` keeps the map's answer: where
// both show light alone (lit), or both casters alone over a search as wide as the
// cone grows up to the casters it found (`covers_cone`: the umbra). Anything else
// is unsure: casters over part of the cone; a search that saw no caster where the
// footprint did (a caster thinner than the search's coarser texels, or nearer the
// receiver than their margin) or no light where the footprint did; casters over a
// search capped short of the cone at their height, past whose edge light may come
// (a box's long shadow under a low, wide sun: the map's heightfield holds the box
// over all of it, but the cone's rays pass beside the box, not under it).
fn cone_unsure(search: Evidence, footprint: Evidence, covers_cone: bool) -> bool {
    let lit = footprint.light && search.light && !search.casters;
    let umbra = footprint.casters && search.casters && !search.light && covers_cone;
    return search.unsure || !(lit || umbra);
}

// What a grid of the search over the light's cone found (`area_grid`): its
// evidence, and the widest the cone grows, in texels, up to the casters it holds.
struct ConeSearch {
    evidence: Evidence,
    reach: f32,
};

// How much wider than its cap a second look at an umbra may reach (`wider_look`).
const AREA_SEARCH_WIDER: f32 = 8.0;

// Whether a grid `radius` texels wide that found casters alone must look again,
// wider: the cone grows wider than the grid up to those casters' height, and light
// past the grid's edge may pass beside them (a box's long shadow under a low, wide
// sun: the map's heightfield holds the box over all of it, but the cone's rays pass
// beside the box, not under it). A roof high over a floor is the common case: a
// second grid past the cone at the casters' height (`wider_radius`), its taps
// farther apart, finds the roof again and the umbra stands, where the first alone
// traced every pixel under it (47 % of Sponza's default view on four cascades
// under a 3° sun).
fn wider_look(first: ConeSearch, radius: f32) -> bool {
    let e = first.evidence;
    return !e.unsure && e.casters && !e.light && first.reach > radius;
}

// The radius of the second look (`wider_look`): its outermost taps
// (`area_search_texel`'s, at (AREA_SEARCH_TAPS − 1) / AREA_SEARCH_TAPS of its
// radius) lie twice as far out as the cone's rim `reach` texels out at the casters
// the first grid found. The first saw only the casters within its cap, and those
// beyond may stand higher, widening the cone: with its taps on the rim alone, the
// second look kept PCSS's umbra over the tip of `grazing`'s long box shadow under a
// 10° sun (a single map's penumbra MAE 0.0359 against 0.0317 with every such pixel
// traced; twice as far: 0.0317, and 0.96 and 1.18 % of Sponza's view traced on a
// single map and four cascades under a 3° sun, against 7.2 and 47 % without a
// second look).
const AREA_RIM_REACH: f32 = 2.0;

fn wider_radius(reach: f32) -> f32 {
    return AREA_RIM_REACH * reach * f32(AREA_SEARCH_TAPS) / f32(AREA_SEARCH_TAPS - 1);
}

// Under a light with an area: whether the map leaves unsure the receiver on `plane`
// at light distance `distance` (`bounds` the footprint's), whose footprint showed
// `footprint` (`cone_unsure`). Its search, a grid over the cone's cross-section at
// the map's near plane (PCSS's blocker-search region, Fernando 2005), capped at
// light.pcss.max_search_texels, looks again wider where it found casters alone
// that stand higher than it reaches (`wider_look`). A technique's own estimate of
// the penumbra can be too narrow (PCSS's under a low sun is half the true width);
// this bounds it by the geometry instead.
//
// The cone and the casters' reach are measured in the larger of the map's two texel
// sizes (`texel_world_size_at`); each grid's radius along an axis is that length in
// the axis's own texels (`texel_shape`), up to the cap.
fn area_unsure(plane: MapPlane, bounds: FootprintBounds, footprint: Evidence, layer: u32, distance: f32) -> bool {
    let near = light.map.near;
    let shape = texel_shape(layer);
    let cone = emitter_cone_radius(light.emitter, distance, near) / texel_world_size_at(layer, near);
    let cap = light.pcss.max_search_texels;
    let radius = clamp(vec2<f32>(cone) / shape, vec2<f32>(1.0), vec2<f32>(cap));
    // How far the grid reaches round the receiver along both axes, in larger texels.
    let spans = min(radius.x * shape.x, radius.y * shape.y);
    let first = area_grid(plane, radius, bounds, layer, distance);
    if !wider_look(first, spans) {
        if cone_unsure(first.evidence, footprint, first.reach <= spans) {
            return true;
        }
        // Lit, or an umbra the grid covers: light alone over a grid capped short
        // of the cone proves no light past its edge.
        let widest = min(vec2<f32>(cone) / shape, vec2<f32>(cap * AREA_SEARCH_WIDER));
        return !first.evidence.casters && wider_grids_find_casters(plane, bounds, layer, distance, WiderGrids(radius, widest));
    }
    let rim = vec2<f32>(wider_radius(first.reach)) / shape;
    let wider = min(rim, vec2<f32>(cap * AREA_SEARCH_WIDER));
    let second = area_grid(plane, wider, bounds, layer, distance);
    let wider_spans = min(wider.x * shape.x, wider.y * shape.y);
    return cone_unsure(second.evidence, footprint, all(rim <= wider) && second.reach <= wider_spans);
}

// The radii of `wider_grids_find_casters`'s grids, in texels along each of the map's
// axes: from twice `first`, doubling, up to `widest`.
struct WiderGrids {
    first: vec2<f32>,
    widest: vec2<f32>,
};

// Whether grids wider than a first one that saw light alone over a search capped
// short of the cone (`grids.first` texels; the cone `grids.widest` or wider) find a
// caster that reaches the cone, or a tap that may be one: each grid twice as wide as
// the one before, up to the cone at the near plane or `AREA_SEARCH_WIDER` times the
// cap. Light alone in a capped grid proves nothing past its edge: the long penumbra
// of a box under a low, wide sun lies past a single map's cap, where the box stands
// higher than the cap reaches. Each grid's taps lie twice as far apart as the one
// before's, so a caster is looked for at a spacing that grows with its distance to
// the side of the receiver, as its share of the sun's disk shrinks
// (refine_virtual.wgsl's `finer_grids` reads a virtual map's levels the same way).
fn wider_grids_find_casters(plane: MapPlane, bounds: FootprintBounds, layer: u32, distance: f32, grids: WiderGrids) -> bool {
    var radius = grids.first;
    while any(radius < grids.widest) {
        radius = min(2.0 * radius, grids.widest);
        let found = area_grid(plane, radius, bounds, layer, distance).evidence;
        if found.unsure || found.casters {
            return true;
        }
    }
    return false;
}

// A grid of `AREA_SEARCH_TAPS`² taps `radius` texels round the receiver's plane
// `plane` (along each of the map's axes): casters inside the cone from the receiver
// to the light (no farther to the side than the cone's radius at the caster's own
// distance, give or take the grid's spacing) and light, a texel with nothing in
// front of the receiver. A caster too far to the side to reach the cone says
// neither (counting it as light traced every umbra whose casters stand above the
// receiver by less than the grid's reach).
fn area_grid(plane: MapPlane, radius: vec2<f32>, bounds: FootprintBounds, layer: u32, distance: f32) -> ConeSearch {
    let last = vec2<i32>(i32(light.map.resolution) - 1);
    // Offsets in larger texels (`texel_shape`), as the cone is.
    let shape = texel_shape(layer);
    let spacing = area_search_spacing(radius);
    var found = ConeSearch(Evidence(false, false, false), 0.0);
    for (var j = 0; j < AREA_SEARCH_TAPS; j++) {
        for (var i = 0; i < AREA_SEARCH_TAPS; i++) {
            let texel = clamp(area_search_texel(plane.p, radius, i, j), vec2<i32>(0), last);
            let offset = vec2<f32>(texel) - plane.p;
            let stored = textureLoad(shadow_map, texel, layer, 0);
            let receiver = plane.depth + dot(plane.gradient, offset);
            let kind = search_tap(stored, receiver, bounds.tolerance, bounds.margin);
            if kind == TAP_LIGHT {
                found.evidence.light = true;
                continue;
            }
            // A caster seen at this tap may reach as far as the next tap toward the
            // receiver: the tap grid's spacing, along each axis, is the slack of the
            // test. (Along each axis rather than along the offset, as a virtual map's
            // square grid has it: with texels shorter along one axis, the spacing
            // along the longer one would stand for both, and traced 9 % more of
            // `grazing` under a 10° sun on a single map.)
            let at = light_distance_from_depth(tap_caster_depth(kind, stored, receiver, bounds.margin));
            let cone_at = emitter_cone_radius(light.emitter, distance, at) / texel_world_size_at(layer, at);
            let beside = length(max(abs(offset) - spacing, vec2<f32>(0.0)) * shape);
            if weigh_caster(&found, kind, beside, cone_at) {
                return found;
            }
        }
    }
    return found;
}

// Weighs a tap of `kind` TAP_CASTER or TAP_EITHER, `beside` texels to the side of
// the receiver (less the grid's spacing, its slack), where the cone is `cone_at`
// texels wide at the caster's height. Too far to reach the cone, it says nothing;
// else a tap that may be either makes the pixel unsure (returns true: the search
// stops), and a caster joins `found`.
fn weigh_caster(found: ptr<function, ConeSearch>, kind: u32, beside: f32, cone_at: f32) -> bool {
    if beside > cone_at {
        return false;
    }
    if kind == TAP_EITHER {
        (*found).evidence.unsure = true;
        return true;
    }
    (*found).evidence.casters = true;
    (*found).reach = max((*found).reach, cone_at);
    return false;
}
