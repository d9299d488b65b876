// Sampling a virtual shadow map through its page table: a texel of a clipmap level
// is found in the page pool through the table's entry for its page (the page
// itself, or a coarser page standing in for it), so that a filter's taps may fall
// in different pages, resident or not. `gnomon_math::virtual_map` holds the same
// arithmetic; `draw/tests.rs` holds this file to it.
//
// The pool is the light's `shadow_map`, its tiles in layers of a few rows; the
// clipmap's uniform and the
// page table follow the other shadow resources, at the place the pass's generated
// constants name (`shadow_entries` in passes/mod.rs).

import package::constants::VIRTUAL_ORIGIN_VECTORS;
import package::techniques::bindings::{shadow_gather, shadow_map};
import package::variant::{SHADOW_BINDING, SHADOW_GROUP};
import package::virtual_map::map_space::{MapSpace, map_point};

struct VirtualMap {
    // Where world points lie on the levels (map_space.wgsl).
    map: MapSpace,
    // Each level's first page, two levels to a vector: level 2k in xy, 2k + 1 in zw.
    origins: array<vec4<i32>, VIRTUAL_ORIGIN_VECTORS>,
    // Map-space size of a texel of level 0; level l's is 2^l times it.
    finest_texel: f32,
    levels: u32,
    pages_per_side: u32,
    page_texels: u32,
    // Page tiles per side of the pool's texture; slots run along rows.
    pool_pages_per_side: u32,
    // A pixel's footprint in world units per unit of view depth: which level it reads.
    footprint_per_depth: f32,
    // Rows of tiles in each layer of the pool; rows run down the layers.
    pool_rows_per_layer: u32,
    // Levels finer than its footprint's that a pixel reads where their pages hold
    // its whole footprint (`virtual_lookup_visibility`).
    edge_levels: u32,
}

@group(SHADOW_GROUP) @binding(SHADOW_BINDING + 7u) var<uniform> virtual_map: VirtualMap;
// One entry per page of every level's window (`TableEntry`): bit 31 valid, bits 24
// to 27 how many levels coarser the page read is, bits 0 to 23 its slot.
@group(SHADOW_GROUP) @binding(SHADOW_BINDING + 8u) var<storage, read> page_table: array<u32>;

// A texel as the table resolves it: its stored depth, and whether its own level's
// page held it (not a coarser page standing in, nor no page at all).
struct VirtualTexel {
    depth: f32,
    exact: bool,
}

// The level a pixel at view depth `view_depth` reads, where a map unit spans
// `world_per_map` world units (`map_point`'s w): the coarsest whose texels are no
// larger than its footprint, as the page requests chose (`page_requests.wgsl`).
fn virtual_level(view_depth: f32, world_per_map: f32) -> u32 {
    let ratio = view_depth * virtual_map.footprint_per_depth / world_per_map / virtual_map.finest_texel;
    if (ratio < 1.0) {
        return 0u;
    }
    return min(u32(floor(log2(ratio))), virtual_map.levels - 1u);
}

// The level a pixel at world point `world` whose footprint picks `level` reads: that
// level, or the finest coarser one whose window holds the point, as its page requests
// chose (`window_level` in page_requests.wgsl); the coarsest where none does.
fn virtual_window_level(world: vec3<f32>, level: u32) -> u32 {
    let xy = virtual_map_point(world).xy;
    let side = i32(virtual_map.pages_per_side);
    var l = level;
    while l + 1u < virtual_map.levels {
        let page_size = virtual_texel_size(l) * f32(virtual_map.page_texels);
        let page = vec2<i32>(floor(xy / page_size)) - virtual_origin(l);
        if all(page >= vec2<i32>(0)) && all(page < vec2<i32>(side)) {
            break;
        }
        l++;
    }
    return l;
}

// Map-space size of a texel of `level`.
fn virtual_texel_size(level: u32) -> f32 {
    return virtual_map.finest_texel * exp2(f32(level));
}

// The level in whose texels a search `radius` map units wide round a pixel of
// `level` spans at most `cap` texels (PCSS's `max_search_texels`, which a 2D map's
// coarser texels stretch as far): `level` itself, or as many levels coarser as it
// takes (`search_level` in page_requests.wgsl, which asks for its pages).
fn virtual_search_level(level: u32, radius: f32, cap: f32) -> u32 {
    let texels = radius / (virtual_texel_size(level) * cap);
    let coarser = u32(max(ceil(log2(texels)), 0.0));
    return min(level + coarser, virtual_map.levels - 1u);
}

