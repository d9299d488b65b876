// Percentage-closer soft shadows (R. Fernando, "Percentage-closer soft shadows",
// SIGGRAPH 2005 sketch), for a light of size w_light (light.emitter.size: the spot's disk
// radius in world units, or tan of the sun's angular radius):
// 1. Blocker search: average the distance d_blocker of the map texels nearer the
//    light than the receiver, over the region where a blocker could hide part of
//    the light from the receiver.
// 2. Penumbra estimate from similar triangles: w = (d_receiver − d_blocker) ·
//    w_light / d_blocker for a spot (distances from the light), or
//    (d_receiver − d_blocker) · tan(angular radius) for a sun.
//    Both are each kind's similar triangles: `emitter_cone_radius` and
//    `emitter_penumbra_radius` (passes/light_kinds.wgsl).
// 3. PCF over a Poisson disk of that radius.
// Both the search region and the penumbra are converted to texels with the map's
// projection: perspective texels grow with distance, orthographic ones do not.
import package::passes::light_binding::{light, light_distance_from_depth, texel_shape, texel_world_size_at};
import package::passes::light_kinds::{emitter_cone_radius, emitter_penumbra_radius};
import package::techniques::bindings::shadow_map;
import package::techniques::common::{ShadowQuery, disk_rotation, pcf_poisson, receiver_depth_gradient};
import package::variant::POISSON_DISK;

// Radius in texels of layer `layer` of a world length `world` that lies at light
// distance `at`.
fn world_to_texels(layer: u32, world: f32, at: f32) -> f32 {
    return world / texel_world_size_at(layer, at);
}

fn pcss_sample_shadow(q: ShadowQuery) -> f32 {
    let max_search = light.pcss.max_search_texels;
    let max_penumbra = light.pcss.max_penumbra_texels;
    let d_receiver = q.distance;
    let near = light.map.near;

    // 1. The search region: the cross-section at the near plane of the cone from the
    // receiver to the light, where the nearest possible blockers lie.
    // Measured along each of the map's axes in that axis's own texels
    // (`texel_shape`): a disk in the world, an ellipse on an oblong-texel map.
    let shape = texel_shape(q.layer);
    let search_world = emitter_cone_radius(light.emitter, d_receiver, near);
    let search = clamp(world_to_texels(q.layer, search_world, near) / shape, vec2<f32>(1.0), vec2<f32>(max_search));

    let gradient = receiver_depth_gradient(q);
    let rotation = disk_rotation(q.pixel);
    let dims = vec2<i32>(textureDimensions(shadow_map));
    let taps = light.pcss.blocker_taps;
    var blocker_sum = 0.0;
    var blockers = 0.0;
    for (var i = 0u; i < taps; i++) {
        let offset = rotation * POISSON_DISK[i] * search;
        let duv = offset / light.map.resolution;
        let uv = q.coords.xy + duv;
        let texel = clamp(vec2<i32>(floor(uv * light.map.resolution)), vec2<i32>(0), dims - vec2<i32>(1));
        let stored = textureLoad(shadow_map, texel, q.layer, 0);
        if stored < q.coords.z + dot(gradient, duv) {
            blocker_sum += light_distance_from_depth(stored);
            blockers += 1.0;
        }
    }
    if blockers == 0.0 {
        return 1.0;
    }
    let d_blocker = blocker_sum / blockers;

    // 2. The penumbra's radius at the receiver.
    let penumbra_world = emitter_penumbra_radius(light.emitter, max(d_receiver - d_blocker, 0.0), d_blocker);
    let penumbra = world_to_texels(q.layer, penumbra_world, d_receiver) / shape;
    // 3. At least the bilinear tap's own half-texel footprint.
    return pcf_poisson(q, clamp(penumbra, vec2<f32>(0.5), vec2<f32>(max_penumbra)), light.pcf.poisson_taps);
}
