// Page requests of a virtual shadow map (`virtual_map/mod.rs`): every pixel the
// prepass saw marks the pages of the clipmap level that matches its footprint, over
// the square its filter and normal offset reach, as bits of one mask per level.
// Many pixels share a page; atomicOr keeps one bit for all of them. The same
// arithmetic as `Clipmap::request` in gnomon-math, which the tests hold it to.

import package::constants::{AREA_SEARCH_FINER_LEVELS, MAP_CUBE, MAP_ORTHOGRAPHIC, VIRTUAL_ORIGIN_VECTORS};
import package::virtual_map::map_space::{MapSpace, map_axis_distance, map_near_radius, map_point, map_sees};

struct PageRequestParams {
    // Where world points lie on the levels (map_space.wgsl).
    map: MapSpace,
    // Each level's first page, two levels to a vector: level 2k in xy, 2k + 1 in zw.
    origins: array<vec4<i32>, VIRTUAL_ORIGIN_VECTORS>,
    // Map-space size of a texel of level 0; level l's is 2^l times it.
    finest_texel: f32,
    // A pixel's footprint in world units per unit of view depth.
    footprint_per_depth: f32,
    // Texels of its level that a pixel's filter reaches from its point.
    reach_texels: f32,
    levels: u32,
    pages_per_side: u32,
    page_texels: u32,
    width: u32,
    height: u32,
    // Levels finer than its footprint's that a pixel along a shadow edge may ask for
    // (`edge_requests.wgsl`).
    edge_levels: u32,
    // Under a light with a size whose penumbrae rays refine: its size (a sun's
    // angular radius's tangent, a spot's radius; 0: no search), and the search's cap
    // in texels (`AreaSearch`).
    area_light_size: f32,
    area_cap_texels: f32,
    // Under a technique that reads the light's cone in coarser levels (PCSS): the
    // light's size (0: none), the texels of its level the coarsest read spans at
    // most, and the most texels of any level a read reaches (`ConeReach`).
    cone_light_size: f32,
    cone_level_cap_texels: f32,
    cone_reach_cap_texels: f32,
    _pad0: u32,
    _pad1: u32,
}

// The prepass's surface: the world point in xyz, its view depth in w (0: no surface).
@group(0) @binding(0) var request_surface: texture_2d<f32>;
// One bit per page: level · pages_per_side² + row · pages_per_side + column, rows
// and columns counted from the level's first page.
@group(0) @binding(1) var<storage, read_write> page_bits: array<atomic<u32>>;
@group(0) @binding(2) var<uniform> request_params: PageRequestParams;

fn level_origin(level: u32) -> vec2<i32> {
    let pair = request_params.origins[level / 2u];
    return select(pair.zw, pair.xy, level % 2u == 0u);
}

// The coarsest level whose texels are no larger than the footprint of a pixel at
// world point `world` and view depth `view_depth` (the level it reads,
// `virtual_level` in page_lookup.wgsl).
fn footprint_level(world: vec3<f32>, view_depth: f32) -> u32 {
    let world_per_map = map_point(request_params.map, world).w;
    let ratio = view_depth * request_params.footprint_per_depth / world_per_map / request_params.finest_texel;
    if (ratio < 1.0) {
        return 0u;
    }
    return min(u32(floor(log2(ratio))), request_params.levels - 1u);
}

// Whether the map-space point `xy` lies in `level`'s window.
fn in_level_window(xy: vec2<f32>, level: u32) -> bool {
    let page_size = request_params.finest_texel * exp2(f32(level)) * f32(request_params.page_texels);
    let page = vec2<i32>(floor(xy / page_size)) - level_origin(level);
    return all(page >= vec2<i32>(0)) && all(page < vec2<i32>(i32(request_params.pages_per_side)));
}

// The level a pixel at world point `world` whose footprint picks `level` reads: that
// level, or the finest coarser one whose window holds the point (`Clipmap::
// level_for_point`); `levels` where none does, or where the map does not see the
// point (`Clipmap::sees`).
fn window_level(world: vec3<f32>, level: u32) -> u32 {
    if !map_sees(request_params.map, world) {
        return request_params.levels;
    }
    let xy = map_point(request_params.map, world).xy;
    var l = level;
    while l < request_params.levels && !in_level_window(xy, l) {
        l++;
    }
    return l;
}

