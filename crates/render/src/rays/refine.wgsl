// Hybrid ray-traced shadows (after Story's HFTS, GDC 2016, and Unreal's shadow-map
// ray tracing): the map answers where it is sure, a ray where it is not. A pixel is
// unsure when its filtered visibility is strictly between 0 and 1 (the taps disagree:
// the edge band), or when `map_unsure` (refine_map.wgsl, refine_omni.wgsl) finds its
// footprint in the map ambiguous. `REFINE_EVERY_PIXEL` traces every pixel instead:
// the exact baseline.
//
// The ray leaves from the pixel's surface point moved off the surface by Wächter &
// Binder's offset along the camera-facing geometric normal (the side the light is on,
// or the pixel is shadowed by its own surface and needs no ray), toward the light's
// centre: one ray, the answer for a hard light.

// A bound on the error of a point rebuilt from the prepass's view depth
// (shadow_mask.wgsl's `world_at`): four roundings (pixel to NDC, times the depth,
// over the projection's scale, the camera's matrix), each within an ulp of the
// magnitudes involved, so 4ε times its largest coordinate plus its view depth. Less
// lets a ray start under a large, distant ground and hit it (Florence's open ground
// seen from 400 units shadowed a third of itself with none); more lifts rays off
// finely tessellated curved surfaces and lets light leak past their folds.
const RECONSTRUCTION_ERROR: f32 = 4.0 * 1.1920929e-7;

fn refined_visibility(
    visibility: f32,
    world: vec3<f32>,
    n: vec3<f32>,
    geometric_n: vec3<f32>,
    l: vec3<f32>,
    cone: f32,
    view_depth: f32,
) -> f32 {
    // Facing away from the light, or outside its cone or range: dark by definition,
    // which the map's answer already says.
    if dot(geometric_n, l) <= 0.0 || (light.kind != LIGHT_SUN && cone <= 0.0) {
        return visibility;
    }
    let unsure = REFINE_EVERY_PIXEL || (visibility > 0.0 && visibility < 1.0)
        || map_unsure(world, facing_side(n, geometric_n), geometric_n, l, view_depth);
    if !unsure {
        return visibility;
    }
    // A sun's ray runs past every caster (t_max beyond the BVH's bounds is harmless);
    // a local light's stops at the light.
    var t_max = 3.0e38;
    if light.kind != LIGHT_SUN {
        t_max = length(light.position - world);
    }
    // The pixel's point is rebuilt from its view depth, a few ulps of its distances
    // off the true surface: on a ground plane at y ≈ 0 seen from 400 units, far more
    // than Wächter & Binder's offset of ulps of y, so the ray would start below the
    // ground and hit it. The point first leaves the surface by a bound on that error.
    let reconstruction = RECONSTRUCTION_ERROR * (max(abs(world.x), max(abs(world.y), abs(world.z))) + view_depth);
    let origin = offset_ray_origin(world + geometric_n * reconstruction, geometric_n);
    return select(1.0, 0.0, ray_blocked(origin, l, t_max));
}