fn virtual_origin(level: u32) -> vec2<i32> {
    let pair = virtual_map.origins[level / 2u];
    return select(pair.zw, pair.xy, level % 2u == 0u);
}

// The table's entry for page `page` of `level` (in pages from the map-space
// origin): 0, no page, outside the level's window.
fn virtual_page_entry(level: u32, page: vec2<i32>) -> u32 {
    let side = i32(virtual_map.pages_per_side);
    let relative = page - virtual_origin(level);
    if (any(relative < vec2<i32>(0)) || any(relative >= vec2<i32>(side))) {
        return 0u;
    }
    return page_table[level * u32(side * side) + u32(relative.y * side + relative.x)];
}

// Texel `texel` of `level` (in texels from the map-space origin, y up) through
// the page table; the far plane (lit) where no page holds it, itself or coarser.
fn virtual_texel(level: u32, texel: vec2<i32>) -> VirtualTexel {
    let size = i32(virtual_map.page_texels);
    let page = vec2<i32>(floor(vec2<f32>(texel) / f32(size)));
    let entry = virtual_page_entry(level, page);
    if ((entry & 0x80000000u) == 0u) {
        return VirtualTexel(1.0, false);
    }
    let slot = entry & 0xffffffu;
    let coarser = (entry >> 24u) & 0xfu;
    // The texel of the page read, at its own level: coordinates halved per level up.
    let scale = f32(1u << coarser);
    let read = vec2<i32>(floor(vec2<f32>(texel) / scale));
    let within = read - vec2<i32>(floor(vec2<f32>(read) / f32(size))) * size;
    let tile = virtual_slot_tile(slot);
    // Texture rows run down, map-space y up.
    let depth = textureLoad(shadow_map, tile.xy + vec2<i32>(within.x, size - 1 - within.y), tile.z, 0);
    return VirtualTexel(depth, coarser == 0u);
}

// Where slot `slot`'s tile lies in the pool: its first texel in xy, its layer in z.
// Slots run along rows, rows down the layers (`PoolSize::tile`).
fn virtual_slot_tile(slot: u32) -> vec3<i32> {
    let pool = virtual_map.pool_pages_per_side;
    let row = slot / pool;
    let rows = virtual_map.pool_rows_per_layer;
    let first = vec2<u32>(slot % pool, row % rows) * virtual_map.page_texels;
    return vec3<i32>(vec2<i32>(first), i32(row / rows));
}

// Where page `page` of `level` (in pages from the map-space origin) lies in the
// pool when its own level's page is resident: its tile's first texel in xy, its
// layer in z, and 1 in w; w is 0 where a coarser page stands in for it, or none.
fn virtual_exact_tile(level: u32, page: vec2<i32>) -> vec4<i32> {
    let entry = virtual_page_entry(level, page);
    if ((entry & 0x80000000u) == 0u || ((entry >> 24u) & 0xfu) != 0u) {
        return vec4<i32>(0);
    }
    return vec4<i32>(virtual_slot_tile(entry & 0xffffffu), 1);
}

// The 2×2 block of texels from `corner` (its lower left, in texels of a level,
// map-space y up) up and right, from the tile at `tile` (the xyz of
// [`virtual_exact_tile`]) in one gather, in the order (x, y+1), (x+1, y+1), (x+1, y),
// (x, y): the block must lie in the tile's page. Texture rows run down, map-space
// y up: the block's rows are texture rows `row − 1` (y + 1) and `row` (y), which
// gather at their shared corner returns as (x, row), (x+1, row), (x+1, row−1),
// (x, row−1).
fn virtual_tile_gather(tile: vec3<i32>, corner: vec2<i32>) -> vec4<f32> {
    let size = i32(virtual_map.page_texels);
    let within = corner - vec2<i32>(floor(vec2<f32>(corner) / f32(size))) * size;
    let at = tile.xy + vec2<i32>(within.x + 1, size - 1 - within.y);
    let pool = vec2<f32>(textureDimensions(shadow_map).xy);
    let g = textureGather(shadow_map, shadow_gather, vec2<f32>(at) / pool, tile.z);
    return vec4<f32>(g.w, g.z, g.y, g.x);
}

