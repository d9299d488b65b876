// The penumbra classification (penumbra_classify.wgsl) of a 2D map: a sun's map or
// cascades, a spot's map. A receiver is placed in the layer its lookup would read
// (`select_cascade`), at its projected texel and depth.
import package::passes::light_binding::light;
import package::passes::map_visibility::select_cascade;
import package::rays::map_step::map_step;
import package::rays::penumbra_classify::{Receiver, classify_receiver, map_reach, plane_gradient, seen_plane_normal, unplaced_receiver};

// The receiver at `world` (its plane through the screen derivatives `world_dx`,
// `world_dy`) in 2D layer `layer`.
fn map_receiver(world: vec3<f32>, world_dx: vec3<f32>, world_dy: vec3<f32>, layer: u32) -> Receiver {
    let clip_from_world = light.cascade_clip_from_world[layer];
    let clip = clip_from_world * vec4<f32>(world, 1.0);
    let a = map_step(clip_from_world, clip.xyz / clip.w, clip.w, world_dx);
    let b = map_step(clip_from_world, clip.xyz / clip.w, clip.w, world_dy);
    if clip.w <= 0.0 || abs(a.x * b.y - a.y * b.x) <= 1e-20 {
        return unplaced_receiver(layer, false);
    }
    let ndc = clip.xyz / clip.w;
    let texel = (ndc.xy * vec2<f32>(0.5, -0.5) + vec2<f32>(0.5)) * light.map.resolution - vec2<f32>(0.5);
    let distance = -(light.light_from_world * vec4<f32>(world, 1.0)).z;
    return Receiver(texel, ndc.z, plane_gradient(a, b), distance, layer, false);
}

// `lookup_visibility` for a light with an area whose penumbrae are traced, on a 2D
// map: (`CLASSIFIED_*`, the layer that holds the receiver).
fn penumbra_map_lookup(
    world: vec3<f32>,
    n: vec3<f32>,
    l: vec3<f32>,
    world_dx: vec3<f32>,
    world_dy: vec3<f32>,
    pixel: vec2<f32>,
    view_depth: f32,
) -> vec2<f32> {
    let layer = select_cascade(view_depth, world, n, l);
    let r = map_receiver(world, world_dx, world_dy, layer);
    let visibility = classify_receiver(r, map_reach(r), seen_plane_normal(n, world_dx, world_dy), world);
    return vec2<f32>(visibility, f32(layer));
}

// The layer that holds the receiver at `world` (`select_cascade`), for a pixel whose
// classification the penumbra history kept (penumbra_mask.wgsl).
fn map_penumbra_layer(world: vec3<f32>, n: vec3<f32>, l: vec3<f32>, view_depth: f32) -> f32 {
    return f32(select_cascade(view_depth, world, n, l));
}
