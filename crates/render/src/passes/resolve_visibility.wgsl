// A pixel's visibility of its light, resolved from the shadow map: the lookup of
// `lookup_visibility` (map_visibility.wgsl, cube_visibility.wgsl or
// paraboloid_visibility.wgsl, bound in passes/wgsl_interfaces.rs), then the rules
// that hold whatever the map says. The
// forward lighting pass calls it per fragment; the shadow-mask pass once per pixel.
import package::passes::light_binding::light;
import package::passes::light_kinds::emitter_unlit;
import package::passes::shading::facing_side;
import package::variant::lookup_visibility;

// (visibility, layer that shaded it) of the surface at `world` with shading normal
// `n` and camera-facing geometric normal `geometric_n`, lit from `l` with cone factor
// `cone`. The world position's screen derivatives give the receiver's plane.
// `pixel_visibility` on the paths that look the map up.
fn resolved_pixel_visibility(
    world: vec3<f32>,
    n: vec3<f32>,
    geometric_n: vec3<f32>,
    l: vec3<f32>,
    cone: f32,
    world_dx: vec3<f32>,
    world_dy: vec3<f32>,
    pixel: vec2<f32>,
    view_depth: f32,
) -> vec2<f32> {
    // The normal offset moves the lookup along `n`: it must point to the side the
    // camera sees, or the offset looks up behind the surface. A host's shader may pass
    // a normal turned by the winding, which authored normals can contradict.
    let seen_n = facing_side(n, geometric_n);
    var shadow = lookup_visibility(world, seen_n, l, world_dx, world_dy, pixel, view_depth);
    if emitter_unlit(light.emitter, cone) {
        // Outside a spot's cone or a light's range no light arrives: visibility 0 by
        // definition.
        shadow.x = 0.0;
    }
    if dot(geometric_n, l) <= 0.0 {
        // A surface turned away from the light is shadowed by itself, whatever the map
        // says (the reference ray tracer uses the same geometric test).
        shadow.x = 0.0;
    }
    return shadow;
}

