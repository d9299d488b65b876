// The trace pass of hybrid ray-traced shadows (refine_classify.wgsl), dispatched
// indirectly over the pixels the mask pass listed.
//
// Under a hard light, one shadow ray per pixel toward the light's centre: the mask
// pass stored each listed pixel lit, and a blocked ray stores it shadowed
// (visibility 0, with its map layer for the cascade view).
//
// Under a light with an area, `light.rays.penumbra_rays` rays per pixel toward points
// stratified over the light (light_sample.wgsl), and the pixel stores the share that
// arrive: a Monte Carlo estimate of the same integral as the CPU reference's, whose
// noise the filter pass (`cs_filter_penumbra`) then smooths. The estimate replaces
// contact shadows there: the rays see the casters that contact shadows approximate.
//
// Rays leave from the pixel's surface point moved off the surface along the
// camera-facing geometric normal (the side the light is on, or the pixel would face
// away from it and not be listed).
import package::passes::camera_binding::camera;
import package::passes::light_binding::light;
import package::passes::light_kinds::emitter_penumbra_radius;
import package::passes::octahedron::octahedron_decode;
import package::passes::screen_common::{prepass_normals, prepass_surface};
import package::passes::shading::light_geometry;
import package::rays::refine_list::unsure_pixels;
import package::rays::surface_rays::{centre_ray_blocked, surface_ray_origin};
import package::variant::{REFINE_GROUP_SIZE, REFINE_PENUMBRAE, area_visibility};

// The light's counters, read only: they are also the pass's indirect dispatch, which
// no pass may write while it reads them so.
struct ListedPixels {
    groups: vec3<u32>,
    count: u32,
};

// The list itself is `unsure_pixels` (refine_list.wgsl), whose entries this pass
// completes with their penumbra width; its counters are read-only here.
@group(1) @binding(4) var<storage, read> listed: ListedPixels;

@group(2) @binding(0) var refined_mask: texture_storage_2d<r32float, write>;
// A copy of the mask as the trace pass left it, which the filter pass reads.
@group(2) @binding(1) var traced_mask: texture_2d<f32>;

// The material bindings of scene_common.wgsl's helpers (material_bindings.wgsl), which
// this pass never calls, take the two bindings of the tracer's group that trace.wgsl
// leaves free for them.

// The penumbra's width on screen, in pixels, at a pixel whose blocked rays met
// casters `blocker` away on average (-1: none), on a surface of normal `geometric_n`
// seen at `view_depth`, from similar triangles (Fernando 2005: w = 2 r_light ·
// d_blocker / (d_light − d_blocker) at the receiver, 2 tan(θ_sun) · d_blocker under a
// sun). The filter pass sizes its kernel by it.
fn penumbra_width_px(blocker: f32, world: vec3<f32>, geometric_n: vec3<f32>, view_depth: f32) -> f32 {
    if blocker < 0.0 {
        return UNBLOCKED_WIDTH_PX;
    }
    let light_to_blocker = max(length(light.emitter.position - world) - blocker, 1e-6);
    var width = 2.0 * emitter_penumbra_radius(light.emitter, blocker, light_to_blocker);
    // On screen the receiver's plane is foreshortened by |n·v| across its steepest
    // direction: the penumbra is at least that narrow there.
    width *= abs(dot(geometric_n, normalize(camera.eye - world)));
    let pixel_world = 2.0 * view_depth / (camera.scale_y * camera.height);
    return width / pixel_world;
}

// The width taken where none of a pixel's rays was blocked: its neighbours' rays
// were, or it would not have been listed, so it lies at a penumbra's lit end.
const UNBLOCKED_WIDTH_PX: f32 = 4.0;
// The width is stored in the high 16 bits of the pixel's list entry, in 1/16 px.
const WIDTH_FIXED_POINT: f32 = 16.0;
const MAX_STORED_WIDTH_PX: f32 = 4095.0;

