// Screen-space shadow mask (as in Unity URP's screen-space shadows): one full-screen
// pass per light over the prepass. It reads each pixel's world point from the
// prepass, resolves the light's shadow lookup there once, with the light's
// own technique (`pixel_visibility`, resolve_visibility.wgsl), lists the pixels whose
// map answer is unsure for the trace pass when refinement is on (`ray_decides`,
// rays/refine_classify.wgsl), marches contact shadows when the light has them
// (contact.wgsl), and stores the visibility in the light's layer of the mask, for its lighting pass to read: one 32-bit float, visibility +
// 2 × the shadow-map layer that shaded it (for the cascade debug view), so that the
// mask path keeps the forward path's visibility exactly.
import package::constants::{DEBUG_VIEW_TRACED, TRACED_LAYER_FLAG};
import package::passes::camera_binding::camera;
import package::passes::contact::contact_visibility;
import package::passes::light_binding::light;
import package::passes::octahedron::octahedron_decode;
import package::passes::screen_common::{plane_point, prepass_normals, prepass_surface};
import package::passes::shading::{facing_error, light_geometry};
import package::variant::{defer_to_ray, pixel_visibility, ray_decides};

// Its vertex stage is fullscreen.wgsl's `vs_fullscreen`.

@fragment
fn fs_mask(@builtin(position) frag: vec4<f32>) -> @location(0) f32 {
    let texel = vec2<i32>(frag.xy);
    let surface = textureLoad(prepass_surface, texel, 0);
    let view_depth = surface.w;
    if view_depth <= 0.0 {
        // Background: no surface, nothing to shade.
        return 1.0;
    }
    let normals = textureLoad(prepass_normals, texel, 0);
    let n = octahedron_decode(normals.xy);
    let geometric_n = octahedron_decode(normals.zw);
    let world = surface.xyz;
    // The screen derivatives the forward pass's dpdx/dpdy give, rebuilt on the
    // receiver's plane: differences across the pixel's 2×2 quad, as fine derivatives
    // take them.
    let quad = floor(frag.xy * 0.5) * 2.0 + vec2<f32>(0.5);
    let world_dx = plane_point(vec2<f32>(quad.x + 1.0, frag.y), world, geometric_n)
        - plane_point(vec2<f32>(quad.x, frag.y), world, geometric_n);
    let world_dy = plane_point(vec2<f32>(frag.x, quad.y + 1.0), world, geometric_n)
        - plane_point(vec2<f32>(frag.x, quad.y), world, geometric_n);

    let geometry = light_geometry(world);
    let l = geometry.xyz;
    var shadow = pixel_visibility(world, n, geometric_n, l, geometry.w, world_dx, world_dy, frag.xy, view_depth);
    // Where the map is unsure and refinement is on, a ray decides: the pixel is
    // stored lit (with its contact shadow) and the trace pass darkens it if the ray
    // is blocked.
    let traced = ray_decides(shadow, world, n, geometric_n, l, geometry.w, facing_error(world, world_dx, world_dy));
    if traced {
        shadow.x = 1.0;
    }
    if light.contact.steps > 0u && shadow.x > 0.0 {
        shadow.x = min(shadow.x, contact_visibility(world, geometric_n, l, frag.xy, view_depth));
    }
    if traced {
        // The traced view marks the pixel in its layer, which the trace and filter
        // passes carry over.
        if camera.debug_view == DEBUG_VIEW_TRACED {
            shadow.y += f32(TRACED_LAYER_FLAG);
        }
        defer_to_ray(vec2<u32>(texel), u32(shadow.y));
    }
    return shadow.x + 2.0 * shadow.y;
}
