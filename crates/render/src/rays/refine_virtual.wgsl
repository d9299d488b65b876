// Whether a virtual map is unsure of a pixel: the footprint test of
// refine_footprint.wgsl (the bilinear 2×2 and a ring of UNSURE_RING_TEXELS texels,
// each stored depth against the receiver's plane there) on the level the pixel read,
// each texel found through the page table. A plane stays a plane in map space
// (orthographic for a sun, perspective for a spot: map_space.wgsl), so the plane's
// depth is affine in texels, with the slope the receiver's normal gives it there
// (`map_plane_gradient`).
//
// A texel that its own level's page does not hold (the pool was full and a coarser
// page stands in, or no page holds it) says nothing exact: the pixel is unsure and
// a ray decides, as past a 2D map's edge. Under a light with an area, the pixel is
// also unsure where a search over the light's cone, in a level coarse enough to span
// it, does not agree with the footprint that the pixel is lit or in the umbra
// (`virtual_area_unsure`, refine_map.wgsl's `area_unsure` through the page table).
import package::passes::light_binding::light;
import package::rays::refine_footprint::{Evidence, FootprintBounds, UNSURE_DEPTH_TEXELS, UNSURE_GRAZING_COS, block_evidence, joined, receiver_bias};
import package::constants::{AREA_SEARCH_FINER_LEVELS, TRACED_LAYER_FLAG, UNSURE_RING_TEXELS};
import package::variant::REFINE_PENUMBRAE;
import package::passes::light_kinds::emitter_cone_radius;
import package::rays::refine_map::{AREA_SEARCH_TAPS, AREA_SEARCH_WIDER, ConeSearch, TAP_LIGHT, area_search_spacing, area_search_texel, cone_unsure, search_tap, tap_caster_depth, weigh_caster, wider_look, wider_radius};
import package::virtual_map::map_space::{map_distance, map_near_radius, map_plane_gradient, map_radius_at, map_texel_along_ray};
import package::virtual_map::page_lookup::{VirtualBlock, virtual_block, virtual_exact_tile, virtual_map, virtual_map_point, virtual_search_level, virtual_texel, virtual_texel_size, virtual_tile_gather};
import package::virtual_map::virtual_visibility::virtual_offset_point;

// The receiver's depth at the four texels of the block from texel (x, y), in
// refine_footprint.wgsl's order ((x, y+1), (x+1, y+1), (x+1, y), (x, y)): its plane
// through depth `depth` at continuous texel position `p`, `gradient` per texel.
fn virtual_block_receiver(x: i32, y: i32, p: vec2<f32>, depth: f32, gradient: vec2<f32>) -> vec4<f32> {
    let r = depth + dot(gradient, vec2<f32>(f32(x), f32(y)) - p);
    return vec4<f32>(r + gradient.y, r + gradient.x + gradient.y, r + gradient.x, r);
}

// The block of `level` from texel `corner` in refine_footprint.wgsl's order ((x,
// y+1), (x+1, y+1), (x+1, y), (x, y)): gathered from `tile` with no table read where
// its w is 1 (the whole footprint lies in one page, resident at its own level), else
// as `virtual_block` finds it (the footprint spans pages).
fn footprint_block(level: u32, corner: vec2<i32>, tile: vec4<i32>) -> VirtualBlock {
    if tile.w == 1 {
        return VirtualBlock(virtual_tile_gather(tile.xyz, corner), true);
    }
    return virtual_block(level, corner);
}

