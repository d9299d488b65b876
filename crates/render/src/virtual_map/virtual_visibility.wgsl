// The shadow lookup of a virtual map (`--partition virtual`): the pixel reads
// the clipmap level that matches its footprint (the level its page requests asked
// for), or a finer one along shadow edges, at its point pushed along its normal by
// the normal-offset bias in texels of that level, through the page table with the
// technique's filter (`sample_shadow_virtual`, techniques/virtual_query.wgsl).
import package::constants::{DEBUG_VIEW_PAGES, TRACED_LAYER_FLAG, UNSURE_RING_TEXELS};
import package::passes::camera_binding::camera;
import package::passes::light_binding::light;
import package::passes::shading::MIN_NORMAL_OFFSET_SCALE;
import package::techniques::common::MAX_RECEIVER_SLOPE_PER_TEXEL;
import package::techniques::virtual_query::VirtualQuery;
import package::variant::sample_shadow_virtual;
import package::virtual_map::map_space::map_delta;
import package::virtual_map::page_lookup::{virtual_exact_tile, virtual_level, virtual_map, virtual_map_point, virtual_page_flags, virtual_texel_size, virtual_window_level};

// The receiver's point as its lookup reads it: pushed along its unit normal `n`,
// lit from `l`, by the normal offset in texels of `level` (their world size there),
// times 1 − N·L (as `shadow_coords` does in map_visibility.wgsl).
fn virtual_offset_point(world: vec3<f32>, n: vec3<f32>, l: vec3<f32>, level: u32) -> vec3<f32> {
    let slope = max(1.0 - clamp(dot(n, l), 0.0, 1.0), MIN_NORMAL_OFFSET_SCALE);
    let texel = virtual_texel_size(level) * virtual_map_point(world).w;
    return world + n * (light.bias.normal_offset * texel * slope);
}

// ∂depth/∂(texel x, y) of the receiver's plane at world point `world` in a level of
// texels `texel` map units wide, from the point's screen derivatives, or 0 when
// receiver-plane bias is off: the same 2×2 solve as `receiver_depth_gradient`
// (common.wgsl) in the map's texels, the derivatives carried into map space by the
// projection's own there (`map_delta`).
fn virtual_receiver_gradient(world: vec3<f32>, world_dx: vec3<f32>, world_dy: vec3<f32>, texel: f32) -> vec2<f32> {
    if light.bias.receiver_plane == 0u {
        return vec2<f32>(0.0);
    }
    let scale = vec3<f32>(1.0 / texel, 1.0 / texel, 1.0);
    let a = map_delta(virtual_map.map, world, world_dx) * scale;
    let b = map_delta(virtual_map.map, world, world_dy) * scale;
    let det = a.x * b.y - a.y * b.x;
    if abs(det) < 1e-24 {
        return vec2<f32>(0.0);
    }
    var g = vec2<f32>(b.y * a.z - a.y * b.z, a.x * b.z - b.x * a.z) / det;
    let len = length(g);
    if len > MAX_RECEIVER_SLOPE_PER_TEXEL {
        g *= MAX_RECEIVER_SLOPE_PER_TEXEL / len;
    }
    return g;
}

// Whether `level`'s own pages hold every texel that a lookup at world point `point`
// and the refinement's footprint test read there: the bilinear 2×2 and a ring of
// UNSURE_RING_TEXELS texels round it (`virtual_map_unsure`, refine_virtual.wgsl).
fn virtual_footprint_resident(point: vec3<f32>, level: u32) -> bool {
    let p = virtual_map_point(point).xy / virtual_texel_size(level) - vec2<f32>(0.5);
    let base = vec2<i32>(floor(p));
    let size = f32(virtual_map.page_texels);
    let first = vec2<i32>(floor(vec2<f32>(base - vec2<i32>(UNSURE_RING_TEXELS)) / size));
    let last = vec2<i32>(floor(vec2<f32>(base + vec2<i32>(1 + UNSURE_RING_TEXELS)) / size));
    for (var y = first.y; y <= last.y; y++) {
        for (var x = first.x; x <= last.x; x++) {
            if virtual_exact_tile(level, vec2<i32>(x, y)).w == 0 {
                return false;
            }
        }
    }
    return true;
}

// The level a pixel whose footprint matches `level` reads at world point `world`:
// the finest of up to `edge_levels` finer ones whose pages hold its whole footprint
// (the pages along shadow edges that earlier frames asked for, edge_requests.wgsl),
// `level` itself otherwise. Each level's pages are asked for only by pixels that
// read the level above, so the search stops at the first level that fails.
fn virtual_read_level(world: vec3<f32>, n: vec3<f32>, l: vec3<f32>, level: u32) -> u32 {
    var read = level;
    for (var k = 0u; k < virtual_map.edge_levels && read > 0u; k++) {
        let finer = read - 1u;
        if !virtual_footprint_resident(virtual_offset_point(world, n, l, finer), finer) {
            break;
        }
        read = finer;
    }
    return read;
}

// The lit fraction at `world` and the level that shaded it, as (visibility, level);
// under the pages view, the level plus TRACED_LAYER_FLAG times its page's flags
// (`virtual_page_flags`), which the lighting pass tints by.
fn virtual_lookup_visibility(
    world: vec3<f32>,
    n: vec3<f32>,
    l: vec3<f32>,
    world_dx: vec3<f32>,
    world_dy: vec3<f32>,
    pixel: vec2<f32>,
    view_depth: f32,
) -> vec2<f32> {
    let surface = virtual_map_point(world);
    let level = virtual_read_level(world, n, l, virtual_window_level(world, virtual_level(view_depth, surface.w)));
    let point = virtual_offset_point(world, n, l, level);
    let map_point = virtual_map_point(point);
    let texel = virtual_texel_size(level);
    let gradient = virtual_receiver_gradient(world, world_dx, world_dy, texel);
    let offset = map_point.xyz - surface.xyz;
    let q = VirtualQuery(map_point.xy / texel, map_point.z, level, texel, texel * map_point.w, pixel, gradient, offset);
    let visibility = sample_shadow_virtual(q);
    var code = level;
    if camera.debug_view == DEBUG_VIEW_PAGES {
        code += TRACED_LAYER_FLAG * virtual_page_flags(level, map_point.xy);
    }
    return vec2<f32>(visibility, f32(code));
}
