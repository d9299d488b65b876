// Refinement by rays on the forward path: the lighting pass, which has just looked
// the fragment's shadow up in the map, traces the fragment's own rays where the map
// is unsure of it (`ray_decides`, refine_classify.wgsl), over the casters' BVH bound
// beside the camera in group 1 (trace.wgsl at TRACE_GROUP 1). The answers are the
// trace pass's (surface_rays.wgsl, the same origins and the same per-pixel light
// samples); what the forward path lacks is the mask path's neighbours:
// - a light with an area gets the plain mean of its `penumbra_rays` rays, without the
//   trace pass's edge-aware filter, so its penumbrae are noisier;
// - every fragment shaded traces, hidden ones included, and in lockstep with the
//   fragments shaded beside it: the mask path, which traces each visible pixel once
//   in groups of listed pixels only, is the cheaper place for rays (`auto` takes it).
//
// Nothing counts the fragments traced: a shader that writes storage has side effects
// that the depth test may not skip, so the driver runs it for every fragment drawn,
// hidden ones included (counting with an atomic made Sponza's refined lighting pass
// 2.6× slower on lavapipe).
import package::constants::{DEBUG_VIEW_TRACED, TRACED_LAYER_FLAG};
import package::passes::camera_binding::camera;
import package::rays::surface_rays::{centre_ray_blocked, surface_ray_origin};
import package::variant::{REFINE_PENUMBRAE, area_visibility, ray_decides};

// The fragment's (visibility, layer): the map's `shadow`, or where a ray decides, the
// rays' answer, with the traced view's mark on the layer.
fn traced_refine_forward(
    shadow: vec2<f32>,
    world: vec3<f32>,
    n: vec3<f32>,
    geometric_n: vec3<f32>,
    geometry: vec4<f32>,
    view_depth: f32,
    frag: vec2<f32>,
    facing_error: f32,
) -> vec2<f32> {
    let l = geometry.xyz;
    if !ray_decides(shadow, world, n, geometric_n, l, geometry.w, facing_error) {
        return shadow;
    }
    // The interpolated point is exact up to the rasterizer's rounding, which the
    // origin's offset for a point rebuilt from depth covers.
    let origin = surface_ray_origin(world, geometric_n, view_depth);
    var visibility = 1.0;
    if REFINE_PENUMBRAE {
        // The pixel's own pattern, as the trace pass seeds it.
        let pixel = vec2<u32>(frag);
        visibility = area_visibility(origin, world, geometric_n, pixel.x | (pixel.y << 16u)).x;
    } else if centre_ray_blocked(origin, world, l) {
        visibility = 0.0;
    }
    var layer = shadow.y;
    if camera.debug_view == DEBUG_VIEW_TRACED {
        layer += f32(TRACED_LAYER_FLAG);
    }
    return vec2<f32>(visibility, layer);
}
