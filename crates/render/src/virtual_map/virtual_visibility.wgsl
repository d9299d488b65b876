// The shadow lookup of a sun's virtual map (`--partition virtual`): the pixel reads
// the clipmap level that matches its footprint (the level its page requests asked
// for), at its point pushed along its normal by the normal-offset bias in texels of
// that level, through the page table with a 2×2 percentage-closer filter.
import package::constants::{DEBUG_VIEW_PAGES, TRACED_LAYER_FLAG};
import package::passes::camera_binding::camera;
import package::passes::light_binding::light;
import package::passes::shading::MIN_NORMAL_OFFSET_SCALE;
import package::virtual_map::page_lookup::{virtual_level, virtual_light_point, virtual_page_flags, virtual_pcf2x2, virtual_texel_size};

// The receiver's point as its lookup reads it: pushed along its unit normal `n`,
// lit from `l`, by the normal offset in texels of `level`, times 1 − N·L (as
// `shadow_coords` does in map_visibility.wgsl).
fn virtual_offset_point(world: vec3<f32>, n: vec3<f32>, l: vec3<f32>, level: u32) -> vec3<f32> {
    let slope = max(1.0 - clamp(dot(n, l), 0.0, 1.0), MIN_NORMAL_OFFSET_SCALE);
    return world + n * (light.bias.normal_offset * virtual_texel_size(level) * slope);
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
    let level = virtual_level(view_depth);
    let point = virtual_offset_point(world, n, l, level);
    let visibility = virtual_pcf2x2(point, level);
    var code = level;
    if camera.debug_view == DEBUG_VIEW_PAGES {
        code += TRACED_LAYER_FLAG * virtual_page_flags(level, virtual_light_point(point).xy);
    }
    return vec2<f32>(visibility, f32(code));
}