// Marks the pages of `level` that a lookup of that level at world point `world` may
// read: the square `reach_texels` of its texels reach round the point, within the
// level's window and, for a point light, its face's slot (`Clipmap::pages_around`).
// Nothing where the point lies outside the level's window.
fn request_level_pages(world: vec3<f32>, level: u32, reach_texels: f32) {
    let texel = request_params.finest_texel * exp2(f32(level));
    let page_size = texel * f32(request_params.page_texels);
    let xy = map_point(request_params.map, world).xy;
    let origin = level_origin(level);
    let side = i32(request_params.pages_per_side);
    let centre = vec2<i32>(floor(xy / page_size)) - origin;
    if (any(centre < vec2<i32>(0)) || any(centre >= vec2<i32>(side))) {
        return;
    }
    let reach = reach_texels * texel;
    var low = max(vec2<i32>(floor((xy - reach) / page_size)) - origin, vec2<i32>(0));
    var high = min(vec2<i32>(floor((xy + reach) / page_size)) - origin, vec2<i32>(side - 1));
    if request_params.map.kind == MAP_CUBE {
        // The slot, 2 map units wide, whose borders are whole pages at every level.
        let slot = floor(xy / 2.0) * 2.0;
        low = max(low, vec2<i32>(round(slot / page_size)) - origin);
        high = min(high, vec2<i32>(round((slot + 2.0) / page_size)) - origin - vec2<i32>(1));
    }
    for (var y = low.y; y <= high.y; y++) {
        for (var x = low.x; x <= high.x; x++) {
            let bit = level * u32(side * side) + u32(y * side + x);
            atomicOr(&page_bits[bit / 32u], 1u << (bit % 32u));
        }
    }
}

// The level in whose texels a search `radius` map units wide round a pixel of
// `level` spans at most `cap` texels: `virtual_search_level` (page_lookup.wgsl).
fn search_level(level: u32, radius: f32, cap: f32) -> u32 {
    let texels = radius / (request_params.finest_texel * exp2(f32(level)) * cap);
    let coarser = u32(max(ceil(log2(texels)), 0.0));
    return min(level + coarser, request_params.levels - 1u);
}

// The radius in map units at the near plane of the cone from world point `world` to
// a light of size `size` (`Clipmap::cone_radius`; `emitter_cone_radius` in
// light_kinds.wgsl, which the request pass has no light for): a sun's tangent times
// the distance behind the plane, a spot's radius shrunk by similar triangles.
fn cone_radius(world: vec3<f32>, size: f32) -> f32 {
    let m = request_params.map;
    let distance = map_axis_distance(m, world);
    let reach = size * max(distance - m.near, 0.0);
    return map_near_radius(m, select(reach / distance, reach, m.kind == MAP_ORTHOGRAPHIC));
}

// Marks the pages that the refinement's search over the light's cone reads for a pixel
// of `level` at world point `world` (`virtual_area_unsure`, refine_virtual.wgsl):
// the cone's radius in texels of the search's level, a texel more for its taps'
// rounding, and the lookup's own reach (its normal offset) in those texels.
fn request_area_search(world: vec3<f32>, level: u32) {
    let cone = cone_radius(world, request_params.area_light_size);
    let cap = request_params.area_cap_texels;
    let search = search_level(level, cone, cap);
    let texel = request_params.finest_texel * exp2(f32(search));
    let radius = clamp(cone / texel, 1.0, cap);
    let lookup = request_params.reach_texels / exp2(f32(search - level));
    request_level_pages(world, search, radius + 1.0 + lookup);
    // The finer levels' grids, `cap` texels round the point (`finer_grids`).
    let first = max(level, search - min(search, AREA_SEARCH_FINER_LEVELS));
    for (var l = first; l < search; l++) {
        request_level_pages(world, l, cap + 1.0 + request_params.reach_texels / exp2(f32(l - level)));
    }
}

// Marks the pages a lookup that reads the light's cone in coarser levels (PCSS,
// pcss_virtual.wgsl) reads for a pixel of `level` at world point `world`: in each
// level from `level` to the one whose texels the cone spans in at most the level cap,
// as many texels as the cone spans there (at most the reach cap, at least one), a
// texel more for the taps' rounding, and the lookup's own reach
// (`Clipmap::cone_requests`).
fn request_cone(world: vec3<f32>, level: u32) {
    let cone = cone_radius(world, request_params.cone_light_size);
    let coarsest = search_level(level, cone, request_params.cone_level_cap_texels);
    for (var l = level; l <= coarsest; l++) {
        let texel = request_params.finest_texel * exp2(f32(l));
        let spans = clamp(cone / texel, 1.0, request_params.cone_reach_cap_texels);
        request_level_pages(world, l, spans + 1.0 + request_params.reach_texels);
    }
}

@compute @workgroup_size(8, 8)
fn request_pages(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= request_params.width || id.y >= request_params.height) {
        return;
    }
    let surface = textureLoad(request_surface, vec2<i32>(id.xy), 0);
    if (surface.w <= 0.0) {
        return;
    }
    let level = window_level(surface.xyz, footprint_level(surface.xyz, surface.w));
    if level < request_params.levels {
        request_level_pages(surface.xyz, level, request_params.reach_texels);
        if request_params.area_light_size > 0.0 {
            request_area_search(surface.xyz, level);
        }
        if request_params.cone_light_size > 0.0 {
            request_cone(surface.xyz, level);
        }
    }
}
