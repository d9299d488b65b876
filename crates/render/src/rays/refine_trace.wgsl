// The trace pass of hybrid ray-traced shadows (refine_classify.wgsl), dispatched
// indirectly over the pixels the mask pass listed.
//
// Under a hard light, one shadow ray per pixel toward the light's centre: the mask
// pass stored each listed pixel lit, and a blocked ray stores it shadowed
// (visibility 0, with its map layer for the cascade view).
//
// Under a light with an area, `light.penumbra_rays` rays per pixel toward points
// stratified over the light (light_sample.wgsl), and the pixel stores the share that
// arrive: a Monte Carlo estimate of the same integral as the CPU reference's, whose
// noise the filter pass (`cs_filter_penumbra`) then smooths. The estimate replaces
// contact shadows there: the rays see the casters that contact shadows approximate.
//
// Rays leave from the pixel's surface point moved off the surface along the
// camera-facing geometric normal (the side the light is on, or the pixel would face
// away from it and not be listed).

// The list and the light's counters, read only: the counters are also the pass's
// indirect dispatch, which no pass may write while it reads them so.
struct ListedPixels {
    groups: vec3<u32>,
    count: u32,
};

@group(1) @binding(3) var<storage, read> unsure_pixels: array<UnsurePixel>;
@group(1) @binding(4) var<storage, read> listed: ListedPixels;

@group(2) @binding(0) var refined_mask: texture_storage_2d<r32float, write>;
// A copy of the mask as the trace pass left it, which the filter pass reads.
@group(2) @binding(1) var traced_mask: texture_2d<f32>;

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
    var t_max = 3.0e38;
    if light.kind != LIGHT_SUN {
        t_max = length(light.position - world);
    }
    return ray_blocked(origin, l, t_max);
}

// The share of `light.penumbra_rays` rays from `origin` to points stratified over the
// light's area that arrive. `pixel` seeds the pixel's own pattern, so neighbours'
// errors are independent and the filter pass averages them down. A sample below the
// surface's horizon is blocked by the surface itself, as in the reference.
fn area_visibility(origin: vec3<f32>, world: vec3<f32>, geometric_n: vec3<f32>, pixel: u32) -> f32 {
    let count = light.penumbra_rays;
    let grid = cmj_grid(count);
    let pattern = lowbias32(pixel ^ 0x9e3779b9u);
    var arrived = 0u;
    for (var s = 0u; s < count; s++) {
        let ray = light_sample(world, cmj(s, count, grid, pattern));
        if dot(ray.xyz, geometric_n) > 0.0 && !ray_blocked(origin, ray.xyz, ray.w) {
            arrived += 1u;
        }
    }
    return f32(arrived) / f32(count);
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
        let origin = surface_ray_origin(world, geometric_n, view_depth);
        let layer = 2.0 * f32(entry.layer);
        if light.penumbra_rays > 0u {
            let visibility = area_visibility(origin, world, geometric_n, entry.pixel);
            textureStore(refined_mask, texel, vec4<f32>(layer + visibility, 0.0, 0.0, 0.0));
        } else if centre_ray_blocked(origin, world, light_geometry(world).xyz) {
            textureStore(refined_mask, texel, vec4<f32>(layer, 0.0, 0.0, 0.0));
        }
    }
}

// The penumbra's filter, after the trace pass under a light with an area: each
// listed pixel's visibility becomes a weighted average of its 3×3 neighbours',
// traced or not, read from the copy `traced_mask` (a cross-bilateral filter, after
// Tomasi & Manduchi 1998 and the joint bilateral upsampling of Kopf et al. 2007):
// - spatial weights 1 2 1 / 2 4 2 / 1 2 1, a binomial kernel that leaves a
//   visibility linear across three pixels unchanged;
// - only neighbours on the same surface: within SURFACE_PIXELS pixel widths of the
//   centre's tangent plane, with normals within SURFACE_COS, so that no caster's
//   value is carried onto the floor behind it;
// - only neighbours the light can reach (facing it, inside its cone);
// - a range weight (`range_weight`) that keeps hard edges hard.
// With each pixel's own pattern the estimates' noise is independent, and where all
// nine count the weights' sum of squares is 36/256 of their squared sum: the noise's
// standard deviation falls to 6/16 of one pixel's.
// The kernel's reach in pixels, and its weights along each axis. A 5 × 5 binomial
// did worse on `contact` (penumbra MAE 0.0192 against 0.0179): most penumbra pixels
// lie within a few pixels of a contact, where a wider kernel blurs.
const FILTER_RADIUS: i32 = 1;
const BINOMIAL = array<f32, 3>(1.0, 2.0, 1.0);
// The range weight's width, in standard deviations of the estimates (1.5 and 2
// measured 0.0191 and 0.0182 there, 3 measured 0.0179).
const RANGE_SIGMAS: f32 = 3.0;
const SURFACE_PIXELS: f32 = 2.0;
const SURFACE_COS: f32 = 0.9;

