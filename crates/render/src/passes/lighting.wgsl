// Lighting pass: Lambert diffuse + Blinn-Phong specular + ambient, with the shadow
// factor of the selected technique multiplying only the direct term. Also writes the
// per-pixel visibility, world position, normals, view depth and object id, all of
// one surface (`seen_surface`).
//
// `pixel_visibility` comes from resolve_visibility.wgsl on the forward path (the
// technique's lookup, per fragment, which `refine_forward` refines by rays where
// asked) or from mask_lookup.wgsl on the mask path (what the screen-space shadow
// mask stored for the pixel). Camera: camera.wgsl; the
// vertex stage and normals: surface.wgsl; the light's direction and cone:
// shading.wgsl; their outputs and tints: lighting_common.wgsl.
import package::constants::{DEBUG_VIEW_CASCADES, DEBUG_VIEW_PAGES, DEBUG_VIEW_TRACED, TRACED_LAYER_FLAG};
import package::passes::camera_binding::camera;
import package::passes::light_binding::light;
import package::passes::lighting_common::{FragmentOut, layer_tint, pages_tint};
import package::passes::scene_common::{alpha_cut, base_color_of, hidden_face, instances};
import package::passes::shading::{blinn_phong, facing_error, light_geometry};
import package::passes::surface::SurfaceVertex;
import package::variant::{is_seen_surface, pixel_visibility, refine_forward, seen_surface};

@fragment
fn fs_lighting(in: SurfaceVertex, @builtin(front_facing) front: bool) -> FragmentOut {
    let inst = instances[in.instance];
    // The surface this pixel shows: the fragment's own, or on the mask path the
    // prepass's (seen_own.wgsl, seen_prepass.wgsl).
    let seen = seen_surface(in);
    let n = seen.shading_n;
    let geometric_n = seen.geometric_n;
    let geometry = light_geometry(seen.world);
    let l = geometry.xyz;
    let cone = geometry.w;

    // The world position's screen derivatives, taken here in uniform control flow;
    // each lookup carries them into its own cascade's texture space.
    let world_dx = dpdx(in.world);
    let world_dy = dpdy(in.world);
    let view_depth = seen.view_depth;
    let looked_up = pixel_visibility(seen.world, n, geometric_n, l, cone, world_dx, world_dy, in.clip.xy, view_depth);
    // Where the forward path refines and the map is unsure, the fragment's rays
    // decide (rays/refine_forward.wgsl).
    let facing = facing_error(seen.world, world_dx, world_dy);
    let shadow = refine_forward(looked_up, seen.world, n, geometric_n, geometry, view_depth, in.clip.xy, facing);
    let visibility = shadow.x;
    // Under the traced view, a layer past TRACED_LAYER_FLAG marks a pixel whose
    // shadow rays decided (shadow_mask.wgsl, refine_forward.wgsl).
    let traced = u32(shadow.y) >= TRACED_LAYER_FLAG;
    let layer = u32(shadow.y) % TRACED_LAYER_FLAG;

    if alpha_cut(inst, in.uv) || hidden_face(inst, front) || !is_seen_surface(in) {
        discard;
    }
    let albedo = base_color_of(inst, in.uv).rgb;
    let v = normalize(camera.eye - seen.world);
    let direct = light.emitter.radiance * cone * blinn_phong(albedo, inst.specular, inst.shininess, n, l, v);
    var color = light.ambient * albedo + visibility * direct;
    if camera.debug_view == DEBUG_VIEW_CASCADES {
        color = layer_tint(color, layer);
    }
    if camera.debug_view == DEBUG_VIEW_PAGES {
        color = pages_tint(color, u32(shadow.y));
    }
    if camera.debug_view == DEBUG_VIEW_TRACED && traced {
        color = mix(color, vec3<f32>(1.0, 0.0, 1.0), 0.6);
    }

    var out: FragmentOut;
    out.color = vec4<f32>(color, 1.0);
    out.visibility = visibility;
    out.position = vec4<f32>(seen.world, view_depth);
    out.normal = seen.encoded_normals;
    out.object_id = inst.object_id;
    return out;
}