// `layer` is the level the lookup read; `n` the normal it was offset along;
// `geometric_n` gives the receiver's plane.
fn virtual_map_unsure(world: vec3<f32>, n: vec3<f32>, geometric_n: vec3<f32>, l: vec3<f32>, layer: u32) -> bool {
    // Past TRACED_LAYER_FLAG: a debug view's flags (virtual_visibility.wgsl).
    let level = layer % TRACED_LAYER_FLAG;
    let texel = virtual_texel_size(level);
    let point = virtual_map_point(virtual_offset_point(world, n, l, level)).xyz;
    let plane = map_plane_gradient(virtual_map.map, world, geometric_n, texel);
    if plane.z == 0.0 {
        // The receiver is seen edge-on from the light.
        return true;
    }
    let gradient = plane.xy;
    let slope = abs(gradient.x) + abs(gradient.y);
    // A texel's length along the light's ray, in depth.
    let along_ray = map_texel_along_ray(virtual_map.map, world, texel);
    let margin = UNSURE_DEPTH_TEXELS * along_ray + (light.bias.slope + 1.0) * slope;
    let own_bias = receiver_bias(max(abs(gradient.x), abs(gradient.y)), point.z);
    // Texel (i, j) holds the depth at its centre, continuous position (i, j).
    let p = point.xy / texel - vec2<f32>(0.5);
    let base = vec2<i32>(floor(p));
    // The surface itself, as far behind the lookup's plane as the offset moved it.
    let surface_point = virtual_map_point(world).xyz;
    let surface = surface_point.z + dot(gradient, surface_point.xy / texel - vec2<f32>(0.5) - p) - point.z;
    let grazing = dot(geometric_n, l) < UNSURE_GRAZING_COS;
    let bounds = FootprintBounds(0.5 * slope, margin, own_bias, surface, grazing);
    let first = base - vec2<i32>(UNSURE_RING_TEXELS);
    let end = base + vec2<i32>(2 + UNSURE_RING_TEXELS);
    // Most footprints lie in one page: its tile, read from the table once.
    let size = f32(virtual_map.page_texels);
    let first_page = vec2<i32>(floor(vec2<f32>(first) / size));
    let last_page = vec2<i32>(floor(vec2<f32>(end - vec2<i32>(1)) / size));
    var tile = vec4<i32>(0);
    if all(first_page == last_page) {
        tile = virtual_exact_tile(level, first_page);
        if tile.w == 0 {
            return true;
        }
    }
    var lit = false;
    var shadowed = false;
    for (var y = first.y; y < end.y; y += 2) {
        for (var x = first.x; x < end.x; x += 2) {
            let block = footprint_block(level, vec2<i32>(x, y), tile);
            if !block.exact {
                return true;
            }
            let stored = block.depths;
            let receiver = virtual_block_receiver(x, y, p, point.z, gradient);
            let evidence = block_evidence(stored, receiver, all(vec2<i32>(x, y) == base), bounds);
            if evidence.x {
                return true;
            }
            lit = lit || evidence.y;
            shadowed = shadowed || evidence.z;
        }
    }
    if lit && shadowed {
        return true;
    }
    let distance = map_distance(virtual_map.map, surface_point.z);
    return REFINE_PENUMBRAE && virtual_area_unsure(p, point.z, gradient, bounds, Evidence(false, lit, shadowed), level, distance);
}

// Under a light with an area: refine_map.wgsl's `area_unsure` for the receiver at
// texel position `p` of `level` (its plane `receiver` + `gradient` per texel, at
// light distance `distance`; `bounds` its footprint's, in the same depth per texel),
// whose footprint showed `footprint`, each tap through the page table. The grid
// spans at most `max_search_texels` texels, as on a 2D map; where the cone is
// wider in the pixel's own fine texels, the search reads the coarser level whose
// texels it spans in that many, so that it covers the cone at the near plane
// (`virtual_search_level`), and looks wider in that level only past the coarsest
// (`wider_look`). The page requests ask for those pages (`request_area_search`,
// page_requests.wgsl); a tap its own page does not hold makes the pixel unsure, as
// in the footprint.
fn virtual_area_unsure(p: vec2<f32>, receiver: f32, gradient: vec2<f32>, bounds: FootprintBounds, footprint: Evidence, level: u32, distance: f32) -> bool {
    let cone = map_near_radius(virtual_map.map, emitter_cone_radius(light.emitter, distance, virtual_map.map.near));
    let cap = light.pcss.max_search_texels;
    let search_level = virtual_search_level(level, cone, cap);
    let receiver_plane = VirtualPlane(p, receiver, gradient, level);
    let plane = plane_in_level(receiver_plane, search_level);
    let scaled = bounds_in_level(bounds, search_level - level);
    let radius = clamp(cone / virtual_texel_size(search_level), 1.0, cap);
    let first = virtual_area_grid(plane, radius, scaled, distance);
    var search = first.evidence;
    var covers = first.reach <= radius;
    if wider_look(first, radius) {
        // Outside a page the requests asked for, the wider grid's taps make the pixel
        // unsure: a ray decides.
        let rim = wider_radius(first.reach);
        let wider = min(rim, cap * AREA_SEARCH_WIDER);
        let second = virtual_area_grid(plane, wider, scaled, distance);
        search = second.evidence;
        covers = rim <= wider && second.reach <= wider;
    }
    if cone_unsure(search, footprint, covers) {
        return true;
    }
    let finer = finer_grids(receiver_plane, bounds, search_level, distance);
    return cone_unsure(joined(search, finer), footprint, covers);
}

