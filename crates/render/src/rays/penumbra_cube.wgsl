// The penumbra classification (penumbra_classify.wgsl) of a point light's cube: a
// receiver is placed on the face its direction from the light falls on
// (`cube_face`), in that face's own projection, at `cube_depth` of its distance
// along the face's axis.
import package::passes::cube_visibility::cube_face;
import package::passes::light_binding::light;
import package::rays::map_step::map_step;
import package::rays::penumbra_classify::{Receiver, classify_receiver, cube_depth, cube_reach, plane_gradient, seen_plane_normal, unplaced_receiver};

// The receiver at `world` on its face of a point light's cube: the face's projection
// places it, and its depth is `cube_depth` of its distance along the face's axis
// (the face's clip w), whose change along a tangent t is near Δw / w².
fn cube_receiver(world: vec3<f32>, world_dx: vec3<f32>, world_dy: vec3<f32>) -> Receiver {
    let face = cube_face(world - light.emitter.position);
    let clip_from_world = light.cascade_clip_from_world[face];
    let clip = clip_from_world * vec4<f32>(world, 1.0);
    let ndc = clip.xyz / clip.w;
    let step = light.map.near / (clip.w * clip.w);
    let a = vec3<f32>(map_step(clip_from_world, ndc, clip.w, world_dx).xy, step * (clip_from_world * vec4<f32>(world_dx, 0.0)).w);
    let b = vec3<f32>(map_step(clip_from_world, ndc, clip.w, world_dy).xy, step * (clip_from_world * vec4<f32>(world_dy, 0.0)).w);
    if clip.w <= 0.0 || abs(a.x * b.y - a.y * b.x) <= 1e-20 {
        return unplaced_receiver(face, true, world);
    }
    let texel = (ndc.xy * vec2<f32>(0.5, -0.5) + vec2<f32>(0.5)) * light.map.resolution - vec2<f32>(0.5);
    return Receiver(texel, cube_depth(clip.w), plane_gradient(a, b), clip.w, face, true, world);
}

// `lookup_visibility` for a point light with an area whose penumbrae are traced, on
// its cube: (`CLASSIFIED_*`, the face that holds the receiver).
fn penumbra_cube_lookup(
    world: vec3<f32>,
    n: vec3<f32>,
    l: vec3<f32>,
    world_dx: vec3<f32>,
    world_dy: vec3<f32>,
    pixel: vec2<f32>,
    view_depth: f32,
) -> vec2<f32> {
    let r = cube_receiver(world, world_dx, world_dy);
    let reach = cube_reach(r, world - light.emitter.position);
    let visibility = classify_receiver(r, reach, seen_plane_normal(n, world_dx, world_dy), world);
    return vec2<f32>(visibility, f32(r.layer));
}
// The face that holds the receiver at `world`, for a pixel whose classification the
// penumbra history kept (penumbra_mask.wgsl).
fn cube_penumbra_layer(world: vec3<f32>, n: vec3<f32>, l: vec3<f32>, view_depth: f32) -> f32 {
    return f32(cube_face(world - light.emitter.position));
}