// How much a neighbour's visibility `q` counts toward the centre's `p`: a Gaussian in
// their difference, RANGE_SIGMAS times as wide as the larger of their estimates'
// binomial standard deviations √(v(1 − v)/N). Two estimates of 0 and 1 have none, and never mix: a
// contact shadow's hard edge stays hard, where a penumbra's noisy middle is averaged.
fn range_weight(p: f32, q: f32) -> f32 {
    let variance = max(p * (1.0 - p), q * (1.0 - q)) / f32(light.penumbra_rays);
    let d = p - q;
    return select(exp(-d * d / (2.0 * RANGE_SIGMAS * RANGE_SIGMAS * variance)), select(0.0, 1.0, d == 0.0), variance == 0.0);
}

// The visibility of a mask texel, which stores it plus 2 × the map layer.
fn mask_visibility(packed: f32) -> f32 {
    return packed - 2.0 * floor(packed * 0.5);
}

@compute @workgroup_size(REFINE_GROUP_SIZE)
fn cs_filter_penumbra(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let count = listed.count;
    let size = vec2<i32>(textureDimensions(traced_mask));
    for (var index = id.x; index < count; index += groups.x * REFINE_GROUP_SIZE) {
        let entry = unsure_pixels[index];
        let texel = vec2<i32>(i32(entry.pixel & 0xffffu), i32(entry.pixel >> 16u));
        let view_depth = textureLoad(prepass_view_depth, texel, 0).x;
        let n = octahedron_decode(textureLoad(prepass_normals, texel, 0).zw);
        let world = world_at(vec2<f32>(texel) + vec2<f32>(0.5), view_depth);
        // A pixel's width in world units at this depth.
        let pixel_world = 2.0 * view_depth / (camera.scale_y * camera.height);
        let visibility = mask_visibility(textureLoad(traced_mask, texel, 0).x);
        var sum = 0.0;
        var weights = 0.0;
        for (var dy = -FILTER_RADIUS; dy <= FILTER_RADIUS; dy++) {
            for (var dx = -FILTER_RADIUS; dx <= FILTER_RADIUS; dx++) {
                let q = texel + vec2<i32>(dx, dy);
                if any(q < vec2<i32>(0)) || any(q >= size) {
                    continue;
                }
                let q_depth = textureLoad(prepass_view_depth, q, 0).x;
                if q_depth <= 0.0 {
                    continue;
                }
                let q_n = octahedron_decode(textureLoad(prepass_normals, q, 0).zw);
                let q_world = world_at(vec2<f32>(q) + vec2<f32>(0.5), q_depth);
                let off_plane = abs(dot(n, q_world - world));
                if off_plane > SURFACE_PIXELS * pixel_world || dot(n, q_n) < SURFACE_COS {
                    continue;
                }
                // A neighbour facing away from the light or outside its cone is dark by
                // definition, not by a caster: it says nothing of this pixel's penumbra.
                let q_light = light_geometry(q_world);
                if dot(q_n, q_light.xyz) <= 0.0 || q_light.w <= 0.0 {
                    continue;
                }
                let q_visibility = mask_visibility(textureLoad(traced_mask, q, 0).x);
                let w = BINOMIAL[dx + FILTER_RADIUS] * BINOMIAL[dy + FILTER_RADIUS] * range_weight(visibility, q_visibility);
                sum += w * q_visibility;
                weights += w;
            }
        }
        // The centre always shares its own surface and weighs 4.
        textureStore(refined_mask, texel, vec4<f32>(2.0 * f32(entry.layer) + sum / weights, 0.0, 0.0, 0.0));
    }
}
