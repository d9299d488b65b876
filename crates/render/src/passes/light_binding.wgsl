// The light uniform, declared once for every pass that reads it, and the functions
// that read it, at the group and binding its pass's generated constants name (`light_binding_wgsl` in passes/mod.rs):
// group 0 binding 1 in Gnomon's own passes, beside the instances; binding 0 of the
// host's group in the shadow receiver.
import package::passes::light::Light;
import package::passes::light_kinds::{emitter_depth_from_distance, emitter_distance_from_depth};
import package::variant::{LIGHT_BINDING, LIGHT_GROUP};

@group(LIGHT_GROUP) @binding(LIGHT_BINDING) var<uniform> light: Light;

// The view depth where cascade `i` starts; `i + 1` where it ends.
fn cascade_split(i: u32) -> f32 {
    if i == 0u {
        return light.cascades[0].split_start;
    }
    return light.cascades[i - 1u].split_end;
}

// World size of one texel of layer `layer` at light distance `distance`.
fn texel_world_size_at(layer: u32, distance: f32) -> f32 {
    return light.cascades[layer].texel_world + light.map.texel_per_distance * max(distance, 0.0);
}

// A texel's size along the map's x and y axes over `texel_world_size_at`'s, the
// larger of the two. A sun's map fitted to a window wider than it is tall (the
// receivers under a low sun: long across the light, short along it) has texels
// shorter along y; a search or a filter measured in the larger texel alone spans
// only part of its world radius along the shorter axis (on `grazing` under a 2° sun,
// the fading tip of the box's shadow: the refinement's search kept PCSS's umbra, and
// PCSS's penumbra was half as wide as the truth's). Spot maps have square texels; a
// warped map's are measured as their largest extent (`local_texel_world_size`), so
// taken square.
fn texel_shape(layer: u32) -> vec2<f32> {
    if light.cascades[layer].warped != 0u {
        return vec2<f32>(1.0);
    }
    // World units to clip units along the map's axes: the lengths of the first two
    // rows of the projection (an orthographic or symmetric perspective one).
    let m = light.cascade_clip_from_world[layer];
    let scale = vec2<f32>(length(vec3<f32>(m[0].x, m[1].x, m[2].x)), length(vec3<f32>(m[0].y, m[1].y, m[2].y)));
    return vec2<f32>(min(scale.x, scale.y)) / scale;
}

// Distance along the light's axis (light view −z) of a point whose shadow-map depth
// is `depth` (how each kind's map stores it: `emitter_distance_from_depth`).
fn light_distance_from_depth(depth: f32) -> f32 {
    return emitter_distance_from_depth(light.emitter, light.map.near, light.map.far, depth);
}

// The depth a shadow map stores for a point at light distance `distance`.
fn light_depth_from_distance(distance: f32) -> f32 {
    return emitter_depth_from_distance(light.emitter, light.map.near, light.map.far, distance);
}

// The depth that moment maps store: light distance, linear in [0, 1] from the near
// to the far plane, so that filtering averages distances, not projected depths.
fn moment_depth(depth: f32) -> f32 {
    let n = light.map.near;
    let f = light.map.far;
    return clamp((light_distance_from_depth(depth) - n) / (f - n), 0.0, 1.0);
}