@compute @workgroup_size(REFINE_GROUP_SIZE)
fn cs_trace(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let count = listed.count;
    // More pixels than REFINE_MAX_GROUPS workgroups cover loop over the rest.
    for (var index = id.x; index < count; index += groups.x * REFINE_GROUP_SIZE) {
        let entry = unsure_pixels[index];
        let texel = vec2<u32>(entry.pixel & 0xffffu, entry.pixel >> 16u);
        let surface = textureLoad(prepass_surface, texel, 0);
        let view_depth = surface.w;
        let geometric_n = octahedron_decode(textureLoad(prepass_normals, texel, 0).zw);
        let world = surface.xyz;
        let origin = surface_ray_origin(world, geometric_n, view_depth);
        let map_layer = entry.layer & 0xffffu;
        let layer = 2.0 * f32(map_layer);
        if REFINE_PENUMBRAE {
            let traced = area_visibility(origin, world, geometric_n, entry.pixel);
            textureStore(refined_mask, texel, vec4<f32>(layer + traced.x, 0.0, 0.0, 0.0));
            let width = penumbra_width_px(traced.y, world, geometric_n, view_depth);
            let stored = u32(clamp(width, 0.0, MAX_STORED_WIDTH_PX) * WIDTH_FIXED_POINT);
            unsure_pixels[index].layer = map_layer | (stored << 16u);
        } else if centre_ray_blocked(origin, world, light_geometry(world).xyz) {
            textureStore(refined_mask, texel, vec4<f32>(layer, 0.0, 0.0, 0.0));
        }
    }
}

// The penumbra's filter, after the trace pass under a light with an area: each
// listed pixel's visibility becomes a weighted average of its neighbours' within
// MAX_FILTER_RADIUS pixels, traced or not, read from the copy `traced_mask` (a
// cross-bilateral filter, after Tomasi & Manduchi 1998 and the joint bilateral
// upsampling of Kopf et al. 2007):
// - anisotropic Gaussian spatial weights, narrow across the penumbra and wide along
//   it (`penumbra_across` finds which way is across). Along the penumbra the
//   visibility hardly changes, so averaging there cuts the noise of N rays without
//   widening the penumbra; across it, a kernel of variance s² widens a penumbra
//   w px wide from 10 % to 90 % (variance about (w / 2.56)²) by
//   √(1 + s² (2.56 / w)²). With s² = w / ACROSS_VARIANCE_DIVISOR px² that is
//   √(1 + 0.41 / w): 5 % at w = 4, 2 % at w = 12;
// - only neighbours on the same surface: within SURFACE_PIXELS pixel widths of the
//   centre's tangent plane, with normals within SURFACE_COS, so that no caster's
//   value is carried onto the floor behind it;
// - only neighbours the light can reach (facing it, inside its cone);
// - a range weight (`range_weight`) that keeps hard edges hard.
// With each pixel's own pattern the estimates' noise is independent. The round
// binomial kernels this replaced (1 2 1 at radius 1, up to radius 3 by w / 4)
// widened the 3.8 px penumbrae of `spheres` by 0.26 px, most of its error (penumbra
// MAE 0.0224 against 0.0177 now, 1024-ray reference), and cost `contact` and
// `grazing` 0.0107 and 0.0278 against 0.0101 and 0.0251. Along-variances of 3 px²
// and across-divisors of 32 each helped one scene and cost another.
const MAX_FILTER_RADIUS: i32 = 3;
const ACROSS_VARIANCE_DIVISOR: f32 = 16.0;
// The least variance across the penumbra, px²: below it no neighbour counts.
const MIN_ACROSS_VARIANCE: f32 = 0.05;
// The least variance along the penumbra, px², and where no direction shows (a flat
// neighbourhood) the variance of a round kernel.
const MIN_ALONG_VARIANCE: f32 = 2.0;
// The range weight's width, in standard deviations of the estimates (1.5 and 2
// measured 0.0191 and 0.0182 on `contact` with the former round kernel, 3 measured
// 0.0179).
const RANGE_SIGMAS: f32 = 3.0;
const SURFACE_PIXELS: f32 = 2.0;
const SURFACE_COS: f32 = 0.9;
// Spatial weights below this are skipped, and their neighbours not read.
const NEGLIGIBLE_WEIGHT: f32 = 1e-3;

