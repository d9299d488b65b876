import package::rays::trace_common::alpha_blocks;
import package::variant::TRACE_GROUP;

enable wgpu_ray_query;

// Shadow rays through the adapter's own acceleration structures (accel.rs), by ray
// queries (wgpu's EXPERIMENTAL_RAY_QUERY, Vulkan's VK_KHR_ray_query): ray-tracing
// hardware where the GPU has it. The casters are the triangles that trace_bvh.wgsl
// walks, in two geometries: the opaque ones, which the traversal commits on its own,
// and the cut-out ones, which it hands back here as candidates to alpha-test
// (trace_common.wgsl). A cut-out triangle's primitive index is its alpha test's
// index: accel.rs lists them in that order.
//
// The intersection test is the adapter's, not Woop et al.'s, and it has no bound on
// the error of t: the ray's origin, already moved off its surface by Wächter &
// Binder's offset, is what keeps it from meeting the surface it leaves, so the ray
// starts at t = 0.
//
// Binding 2 of group TRACE_GROUP: the top-level structure.

@group(TRACE_GROUP) @binding(2) var casters: acceleration_structure;

// The distance along the segment from `origin` along the unit `direction` to the
// first caster the query meets before `t_max`, or -1 where none blocks it. The
// first hit ends the query (a shadow ray needs no closest one), so this is some
// caster's distance, not the nearest's.
fn query_ray_first_hit(origin: vec3<f32>, direction: vec3<f32>, t_max: f32) -> f32 {
    var query: ray_query;
    rayQueryInitialize(&query, casters, RayDesc(RAY_FLAG_TERMINATE_ON_FIRST_HIT, 0xffu, 0.0, t_max, origin, direction));
    while rayQueryProceed(&query) {
        // Only cut-out triangles are candidates: the rest are opaque.
        let candidate = rayQueryGetCandidateIntersection(&query);
        let b = candidate.barycentrics;
        if alpha_blocks(candidate.primitive_index, vec3<f32>(1.0 - b.x - b.y, b.x, b.y), 1.0) {
            rayQueryConfirmIntersection(&query);
        }
    }
    let hit = rayQueryGetCommittedIntersection(&query);
    return select(-1.0, hit.t, hit.kind != RAY_QUERY_INTERSECTION_NONE);
}
