// The trace pass of hybrid ray-traced shadows (refine_classify.wgsl): one shadow ray
// per pixel the mask pass listed, dispatched indirectly over the list. The mask pass
// stored each listed pixel lit; a blocked ray stores it shadowed (visibility 0, with
// its map layer for the cascade view).
//
// The ray leaves from the pixel's surface point moved off the surface along the
// camera-facing geometric normal (the side the light is on, or the pixel would face
// away from it and not be listed) toward the light's centre: one ray, the answer
// for a hard light.

// The list and the light's counters, read only: the counters are also the pass's
// indirect dispatch, which no pass may write while it reads them so.
struct ListedPixels {
    groups: vec3<u32>,
    count: u32,
};

@group(1) @binding(3) var<storage, read> unsure_pixels: array<UnsurePixel>;
@group(1) @binding(4) var<storage, read> listed: ListedPixels;

@group(2) @binding(0) var refined_mask: texture_storage_2d<r32float, write>;

// Declared for scene_common.wgsl's material helpers, which this pass never calls: the
// two bindings of the tracer's group that trace.wgsl leaves free for them.
@group(3) @binding(0) var base_color_texture: texture_2d<f32>;
@group(3) @binding(1) var base_color_sampler: sampler;

// A bound on the error of a point rebuilt from the prepass's view depth
// (screen_common.wgsl's `world_at`): four roundings (pixel to NDC, times the depth,
// over the projection's scale, the camera's matrix), each within an ulp of the
// magnitudes involved, so 4ε times its largest coordinate plus its view depth. Less
// lets a ray start under a large, distant ground and hit it (Florence's open ground
// seen from 400 units shadowed a third of itself with none); more lifts rays off
// finely tessellated curved surfaces and lets light leak past their folds.
const RECONSTRUCTION_ERROR: f32 = 4.0 * 1.1920929e-7;

// Whether the ray from the surface point `world` (geometric normal `geometric_n`,
// seen at `view_depth`) toward the light, direction `l`, meets a caster.
fn surface_ray_blocked(world: vec3<f32>, geometric_n: vec3<f32>, l: vec3<f32>, view_depth: f32) -> bool {
    // A sun's ray runs past every caster (t_max beyond the BVH's bounds is harmless);
    // a local light's stops at the light.
    var t_max = 3.0e38;
    if light.kind != LIGHT_SUN {
        t_max = length(light.position - world);
    }
    // The point first leaves the surface by the bound on its rebuild's error, then by
    // Wächter & Binder's offset of ulps of its coordinates.
    let reconstruction = RECONSTRUCTION_ERROR * (max(abs(world.x), max(abs(world.y), abs(world.z))) + view_depth);
    let origin = offset_ray_origin(world + geometric_n * reconstruction, geometric_n);
    return ray_blocked(origin, l, t_max);
}

@compute @workgroup_size(REFINE_GROUP_SIZE)
fn cs_trace(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let count = listed.count;
    // More pixels than REFINE_MAX_GROUPS workgroups cover loop over the rest.
    for (var index = id.x; index < count; index += groups.x * REFINE_GROUP_SIZE) {
        let entry = unsure_pixels[index];
        let texel = vec2<u32>(entry.pixel & 0xffffu, entry.pixel >> 16u);
        let view_depth = textureLoad(prepass_view_depth, texel, 0).x;
        let geometric_n = octahedron_decode(textureLoad(prepass_normals, texel, 0).zw);
        let world = world_at(vec2<f32>(texel) + vec2<f32>(0.5), view_depth);
        let l = light_geometry(world).xyz;
        if surface_ray_blocked(world, geometric_n, l, view_depth) {
            textureStore(refined_mask, texel, vec4<f32>(2.0 * f32(entry.layer), 0.0, 0.0, 0.0));
        }
    }
}
