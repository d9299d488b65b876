// One shadow ray per invocation (query.rs): 1 in `answers` where a caster blocks it.
import package::rays::trace_common::ray_blocked;
import package::variant::QUERY_WORKGROUP;

struct QueryRay {
    origin: vec3<f32>,
    length: f32,
    direction: vec3<f32>,
    _pad: f32,
};

@group(0) @binding(0) var<storage, read> query_rays: array<QueryRay>;
@group(0) @binding(1) var<storage, read_write> answers: array<u32>;

@compute @workgroup_size(QUERY_WORKGROUP)
fn cs_query(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let index = id.x + id.y * groups.x * QUERY_WORKGROUP;
    if index >= arrayLength(&query_rays) {
        return;
    }
    let ray = query_rays[index];
    answers[index] = select(0u, 1u, ray_blocked(ray.origin, ray.direction, ray.length));
}
