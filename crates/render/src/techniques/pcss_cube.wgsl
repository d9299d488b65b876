// PCSS on a point light's cube map (Fernando 2005, as pcss.wgsl), for a sphere of
// radius w_light (light.emitter.size). Distances are from the light's centre; every
// offset is across the ray, in texels at the receiver.
import package::passes::light_binding::light;
import package::techniques::bindings::{shadow_cube, shadow_gather};
import package::techniques::common::disk_rotation;
import package::techniques::cube::{CubeQuery, cube_direction, cube_pcf_poisson, cube_tap_depth};
import package::variant::POISSON_DISK;

fn pcss_sample_shadow_cube(q: CubeQuery) -> f32 {
    let size = light.emitter.size;
    let max_search = light.pcss.max_search_texels;
    let max_penumbra = light.pcss.max_penumbra_texels;
    let range = light.emitter.range;
    let near = light.map.near;
    let d_receiver = q.depth * range;

    // 1. The search region: a blocker at distance t hides the light from the receiver
    // within size·(d − t)/t across the ray at the receiver, the most at the near plane.
    let search = clamp(size * (d_receiver - near) / near / q.texel_world, 1.0, max_search);
    let rotation = disk_rotation(q.pixel);
    let taps = light.pcss.blocker_taps;
    var blocker_sum = 0.0;
    var blockers = 0.0;
    for (var i = 0u; i < taps; i++) {
        let direction = cube_direction(q, rotation * POISSON_DISK[i] * search);
        let stored = textureGather(shadow_cube, shadow_gather, direction);
        let nearer = vec4<f32>(stored < vec4<f32>(cube_tap_depth(q, direction)));
        blocker_sum += dot(nearer, stored);
        blockers += dot(nearer, vec4<f32>(1.0));
    }
    if blockers == 0.0 {
        return 1.0;
    }
    let d_blocker = max(blocker_sum / blockers * range, near);

    // 2. The penumbra's radius at the receiver, by similar triangles.
    let penumbra = size * max(d_receiver - d_blocker, 0.0) / d_blocker / q.texel_world;
    // 3. At least the bilinear tap's own half-texel footprint.
    return cube_pcf_poisson(q, clamp(penumbra, 0.5, max_penumbra), light.pcf.poisson_taps);
}
