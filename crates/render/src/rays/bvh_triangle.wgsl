// One caster triangle of the BVH's buffer (bvh.rs's `TriangleGpu`), in world space:
// what the shader tracer walks (trace_bvh.wgsl), the acceleration structures read
// their vertices from (accel.rs), and the touched layer draws (touched.wgsl).
struct BvhTriangle {
    v0: vec3<f32>,
    // Index into bvh_alpha, or NO_ALPHA.
    alpha: u32,
    v1: vec3<f32>,
    // 1 for a triangle of a closed, opaque mesh (bvh.rs's `TriangleGpu::closed`).
    closed: u32,
    v2: vec3<f32>,
    _pad2: u32,
};
