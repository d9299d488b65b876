// Shadow rays from a surface point seen on screen, shared by the trace pass
// (refine_trace.wgsl, on the mask path) and the forward lighting pass
// (refine_forward.wgsl): where they start, the ray to a hard light's centre, and the
// share of rays over a light's area that arrive. Needs trace.wgsl, light_sample.wgsl
// and the light's uniform.
import package::passes::light_binding::light;
import package::passes::light_kinds::{emitter_ray_length, emitter_sample, emitter_sample_weight};
import package::rays::light_sample::{cmj, cmj_grid, lowbias32};
import package::rays::trace_common::{offset_ray_origin, ray_blocked};
import package::variant::ray_first_hit;

// A bound on how far the surface point off its triangle may lie: the point is the
// rasterizer's interpolation of the vertices' world positions (the prepass's, or the
// lighting pass's own), a weighted sum whose weights add up to 1 to within a few
// roundings, each within an ulp of the magnitudes involved, so 4ε times its largest
// coordinate plus its view depth. Less lets a ray start under a large, distant ground
// and hit it (Florence's open ground seen from 400 units shadowed a third of itself
// with none); more lifts rays off finely tessellated curved surfaces and lets light
// leak past their folds.
const RECONSTRUCTION_ERROR: f32 = 4.0 * 1.1920929e-7;

// The origin of shadow rays from the surface point `world` (geometric normal
// `geometric_n`, seen at `view_depth`): the point first leaves the surface by the
// bound on its rebuild's error, then by Wächter & Binder's offset of ulps of its
// coordinates.
fn surface_ray_origin(world: vec3<f32>, geometric_n: vec3<f32>, view_depth: f32) -> vec3<f32> {
    let reconstruction = RECONSTRUCTION_ERROR * (max(abs(world.x), max(abs(world.y), abs(world.z))) + view_depth);
    return offset_ray_origin(world + geometric_n * reconstruction, geometric_n);
}

// Whether the ray from `origin` toward the light's centre, direction `l`, meets a
// caster. A sun's ray runs past every caster (t_max beyond the BVH's bounds is
// harmless); a local light's stops at the light.
fn centre_ray_blocked(origin: vec3<f32>, world: vec3<f32>, l: vec3<f32>) -> bool {
    return ray_blocked(origin, l, emitter_ray_length(light.emitter, world));
}

// `area_visibility` by rays, where they cannot walk a penumbra beam (ray queries):
// the share of `light.rays.penumbra_rays` rays from `origin` to points stratified over the
// light's area that arrive, each weighted by its point's falloff
// (`emitter_sample_weight`), and the mean distance to the caster that each blocked
// ray met (-1 when none was blocked). `pixel` seeds the pixel's own pattern, so
// neighbours' errors are independent and the filter pass averages them down. A
// sample below the surface's horizon is blocked by the surface itself, as in the
// reference, and has no caster's distance.
fn ray_area_visibility(origin: vec3<f32>, world: vec3<f32>, geometric_n: vec3<f32>, pixel: u32) -> vec2<f32> {
    let count = light.rays.penumbra_rays;
    let grid = cmj_grid(count);
    let pattern = lowbias32(pixel ^ 0x9e3779b9u);
    var arrived = 0.0;
    var total = 0.0;
    var blocked = 0u;
    var blocker_distance = 0.0;
    for (var s = 0u; s < count; s++) {
        let ray = emitter_sample(light.emitter, world, cmj(s, count, grid, pattern));
        let weight = emitter_sample_weight(light.emitter, ray.w);
        total += weight;
        if dot(ray.xyz, geometric_n) <= 0.0 {
            continue;
        }
        let t = ray_first_hit(origin, ray.xyz, ray.w);
        if t < 0.0 {
            arrived += weight;
        } else {
            blocked += 1u;
            blocker_distance += t;
        }
    }
    let mean_blocker = select(-1.0, blocker_distance / f32(max(blocked, 1u)), blocked > 0u);
    return vec2<f32>(arrived / max(total, 1e-30), mean_blocker);
}