// How much a neighbour's visibility `q` counts toward the centre's `p`: a Gaussian in
// their difference, RANGE_SIGMAS times as wide as the larger of their estimates'
// binomial standard deviations √(v(1 − v)/N). Two estimates of 0 and 1 have none, and never mix: a
// contact shadow's hard edge stays hard, where a penumbra's noisy middle is averaged.
fn range_weight(p: f32, q: f32) -> f32 {
    let variance = max(p * (1.0 - p), q * (1.0 - q)) / f32(light.rays.penumbra_rays);
    let d = p - q;
    return select(exp(-d * d / (2.0 * RANGE_SIGMAS * RANGE_SIGMAS * variance)), select(0.0, 1.0, d == 0.0), variance == 0.0);
}

// The visibility of a mask texel, which stores it plus 2 × the map layer.
fn mask_visibility(packed: f32) -> f32 {
    return packed - 2.0 * floor(packed * 0.5);
}

// The centre of the penumbra filter's kernel.
struct FilterCentre {
    texel: vec2<i32>,
    world: vec3<f32>,
    n: vec3<f32>,
    // A pixel's width in world units at the centre's depth.
    pixel_world: f32,
    visibility: f32,
};

// The visibility of the centre's neighbour `q`, or -1 where it says nothing of the
// centre's penumbra: off the screen or the centre's surface, or not reached by the
// light at all.
fn neighbour_visibility(c: FilterCentre, q: vec2<i32>) -> f32 {
    let size = vec2<i32>(textureDimensions(traced_mask));
    if any(q < vec2<i32>(0)) || any(q >= size) {
        return -1.0;
    }
    let q_surface = textureLoad(prepass_surface, q, 0);
    if q_surface.w <= 0.0 {
        return -1.0;
    }
    let q_n = octahedron_decode(textureLoad(prepass_normals, q, 0).zw);
    let q_world = q_surface.xyz;
    let off_plane = abs(dot(c.n, q_world - c.world));
    if off_plane > SURFACE_PIXELS * c.pixel_world || dot(c.n, q_n) < SURFACE_COS {
        return -1.0;
    }
    // A neighbour facing away from the light or outside its cone is dark by
    // definition, not by a caster: it says nothing of this pixel's penumbra.
    let q_light = light_geometry(q_world);
    if dot(q_n, q_light.xyz) <= 0.0 || q_light.w <= 0.0 {
        return -1.0;
    }
    return mask_visibility(textureLoad(traced_mask, q, 0).x);
}

// The visibilities of the centre's 3 × 3 neighbourhood, row by row (the centre's own
// at 4; -1 where a neighbour says nothing of its penumbra): what both the direction
// across the penumbra and the kernel's inner ring read, taken once.
fn neighbourhood(c: FilterCentre) -> array<f32, 9> {
    var near: array<f32, 9>;
    for (var k = 0; k < 9; k++) {
        if k == 4 {
            near[k] = c.visibility;
        } else {
            near[k] = neighbour_visibility(c, c.texel + vec2<i32>(k % 3 - 1, k / 3 - 1));
        }
    }
    return near;
}

