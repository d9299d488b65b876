// Hybrid ray-traced shadows (after Story's HFTS, GDC 2016, and Unreal's shadow-map
// ray tracing): the map answers where it is sure, a ray where it is not. This file
// decides which pixels rays answer. On the mask path, the mask pass lists them
// (refine_append.wgsl) for the trace pass (refine_trace.wgsl), which casts their rays
// in a compute pass dispatched over the list alone: tracing in the mask pass itself
// would hold every lane of a group for its slowest ray, and lockstep made a frame
// 3.3× dearer where 2 % of pixels traced. On the forward path, the lighting pass
// traces them where it shades them (refine_forward.wgsl).
//
// A pixel is unsure when its filtered visibility is strictly between 0 and 1 (the
// taps disagree: the edge band), or when `map_unsure` (refine_map.wgsl,
// refine_cube.wgsl, refine_omni.wgsl) finds its footprint in the map ambiguous. `REFINE_EVERY_PIXEL`
// lists every pixel instead: the exact baseline.
import package::passes::light_binding::light;
import package::passes::light_kinds::emitter_unlit;
import package::passes::shading::facing_side;
import package::variant::{REFINE_EVERY_PIXEL, map_unsure};

// Whether a ray decides the pixel: it faces the light, lies inside its cone and range,
// and the map is unsure of it (or every pixel traces). `shadow` is the lookup's
// (visibility, layer). Within `facing_error` of edge-on to the light
// (resolve_visibility.wgsl), the geometric normal cannot say whether the surface
// faces the light, and a ray decides that too: it leaves from the camera's side of
// the surface, so it leaves the surface's plane where that side faces the light and
// meets the surface itself where it does not.
fn classified_ray_decides(
    shadow: vec2<f32>,
    world: vec3<f32>,
    n: vec3<f32>,
    geometric_n: vec3<f32>,
    l: vec3<f32>,
    cone: f32,
    facing_error: f32,
) -> bool {
    // Outside the light's cone or range, or facing away from it: dark by
    // definition, which the map's answer already says.
    let facing = dot(geometric_n, l);
    if facing <= -facing_error || emitter_unlit(light.emitter, cone) {
        return false;
    }
    return REFINE_EVERY_PIXEL || facing < facing_error || (shadow.x > 0.0 && shadow.x < 1.0)
        || map_unsure(world, facing_side(n, geometric_n), geometric_n, l, u32(shadow.y));
}

