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

// The light's counters, read only: they are also the pass's indirect dispatch, which
// no pass may write while it reads them so.
struct ListedPixels {
    groups: vec3<u32>,
    count: u32,
};

// The list, whose entries the trace pass completes with their filter radius.
@group(1) @binding(3) var<storage, read_write> unsure_pixels: array<UnsurePixel>;
@group(1) @binding(4) var<storage, read> listed: ListedPixels;

@group(2) @binding(0) var refined_mask: texture_storage_2d<r32float, write>;
// A copy of the mask as the trace pass left it, which the filter pass reads.
@group(2) @binding(1) var traced_mask: texture_2d<f32>;

// Declared for scene_common.wgsl's material helpers, which this pass never calls: the
// two bindings of the tracer's group that trace.wgsl leaves free for them.
@group(3) @binding(0) var base_color_texture: texture_2d<f32>;
@group(3) @binding(1) var base_color_sampler: sampler;

// The penumbra filter's radius at a pixel whose blocked rays met casters `blocker`
// away on average (-1: none), on a surface of normal `geometric_n` seen at
// `view_depth`: a quarter of the penumbra's width in pixels, from similar triangles
// (Fernando 2005: w = 2 r_light · d_blocker / (d_light − d_blocker) at the receiver,
// 2 tan(θ_sun) · d_blocker under a sun), from 1 to MAX_FILTER_RADIUS. A binomial
// kernel of radius r has a variance of r/2 px²; a penumbra w px wide from 10 % to
// 90 % has one of about (w / 2.56)², so a radius of w / 4 widens it by
// √(1 + 0.82 / w): 10 % at w = 4, 3 % at w = 12, while the noise of 16 rays falls
// with every pixel the kernel takes in.
fn penumbra_filter_radius(blocker: f32, world: vec3<f32>, geometric_n: vec3<f32>, view_depth: f32) -> u32 {
    if blocker < 0.0 {
        return 1u;
    }
    var width = 2.0 * light.light_size * blocker;
    if light.kind != LIGHT_SUN {
        width /= max(length(light.position - world) - blocker, 1e-6);
    }
    // On screen the receiver's plane is foreshortened by |n·v| across its steepest
    // direction: the penumbra is at least that narrow there, and the kernel is round.
    width *= abs(dot(geometric_n, normalize(camera.eye - world)));
    let pixel_world = 2.0 * view_depth / (camera.scale_y * camera.height);
    let radius = width / pixel_world / PIXELS_PER_FILTER_RADIUS;
    return u32(clamp(radius, 1.0, f32(MAX_FILTER_RADIUS)));
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
        let map_layer = entry.layer & 0xffffu;
        let layer = 2.0 * f32(map_layer);
        if light.penumbra_rays > 0u {
            let traced = area_visibility(origin, world, geometric_n, entry.pixel);
            textureStore(refined_mask, texel, vec4<f32>(layer + traced.x, 0.0, 0.0, 0.0));
            let radius = penumbra_filter_radius(traced.y, world, geometric_n, view_depth);
            unsure_pixels[index].layer = map_layer | (radius << 16u);
        } else if centre_ray_blocked(origin, world, light_geometry(world).xyz) {
            textureStore(refined_mask, texel, vec4<f32>(layer, 0.0, 0.0, 0.0));
        }
    }
}

// The penumbra's filter, after the trace pass under a light with an area: each
// listed pixel's visibility becomes a weighted average of its neighbours' within
// the radius the trace pass chose from the penumbra's width and stored in the
// pixel's entry (1 to MAX_FILTER_RADIUS pixels),
// traced or not, read from the copy `traced_mask` (a cross-bilateral filter, after
// Tomasi & Manduchi 1998 and the joint bilateral upsampling of Kopf et al. 2007):
// - binomial spatial weights (1 2 1 at radius 1, 1 4 6 4 1 at 2, ...), which leave a
//   visibility linear across the kernel unchanged;
// - only neighbours on the same surface: within SURFACE_PIXELS pixel widths of the
//   centre's tangent plane, with normals within SURFACE_COS, so that no caster's
//   value is carried onto the floor behind it;
// - only neighbours the light can reach (facing it, inside its cone);
// - a range weight (`range_weight`) that keeps hard edges hard.
// With each pixel's own pattern the estimates' noise is independent: where all nine
// of a radius-1 kernel count, its weights' sum of squares is 36/256 of their squared
// sum, and the noise's standard deviation falls to 6/16 of one pixel's. A fixed
// 5 × 5 kernel did worse than 3 × 3 on `contact` (penumbra MAE 0.0192 against
// 0.0179): most penumbra pixels lie within a few pixels of a contact, where the
// penumbra is narrow and a wide kernel blurs it. Hence the radius per pixel.
const MAX_FILTER_RADIUS: u32 = 3u;
const PIXELS_PER_FILTER_RADIUS: f32 = 4.0;
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

// The binomial coefficient C(2r, r + d): the weight of offset d in a kernel of
// radius r, 1 2 1 at r = 1.
fn binomial(r: i32, d: i32) -> f32 {
    let k = r + abs(d);
    var c = 1.0;
    for (var i = 1; i <= 2 * r - k; i++) {
        c *= f32(k + i) / f32(i);
    }
    return c;
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
        let radius = i32(clamp(entry.layer >> 16u, 1u, MAX_FILTER_RADIUS));
        for (var dy = -radius; dy <= radius; dy++) {
            for (var dx = -radius; dx <= radius; dx++) {
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
                let w = binomial(radius, dx) * binomial(radius, dy) * range_weight(visibility, q_visibility);
                sum += w * q_visibility;
                weights += w;
            }
        }
        // The centre always shares its own surface, and weighs most.
        textureStore(refined_mask, texel, vec4<f32>(2.0 * f32(entry.layer & 0xffffu) + sum / weights, 0.0, 0.0, 0.0));
    }
}