// The evidence of grids `cap` texels round the receiver in the levels finer than
// the search's (at most AREA_SEARCH_FINER_LEVELS of them, down to the pixel's own):
// the search's grid, its taps a sixth of the cone apart, misses a caster narrower
// than that (a post under a 10° sun), while each finer grid's taps lie half as far
// apart as the next coarser's over a quarter of its area, so a caster is looked for
// at a spacing that grows with its distance to the side of the receiver, as its
// share of the sun's disk shrinks.
fn finer_grids(receiver: VirtualPlane, bounds: FootprintBounds, search_level: u32, distance: f32) -> Evidence {
    var found = Evidence(false, false, false);
    let cap = light.pcss.max_search_texels;
    let first = max(receiver.level, search_level - min(search_level, AREA_SEARCH_FINER_LEVELS));
    for (var l = first; l < search_level; l++) {
        let grid = virtual_area_grid(plane_in_level(receiver, l), cap, bounds_in_level(bounds, l - receiver.level), distance);
        found = joined(found, grid.evidence);
        if found.unsure {
            return found;
        }
    }
    return found;
}

// `plane` (in texels of its own level) in texels of the coarser `level`.
fn plane_in_level(plane: VirtualPlane, level: u32) -> VirtualPlane {
    let scale = exp2(f32(level - plane.level));
    return VirtualPlane((plane.p + vec2<f32>(0.5)) / scale - vec2<f32>(0.5), plane.depth, plane.gradient * scale, level);
}

// A footprint's `bounds` in texels `coarser` levels coarser than its own.
fn bounds_in_level(bounds: FootprintBounds, coarser: u32) -> FootprintBounds {
    let scale = exp2(f32(coarser));
    return FootprintBounds(bounds.tolerance * scale, bounds.margin * scale, bounds.own_bias, bounds.surface, bounds.grazing);
}

// The receiver's plane in texels of a search's level: depth `depth` at texel
// position `p`, changing by `gradient` per texel.
struct VirtualPlane {
    p: vec2<f32>,
    depth: f32,
    gradient: vec2<f32>,
    level: u32,
};

// refine_map.wgsl's `area_grid` on a virtual map's level, `radius` texels of it
// round `plane`, each tap through the page table; a tap that its own page does not
// hold makes the pixel unsure.
fn virtual_area_grid(plane: VirtualPlane, radius: f32, bounds: FootprintBounds, distance: f32) -> ConeSearch {
    let texel = virtual_texel_size(plane.level);
    let spacing = area_search_spacing(vec2<f32>(radius)).x;
    var found = ConeSearch(Evidence(false, false, false), 0.0);
    for (var j = 0; j < AREA_SEARCH_TAPS; j++) {
        for (var i = 0; i < AREA_SEARCH_TAPS; i++) {
            let tap = area_search_texel(plane.p, vec2<f32>(radius), i, j);
            let stored = virtual_texel(plane.level, tap);
            if !stored.exact {
                found.evidence.unsure = true;
                return found;
            }
            let offset = vec2<f32>(tap) - plane.p;
            let receiver = plane.depth + dot(plane.gradient, offset);
            let kind = search_tap(stored.depth, receiver, bounds.tolerance, bounds.margin);
            if kind == TAP_LIGHT {
                found.evidence.light = true;
                continue;
            }
            let at = map_distance(virtual_map.map, tap_caster_depth(kind, stored.depth, receiver, bounds.margin));
            let cone_at = map_radius_at(virtual_map.map, emitter_cone_radius(light.emitter, distance, at), at) / texel;
            if weigh_caster(&found, kind, length(offset) - spacing, cone_at) {
                return found;
            }
        }
    }
    return found;
}
