// Gnomon's shadow receiver: the shadows of one light, for a host's own fragment
// shader. Linked with what it imports (the light and camera, the technique's lookup
// and the rules of resolve_visibility.wgsl) into plain WGSL; the host's shader
// follows it in one module.
//
// Every resource sits in one bind group, at the index the host chose, in the order of
// `Layouts::receiver`: the light (light_binding.wgsl) at binding 0, the camera
// (camera_binding.wgsl) at 1, and the shadow resources (techniques/bindings.wgsl)
// from 2, each placed by generated constants (`receiver_wgsl` in receiver.rs).
import package::passes::camera_binding::camera;
import package::passes::light_binding::light;
import package::passes::shading::light_geometry;
import package::variant::pixel_visibility;

// The fraction of this light that reaches the surface point `world` (world space), in
// [0, 1]: 0 in shadow, on a surface turned away from the light, or outside a spot's
// cone or a light's range; 1 fully lit. Exactly what Gnomon's own lighting pass
// computes for the same point.
//
// `normal`: the unit shading normal, on either side: it is turned to the side the
// camera sees, by the triangle's plane. `frag_coord`: the fragment's
// `@builtin(position)`, for the per-pixel rotation of the filter taps.
//
// Call it from a fragment shader in uniform control flow, before any `discard`: it
// takes the screen derivatives of `world` (the receiver's plane, the geometric normal).
fn shadow_visibility(world: vec3<f32>, normal: vec3<f32>, frag_coord: vec4<f32>) -> f32 {
    let world_dx = dpdx(world);
    let world_dy = dpdy(world);
    // The triangle's plane normal, facing the camera (as surface.wgsl derives it).
    var geometric_n = normalize(cross(world_dx, world_dy));
    if dot(geometric_n, camera.eye - world) < 0.0 {
        geometric_n = -geometric_n;
    }
    let geometry = light_geometry(world);
    let view_depth = -(camera.view_from_world * vec4<f32>(world, 1.0)).z;
    let shadow = pixel_visibility(
        world, normal, geometric_n, geometry.xyz, geometry.w, world_dx, world_dy, frag_coord.xy, view_depth
    );
    return shadow.x;
}

// The light as seen from `world`, before shadowing: the unit direction towards the
// light (xyz) and the fraction that arrives there (w: 1 for a sun, a spot's cone
// falloff, 0 beyond a light's range). Its colour times intensity is
// `shadow_light_radiance()`.
fn shadow_light_direction(world: vec3<f32>) -> vec4<f32> {
    return light_geometry(world);
}

// The light's colour times its intensity (linear RGB).
fn shadow_light_radiance() -> vec3<f32> {
    return light.emitter.radiance;
}