// The unit direction across the penumbra at the centre, on screen (zero where its
// 3 × 3 neighbourhood `near` shows none): the gradient's direction of the
// least-squares plane through the visibilities of the centre and its neighbours on
// its surface. Each neighbour's estimate is noisy, but nine of them find the
// direction of a penumbra a few pixels wide to within a few degrees.
fn penumbra_across(near: ptr<function, array<f32, 9>>) -> vec2<f32> {
    var count = 0.0;
    var d_sum = vec2<f32>(0.0);
    var v_sum = 0.0;
    var dd = vec3<f32>(0.0);
    var dv = vec2<f32>(0.0);
    for (var k = 0; k < 9; k++) {
        let v = (*near)[k];
        if v < 0.0 {
            continue;
        }
        let d = vec2<f32>(f32(k % 3 - 1), f32(k / 3 - 1));
        count += 1.0;
        d_sum += d;
        v_sum += v;
        dd += vec3<f32>(d.x * d.x, d.x * d.y, d.y * d.y);
        dv += d * v;
    }
    // Centred moments: M g = b.
    let mean = d_sum / count;
    let m = dd - count * vec3<f32>(mean.x * mean.x, mean.x * mean.y, mean.y * mean.y);
    let b = dv - count * mean * (v_sum / count);
    let det = m.x * m.z - m.y * m.y;
    if det < 1e-3 {
        return vec2<f32>(0.0);
    }
    let g = vec2<f32>(m.z * b.x - m.y * b.y, m.x * b.y - m.y * b.x) / det;
    let len = length(g);
    return select(vec2<f32>(0.0), g / len, len > 1e-4);
}

@compute @workgroup_size(REFINE_GROUP_SIZE)
fn cs_filter_penumbra(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    if true { return; }
    let count = listed.count;
    for (var index = id.x; index < count; index += groups.x * REFINE_GROUP_SIZE) {
        let entry = unsure_pixels[index];
        let texel = vec2<i32>(i32(entry.pixel & 0xffffu), i32(entry.pixel >> 16u));
        let surface = textureLoad(prepass_surface, texel, 0);
        let view_depth = surface.w;
        let n = octahedron_decode(textureLoad(prepass_normals, texel, 0).zw);
        let world = surface.xyz;
        let pixel_world = 2.0 * view_depth / (camera.scale_y * camera.height);
        let visibility = mask_visibility(textureLoad(traced_mask, texel, 0).x);
        let c = FilterCentre(texel, world, n, pixel_world, visibility);
        let width = f32(entry.layer >> 16u) / WIDTH_FIXED_POINT;
        var near = neighbourhood(c);
        let across = penumbra_across(&near);
        let along_variance = max(width / ACROSS_VARIANCE_DIVISOR, MIN_ALONG_VARIANCE);
        let round = all(across == vec2<f32>(0.0));
        let across_variance = select(max(width / ACROSS_VARIANCE_DIVISOR, MIN_ACROSS_VARIANCE), along_variance, round);
        var sum = 0.0;
        var weights = 0.0;
        for (var dy = -MAX_FILTER_RADIUS; dy <= MAX_FILTER_RADIUS; dy++) {
            for (var dx = -MAX_FILTER_RADIUS; dx <= MAX_FILTER_RADIUS; dx++) {
                let d = vec2<f32>(f32(dx), f32(dy));
                // Offsets across and along the penumbra (any split, for a round kernel).
                let a = select(dot(d, across), d.x, round);
                let b = select(d.x * across.y - d.y * across.x, d.y, round);
                let spatial = exp(-0.5 * (a * a / across_variance + b * b / along_variance));
                if spatial < NEGLIGIBLE_WEIGHT {
                    continue;
                }
                var q_visibility: f32;
                if abs(dx) <= 1 && abs(dy) <= 1 {
                    q_visibility = near[(dy + 1) * 3 + dx + 1];
                } else {
                    q_visibility = neighbour_visibility(c, texel + vec2<i32>(dx, dy));
                }
                if q_visibility < 0.0 {
                    continue;
                }
                let w = spatial * range_weight(visibility, q_visibility);
                sum += w * q_visibility;
                weights += w;
            }
        }
        // The centre always shares its own surface, and weighs most.
        textureStore(refined_mask, texel, vec4<f32>(2.0 * f32(entry.layer & 0xffffu) + sum / weights, 0.0, 0.0, 0.0));
    }
}
