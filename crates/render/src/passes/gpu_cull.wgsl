// Culls the shadow items (`gpu_scene/shadow_items.rs`) for one shadow layer: every
// item that reaches into the layer's frustum and is not wholly of the winding its
// bucket's pipeline culls appends its draw to its bucket's slots in `draws`, and
// `counts` ends holding how many each bucket kept: the count the layer's multi-draw
// reads. Draw order within a bucket follows the atomics, which a depth-only pass with
// a `Less` test does not see: the nearest depth wins whatever comes first.
//
// The tests are the CPU culler's (`gnomon_math::culling::Frustum::classify`,
// `gnomon_math::facing::NormalCone::winding`), in f32 where the CPU's cone test is in
// f64, so both tests here leave a slack for rounding: they may keep a cluster the
// CPU skips, never skip one the CPU keeps.
import package::constants::{CULL_WORKGROUP, WINDING_CCW, WINDING_CW, WINDING_KEPT};

struct ShadowItem {
    min: vec3f,
    bucket: u32,
    max: vec3f,
    has_cone: u32,
    axis: vec3f,
    sin_half_angle: f32,
    index_count: u32,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
}

struct CullView {
    // n · p + d ≥ 0 inside; plane 4 is the near plane.
    planes: array<vec4f, 6>,
    // The projection's centre in homogeneous coordinates, normalized
    // (`gnomon_math::facing::ProjectionCentre`).
    centre: vec4f,
    item_count: u32,
    // 1 where the near plane counts (not for a pass that clamps depth).
    near: u32,
    _pad0: u32,
    _pad1: u32,
}

struct CullBucket {
    first_slot: u32,
    // The winding its pipeline culls: WINDING_KEPT where it culls none.
    culled: u32,
}

// `VkDrawIndexedIndirectCommand`, as `multi_draw_indexed_indirect_count` reads it.
struct DrawArgs {
    index_count: u32,
    instance_count: u32,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
}

@group(0) @binding(0) var<storage, read> items: array<ShadowItem>;
@group(0) @binding(1) var<uniform> view: CullView;
@group(0) @binding(2) var<storage, read> buckets: array<CullBucket>;
@group(0) @binding(3) var<storage, read_write> counts: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> draws: array<DrawArgs>;

// Whether the box lies wholly outside one plane: its corner farthest along the
// plane's normal (the "p-vertex"; Greene, Graphics Gems IV, 1994) is outside by more
// than rounding. The CPU's sum may be ordered or fused differently, so a box within a
// few ulps of a plane is kept here: 1e-6 of the terms' magnitudes is over 10 ulps.
fn outside_frustum(lo: vec3f, hi: vec3f) -> bool {
    if any(lo > hi) {
        return true;
    }
    for (var i = 0u; i < 6u; i++) {
        if i == 4u && view.near == 0u {
            continue;
        }
        let plane = view.planes[i];
        let farthest = select(lo, hi, plane.xyz >= vec3f(0.0));
        let magnitude = dot(abs(plane.xyz), abs(farthest)) + abs(plane.w);
        if dot(plane.xyz, farthest) + plane.w < -1e-6 * magnitude {
            return true;
        }
    }
    return false;
}

// The winding every triangle of the item has, where one holds for all of them
// (`NormalCone::winding`): with h the centre, v = h_w·p − h_xyz for p in the box's
// bounding ball B(c, r), the sign of a·v decides for every normal of the cone when
// |a·v_c| > sin θ·|v_c| + ρ·(1 + sin θ), ρ = |h_w|·r.
fn cone_winding(item: ShadowItem) -> u32 {
    let h = view.centre;
    let c = 0.5 * (item.min + item.max);
    let r = 0.5 * length(item.max - item.min);
    let v = h.w * c - h.xyz;
    let rho = abs(h.w) * r;
    let s = item.sin_half_angle;
    // v and a·v carry f32 rounding of at most a few ulps of |h_w·c| + |h_xyz|: a
    // slack of 1e-5 of it (over 100 ulps) keeps rounding from ever deciding.
    let slack = 1e-5 * (abs(h.w) * length(c) + length(h.xyz));
    let needed = s * length(v) + (rho + slack) * (1.0 + s);
    let along = dot(item.axis, v);
    if along > needed {
        return WINDING_CW;
    }
    if -along > needed {
        return WINDING_CCW;
    }
    return WINDING_KEPT;
}

@compute @workgroup_size(CULL_WORKGROUP)
fn cull(@builtin(global_invocation_id) id: vec3u) {
    let index = id.x;
    if index >= view.item_count {
        return;
    }
    let item = items[index];
    if outside_frustum(item.min, item.max) {
        return;
    }
    let bucket = buckets[item.bucket];
    if bucket.culled != WINDING_KEPT && item.has_cone != 0u && cone_winding(item) == bucket.culled {
        return;
    }
    let slot = atomicAdd(&counts[item.bucket], 1u);
    draws[bucket.first_slot + slot] = DrawArgs(
        item.index_count,
        1u,
        item.first_index,
        item.base_vertex,
        item.first_instance,
    );
}
