// pcss on a virtual map: pcss.wgsl's three steps (Fernando 2005) for a sun, a spot
// or a point light, with every tap through the page table. Each step reads the level where its
// width spans at most its cap, as a mip chain is read: the pixel's own level, or a
// coarser one where the cone or the penumbra is wider than the cap in the pixel's
// texels. So a wide light's search sees its whole cone and a wide penumbra is not
// clipped, however fine the pixel's level; its page requests ask for those levels
// (`request_cone`, page_requests.wgsl).
// 1. the blocker search over the cone from the receiver to the light's area at the
//    map's near plane (in map units there, `map_near_radius`), each tap the stored
//    depth of its texel, in the level where the cone spans at most
//    `max_search_texels`;
// 2. the penumbra's radius from the blockers' mean distance (`emitter_penumbra_radius`);
// 3. a Poisson disk of bilinear taps that wide, in the level where it spans at most
//    `max_penumbra_texels` and where the receiver's plane may be trusted that far
//    (`pcss_virtual_filter_level`).
import package::constants::MAP_ORTHOGRAPHIC;
import package::passes::light_binding::light;
import package::passes::light_kinds::{emitter_cone_radius, emitter_penumbra_radius};
import package::techniques::common::{MAX_RECEIVER_SLOPE_PER_TEXEL, disk_rotation};
import package::techniques::virtual_query::{VirtualQuery, virtual_distance, virtual_pcf_poisson, virtual_query_in_level, virtual_tap_offset};
import package::variant::POISSON_DISK;
import package::virtual_map::map_space::{map_near_radius, map_radius_at};
import package::virtual_map::page_lookup::{virtual_map, virtual_search_level, virtual_texel_depth};

// What a blocker search found: the sum of its blockers' distances along the light's
// axis, and how many there were.
struct PcssBlockers {
    distance_sum: f32,
    count: f32,
    // The nearest blocker's distance along the light's axis.
    nearest: f32,
}

// The blockers among `light.pcss.blocker_taps` taps of a Poisson disk `radius` texels
// wide round the query.
fn pcss_virtual_blockers(q: VirtualQuery, radius: f32) -> PcssBlockers {
    let rotation = disk_rotation(q.pixel);
    var found = PcssBlockers(0.0, 0.0, 3.0e38);
    for (var i = 0u; i < light.pcss.blocker_taps; i++) {
        let offset = virtual_tap_offset(q, rotation * POISSON_DISK[i] * radius);
        let stored = virtual_texel_depth(q.level, vec2<i32>(floor(q.texels + offset)));
        if stored < q.depth + dot(q.gradient, offset) {
            let at = virtual_distance(stored);
            found.distance_sum += at;
            found.count += 1.0;
            found.nearest = min(found.nearest, at);
        }
    }
    return found;
}

// The level the filter reads a penumbra `radius` map units wide in: the one where it
// spans at most `max_penumbra_texels`, but no coarser than where the receiver's plane
// changes depth by more than MAX_RECEIVER_SLOPE_PER_TEXEL a texel. Its taps compare
// depths along that plane (receiver-plane bias), which a surface edge-on to the sun
// does not follow so far from the pixel: the wider filter let light leak onto such
// walls (Sponza, 960×540, 3° sun: all-pixel MAE 0.0205 before coarser levels,
// 0.0242 with them unbounded, 0.0213 so bounded).
fn pcss_virtual_filter_level(q: VirtualQuery, radius: f32) -> u32 {
    var level = virtual_search_level(q.level, radius, light.pcss.max_penumbra_texels);
    let slope = length(q.gradient);
    while level > q.level && slope * exp2(f32(level - q.level)) > MAX_RECEIVER_SLOPE_PER_TEXEL {
        level--;
    }
    return level;
}

// The blockers of a search over a cone `search` map units wide round the query: in
// the level where it spans at most `max_search_texels`, and where that level is
// coarser than the query's, in the query's own level too, as far as its cap.
fn pcss_virtual_search(q: VirtualQuery, search: f32) -> PcssBlockers {
    let max_search = light.pcss.max_search_texels;
    let s = virtual_query_in_level(q, virtual_search_level(q.level, search, max_search));
    var found = pcss_virtual_blockers(s, clamp(search / s.texel_map, 1.0, max_search));
    if s.level > q.level {
        // A coarser level's texels sample a thin caster (a post, a branch) at too few
        // points to be found: the pixel's own level is searched too, as far as its cap.
        let own = pcss_virtual_blockers(q, max_search);
        found = PcssBlockers(found.distance_sum + own.distance_sum, found.count + own.count, min(found.nearest, own.nearest));
    }
    return found;
}

fn pcss_sample_shadow_virtual(q: VirtualQuery) -> f32 {
    let d_receiver = virtual_distance(q.depth);
    let search_world = emitter_cone_radius(light.emitter, d_receiver, virtual_distance(0.0));
    var found = pcss_virtual_search(q, map_near_radius(virtual_map.map, search_world));
    if found.count == 0.0 {
        return 1.0;
    }
    if virtual_map.map.kind != MAP_ORTHOGRAPHIC {
        // No blocker lies nearer than the nearest found, so the cone at its depth
        // bounds where a caster can hide the light: searched again over that cone,
        // narrower, so in a finer level. A spot's near plane lies where its settings
        // put it, close to the light, not at its nearest caster as a sun's clipmap's
        // does (fitted to the scene), and the cone there spans much of the map
        // (`contact` under a spot of radius 0.5: ten times its width). Measured,
        // PCSS alone there: all-pixel MAE 0.0059 to 0.0037 (the spot's 2D map:
        // 0.0036). A sun's PCSS alone gains too (`grazing`'s close view under 10°:
        // 0.0433 to 0.0359), but which pixels rays refine moves, and `grazing` under
        // a 10° sun would trace 50.01 % of its pixels instead of 49.87 %, past the
        // half virtual_maps.rs holds it to: a sun keeps the one search.
        let nearest = emitter_cone_radius(light.emitter, d_receiver, found.nearest);
        found = pcss_virtual_search(q, map_radius_at(virtual_map.map, nearest, found.nearest));
        if found.count == 0.0 {
            return 1.0;
        }
    }
    let d_blocker = found.distance_sum / found.count;
    let penumbra_world = emitter_penumbra_radius(light.emitter, max(d_receiver - d_blocker, 0.0), d_blocker);
    // World units per map unit at the receiver: 1 for a sun.
    let world_per_map = q.texel_world / q.texel_map;
    let f = virtual_query_in_level(q, pcss_virtual_filter_level(q, penumbra_world / world_per_map));
    let radius = clamp(penumbra_world / f.texel_world, 0.5, light.pcss.max_penumbra_texels);
    return virtual_pcf_poisson(f, radius, light.pcf.poisson_taps);
}
