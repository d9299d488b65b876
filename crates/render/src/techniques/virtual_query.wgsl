// What every technique's `sample_shadow_virtual` receives, and the helpers they
// share: a virtual map (`--partition virtual`) is read through its page table,
// each bilinear tap resolving its own page (`virtual_pcf2x2_at`,
// virtual_map/page_lookup.wgsl), so that a kernel may straddle pages, resident at
// its level or stood in for by a coarser one. A tap is a point in texels of the
// level the pixel reads; the kernels are the 2D maps' (pcf.wgsl, common.wgsl) with
// their taps moved there.
import package::constants::{MAP_CUBE, MAX_KERNEL_TEXELS};
import package::passes::light_binding::light;
import package::techniques::common::disk_rotation;
import package::techniques::pcf::{kernel_grid, kernel_grid_x, kernel_grid_y};
import package::variant::POISSON_DISK;
import package::virtual_map::map_space::map_distance;
import package::virtual_map::page_lookup::{virtual_map, virtual_pcf2x2_at};

// One lookup in a virtual map.
struct VirtualQuery {
    // The (offset) receiver in texels of `level` from the map-space origin: texel
    // (i, j) spans [i, i + 1) × [j, j + 1).
    texels: vec2<f32>,
    // The receiver's depth as the map stores it (0 at the near plane, 1 at the far).
    depth: f32,
    // The clipmap level the pixel reads.
    level: u32,
    // Map-space size of one texel of the level (map_space.wgsl).
    texel_map: f32,
    // World size of one texel of the level at the receiver (a spot's grow with the
    // distance from it).
    texel_world: f32,
    // Fragment position in pixels, for per-pixel noise.
    pixel: vec2<f32>,
    // The receiver plane's change of depth per texel, for receiver-plane depth bias;
    // zero without it.
    gradient: vec2<f32>,
    // The normal offset's shift of the receiver's point at `level`'s texel, in map
    // space: x and y in map units, z in the map's depth. A coarser level's offset
    // is as many of its own texels, so 2^k times this shift (`virtual_query_in_level`).
    offset: vec3<f32>,
};

// The same lookup in `level`, the query's own or a coarser one: the receiver pushed
// by that level's normal offset, in its texels, its plane's slope per texel of it.
// A filter wider than its cap in the query's level reads it there, as a mip chain
// is read (pcss_virtual.wgsl).
fn virtual_query_in_level(q: VirtualQuery, level: u32) -> VirtualQuery {
    let scale = exp2(f32(level - q.level));
    let texel = q.texel_map * scale;
    let further = q.offset * (scale - 1.0);
    let texels = (q.texels * q.texel_map + further.xy) / texel;
    return VirtualQuery(texels, q.depth + further.z, level, texel, q.texel_world * scale, q.pixel, q.gradient * scale, q.offset * scale);
}

// The distance along the light's axis of a point of stored depth `depth`
// (`map_distance`).
fn virtual_distance(depth: f32) -> f32 {
    return map_distance(virtual_map.map, depth);
}

// A tap `offset` texels from the lookup, as an offset that stays in the map the
// receiver lies in: under a point light, within its cube face's slot (2 map units
// wide, `virtual_map::cube`), the bilinear 2×2 included. The slot's guard band holds
// its own face's depths round the face; past it lies another face's slot, other
// directions, so a wider filter (a PCSS cone, a wide kernel at a coarse level) is
// held at the band's edge, as a cube map without seamless filtering clamps to its
// face's edge. Unchanged for a sun or a spot.
fn virtual_tap_offset(q: VirtualQuery, offset: vec2<f32>) -> vec2<f32> {
    if virtual_map.map.kind != MAP_CUBE {
        return offset;
    }
    let slot = floor(q.texels * q.texel_map / 2.0) * 2.0;
    let low = slot / q.texel_map + vec2<f32>(0.5);
    let high = (slot + 2.0) / q.texel_map - vec2<f32>(0.5);
    return clamp(q.texels + offset, low, high) - q.texels;
}

// One bilinear comparison tap `offset` texels from the lookup (within its map:
// `virtual_tap_offset`), with the compared depth moved along the receiver's plane.
fn virtual_compare_tap(q: VirtualQuery, offset: vec2<f32>) -> f32 {
    let tap = virtual_tap_offset(q, offset);
    return virtual_pcf2x2_at(q.texels + tap, q.depth + dot(q.gradient, tap), q.level);
}

// The kernel width in texels of the level read (kernel_width_texels for a virtual
// map): --pcf-kernel as given, or converted from world units by the level's texel.
fn virtual_kernel_width_texels(q: VirtualQuery) -> f32 {
    if light.pcf.kernel_in_world == 1u {
        return clamp(light.pcf.kernel_width / q.texel_world, 1.0, MAX_KERNEL_TEXELS);
    }
    return light.pcf.kernel_width;
}

// A rotated Poisson disk of `count` bilinear taps, `radius` texels wide (pcf_poisson).
fn virtual_pcf_poisson(q: VirtualQuery, radius: f32, count: u32) -> f32 {
    let rotation = disk_rotation(q.pixel);
    var sum = 0.0;
    for (var i = 0u; i < count; i++) {
        sum += virtual_compare_tap(q, rotation * POISSON_DISK[i] * radius);
    }
    return sum / f32(count);
}

// A box or tent kernel `width` texels wide from bilinear taps with exact weights
// (pcf.wgsl's kernel grid, after Castaño 2013: two neighbouring texel cells read by
// one tap).
fn virtual_pcf_kernel(q: VirtualQuery, width: f32, tent: bool) -> f32 {
    let g = kernel_grid(q.texels, width, tent);
    var sum = 0.0;
    var total = 0.0;
    for (var j = 0; j < g.taps.y; j++) {
        let ty = kernel_grid_y(g, j);
        for (var i = 0; i < g.taps.x; i++) {
            let tx = kernel_grid_x(g, i);
            let w = tx.y * ty.y;
            if w > 0.0 {
                sum += w * virtual_compare_tap(q, vec2<f32>(tx.x, ty.x));
                total += w;
            }
        }
    }
    return sum / max(total, 1e-12);
}
