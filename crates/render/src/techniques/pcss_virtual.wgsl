// pcss on a virtual map: pcss.wgsl's three steps (Fernando 2005) for a sun, with
// every tap through the page table, in texels of the level the pixel reads (whose
// size is the same everywhere: the map is orthographic):
// 1. the blocker search over the cone from the receiver to the sun's disk at the
//    map's near plane, each tap the stored depth of its texel;
// 2. the penumbra's radius from the blockers' mean distance (`emitter_penumbra_radius`);
// 3. a Poisson disk of bilinear taps that wide.
import package::passes::light_binding::light;
import package::passes::light_kinds::{emitter_cone_radius, emitter_penumbra_radius};
import package::techniques::common::disk_rotation;
import package::techniques::virtual_query::{VirtualQuery, virtual_distance, virtual_pcf_poisson};
import package::variant::POISSON_DISK;
import package::virtual_map::page_lookup::virtual_texel_depth;

fn pcss_sample_shadow_virtual(q: VirtualQuery) -> f32 {
    let max_search = light.pcss.max_search_texels;
    let max_penumbra = light.pcss.max_penumbra_texels;
    let d_receiver = virtual_distance(q.depth);
    let search_world = emitter_cone_radius(light.emitter, d_receiver, virtual_distance(0.0));
    let search = clamp(search_world / q.texel_world, 1.0, max_search);
    let rotation = disk_rotation(q.pixel);
    var blocker_sum = 0.0;
    var blockers = 0.0;
    for (var i = 0u; i < light.pcss.blocker_taps; i++) {
        let offset = rotation * POISSON_DISK[i] * search;
        let stored = virtual_texel_depth(q.level, vec2<i32>(floor(q.texels + offset)));
        if stored < q.depth + dot(q.gradient, offset) {
            blocker_sum += virtual_distance(stored);
            blockers += 1.0;
        }
    }
    if blockers == 0.0 {
        return 1.0;
    }
    let d_blocker = blocker_sum / blockers;
    let penumbra_world = emitter_penumbra_radius(light.emitter, max(d_receiver - d_blocker, 0.0), d_blocker);
    return virtual_pcf_poisson(q, clamp(penumbra_world / q.texel_world, 0.5, max_penumbra), light.pcf.poisson_taps);
}
