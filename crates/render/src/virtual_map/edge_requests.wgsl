// The pages along a virtual map's shadow edges (adaptive shadow maps: Fernando,
// Fernandez, Bala and Greenberg, "Adaptive shadow maps", SIGGRAPH 2001): after a
// light's trace pass, every pixel its mask pass left to a ray asks for the pages one
// level finer than the level it read, around its point, as bits of the request
// pass's layout (`page_requests.wgsl`), for the next frame. There a pixel reads the
// finest level whose pages hold its whole footprint (`virtual_lookup_visibility`),
// so the band where the map is unsure, as wide as the footprint test's block of
// texels, narrows by half with each level; a pixel asks for nothing finer than
// `edge_levels` below its footprint's level.
import package::rays::refine_list::{ListedPixels, unsure_pixels};
import package::constants::TRACED_LAYER_FLAG;
import package::passes::screen_common::prepass_surface;
import package::variant::REFINE_GROUP_SIZE;
import package::virtual_map::page_requests::{footprint_level, request_area_search, request_level_pages, request_params, window_level};

// The light's refinement counters, read only: the pass is dispatched by them.
@group(1) @binding(4) var<storage, read> edge_listed: ListedPixels;

@compute @workgroup_size(REFINE_GROUP_SIZE)
fn request_edge_pages(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let count = edge_listed.count;
    // More pixels than the dispatch's workgroups cover loop over the rest.
    for (var index = id.x; index < count; index += groups.x * REFINE_GROUP_SIZE) {
        let entry = unsure_pixels[index];
        let texel = vec2<u32>(entry.pixel & 0xffffu, entry.pixel >> 16u);
        let surface = textureLoad(prepass_surface, texel, 0);
        if surface.w <= 0.0 {
            continue;
        }
        // The level the pixel read; past TRACED_LAYER_FLAG, a debug view's flags.
        let read = (entry.layer & 0xffffu) % TRACED_LAYER_FLAG;
        let footprint = window_level(surface.xyz, footprint_level(surface.xyz, surface.w));
        if read == 0u || read + request_params.edge_levels <= footprint {
            continue;
        }
        request_level_pages(surface.xyz, read - 1u, request_params.reach_texels);
        if request_params.area_light_size > 0.0 {
            request_area_search(surface.xyz, read - 1u);
        }
    }
}