// The stored depth of texel `texel` of `level` ([`virtual_texel`]'s).
fn virtual_texel_depth(level: u32, texel: vec2<i32>) -> f32 {
    return virtual_texel(level, texel).depth;
}

// A 2×2 block of stored depths, in the order (x, y+1), (x+1, y+1), (x+1, y), (x, y),
// and whether its own level's pages held every texel of it.
struct VirtualBlock {
    depths: vec4<f32>,
    exact: bool,
}

// The block of `level` from texel `corner` (its lower left, map-space y up) up and
// right. Most blocks lie in one page: its tile from the table once, the four texels
// in one gather where the page is resident at its own level; through the table
// texel by texel otherwise (a block across a page border, or a page a coarser one
// stands in for).
fn virtual_block(level: u32, corner: vec2<i32>) -> VirtualBlock {
    let size = f32(virtual_map.page_texels);
    let first_page = vec2<i32>(floor(vec2<f32>(corner) / size));
    let last_page = vec2<i32>(floor(vec2<f32>(corner + vec2<i32>(1)) / size));
    if all(first_page == last_page) {
        let tile = virtual_exact_tile(level, first_page);
        if tile.w == 1 {
            return VirtualBlock(virtual_tile_gather(tile.xyz, corner), true);
        }
    }
    let a = virtual_texel(level, corner + vec2<i32>(0, 1));
    let b = virtual_texel(level, corner + vec2<i32>(1, 1));
    let c = virtual_texel(level, corner + vec2<i32>(1, 0));
    let d = virtual_texel(level, corner);
    return VirtualBlock(vec4<f32>(a.depth, b.depth, c.depth, d.depth), a.exact && b.exact && c.exact && d.exact);
}

// A world point on the map: x and y in map units, the depth the map stores for it
// (0 at the near plane, 1 at the far one), and in w the world units per map unit
// there (`map_point`).
fn virtual_map_point(world: vec3<f32>) -> vec4<f32> {
    return map_point(virtual_map.map, world);
}

// The fraction of a 2×2 bilinear footprint of `level` round the world point that
// sees the light: each of the four texels compared with the receiver's depth, and
// the results weighted bilinearly (percentage-closer filtering, Reeves, Salesin and
// Cook 1987), whatever pages the taps fall in.
fn virtual_pcf2x2(world: vec3<f32>, level: u32) -> f32 {
    let point = virtual_map_point(world);
    return virtual_pcf2x2_at(point.xy / virtual_texel_size(level), point.z, level);
}

// [`virtual_pcf2x2`] at `texels`, a point in texels of `level` from the map-space
// origin (texel (i, j) spans [i, i + 1) × [j, j + 1)), against depth `depth`: the tap
// every filter of a virtual map is made of (techniques/virtual_query.wgsl).
fn virtual_pcf2x2_at(texels: vec2<f32>, depth: f32, level: u32) -> f32 {
    let continuous = texels - vec2<f32>(0.5);
    let base = vec2<i32>(floor(continuous));
    let weight = continuous - floor(continuous);
    let stored = virtual_block(level, base).depths;
    var lit = vec4<f32>(0.0);
    lit.x = select(0.0, 1.0, depth <= stored.w);
    lit.y = select(0.0, 1.0, depth <= stored.z);
    lit.z = select(0.0, 1.0, depth <= stored.x);
    lit.w = select(0.0, 1.0, depth <= stored.y);
    let bottom = mix(lit.x, lit.y, weight.x);
    let top = mix(lit.z, lit.w, weight.x);
    return mix(bottom, top, weight.y);
}

// The pages debug view's flags for a lookup of `level` at map-space `xy`: 1 where
// its page was drawn this frame (the table's bit 28), 2 where a coarser page stands
// in for it or none does, 4 within a texel of its page's border.
fn virtual_page_flags(level: u32, xy: vec2<f32>) -> u32 {
    let size = f32(virtual_map.page_texels);
    let p = xy / (virtual_map.finest_texel * exp2(f32(level)));
    let page = floor(p / size);
    let within = p - page * size;
    let entry = virtual_page_entry(level, vec2<i32>(page));
    var flags = select(0u, 1u, (entry & 0x10000000u) != 0u);
    if ((entry & 0x80000000u) == 0u || ((entry >> 24u) & 0xfu) != 0u) {
        flags |= 2u;
    }
    if (any(within < vec2<f32>(1.0)) || any(within > vec2<f32>(size - 1.0))) {
        flags |= 4u;
    }
    return flags;
}
