// The trace pass of hybrid ray-traced shadows (refine_classify.wgsl), dispatched
// indirectly over the pixels the mask pass listed.
//
// Under a hard light, one shadow ray per pixel toward the light's centre: the mask
// pass stored each listed pixel lit, and a blocked ray stores it shadowed
// (visibility 0, with its map layer for the cascade view).
//
// Under a light with an area, one penumbra beam per pixel (`area_visibility`:
// penumbra_beam.wgsl, the share of the light's samples that arrive, weighed as the
// CPU reference's rays), its samples turned by the pixel and the frame, so that the
// beams a still pixel gathers frame after frame are independent; the pixel stores the
// mean of its beams, this one and those its history held (penumbra_mask.wgsl), and
// the history keeps it. The estimate replaces contact shadows there: the rays see the
// casters that contact shadows approximate. Then `cs_fill_penumbra` answers the
// unsure pixels this frame did not beam and whose history holds no beam.
//
// Rays leave from the pixel's surface point moved off the surface along the
// camera-facing geometric normal (the side the light is on, or the pixel would face
// away from it and not be listed).
import package::passes::camera_binding::camera;
import package::passes::light_binding::light;
import package::passes::octahedron::octahedron_decode;
import package::passes::screen_common::{prepass_normals, prepass_surface};
import package::passes::shading::light_geometry;
import package::rays::light_sample::lowbias32;
import package::rays::refine_list::{ListedPixels, unsure_pixels};
import package::rays::surface_rays::{centre_ray_blocked, surface_ray_origin};
import package::variant::{REFINE_GROUP_SIZE, REFINE_PENUMBRAE, area_visibility};

// The list itself is `unsure_pixels` (refine_list.wgsl); the light's counters are
// read only here: they are also the passes' indirect dispatches, which no pass may
// write while it reads them so (`RefineCounters` in refine_append.wgsl).
@group(1) @binding(4) var<storage, read> listed: ListedPixels;

@group(2) @binding(0) var refined_mask: texture_storage_2d<r32float, write>;
// A copy of the mask as the trace pass left it, which the fill pass reads.
@group(2) @binding(1) var traced_mask: texture_2d<f32>;
// The light's penumbra history, as this frame leaves it (penumbra_mask.wgsl).
@group(2) @binding(2) var traced_history: texture_storage_2d<rg32float, write>;

// The material bindings of scene_common.wgsl's helpers (material_bindings.wgsl), which
// this pass never calls, take the two bindings of the tracer's group that trace.wgsl
// leaves free for them.

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
        let layer = 2.0 * f32(entry.layer);
        if REFINE_PENUMBRAE {
            // This frame's turn of the pixel's samples.
            let pattern = entry.pixel ^ lowbias32(light.rays.frame + 0x68e31da4u);
            let beam = area_visibility(origin, world, geometric_n, pattern).x;
            let beams = entry.beams + 1.0;
            let mean = entry.mean + (beam - entry.mean) / beams;
            textureStore(refined_mask, texel, vec4<f32>(layer + mean, 0.0, 0.0, 0.0));
            textureStore(traced_history, texel, vec4<f32>(mean, beams, 0.0, 0.0));
        } else if centre_ray_blocked(origin, world, light_geometry(world).xyz) {
            textureStore(refined_mask, texel, vec4<f32>(layer, 0.0, 0.0, 0.0));
        }
    }
}

// The fill pass, after the trace pass under a light with an area: each unsure pixel
// that no beam answered, this frame or before (listed from the list's far end), is
// answered from its neighbours' answers on the same surface within one pixel, read
// from the copy `traced_mask`: their mean, each weighed by the inverse square of its
// distance, where they differ by at most `FILL_SPREAD` and two of them inside a
// penumbra lie on either side of it (`Neighbours`); or else by a beam of its own. A
// quarter of the unsure pixels are beamed, one of each 2 × 2 block, so every pixel
// has beamed or decided neighbours within one pixel on its surface unless the block
// lies across an edge; where the penumbra is wide they differ little, and its mean
// is its interpolation, within a few hundredths; where it is narrow (a contact, a
// small light) they differ by much more, and the mean would smear it. The mean is no
// estimate of the pixel's own: the history keeps it with no beam, and the pixel is
// beamed in its turn.
@compute @workgroup_size(REFINE_GROUP_SIZE)
fn cs_fill_penumbra(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let count = listed.fill_count;
    let last = arrayLength(&unsure_pixels) - 1u;
    for (var index = id.x; index < count; index += groups.x * REFINE_GROUP_SIZE) {
        let entry = unsure_pixels[last - index];
        let texel = vec2<i32>(i32(entry.pixel & 0xffffu), i32(entry.pixel >> 16u));
        let surface = textureLoad(prepass_surface, texel, 0);
        let n = octahedron_decode(textureLoad(prepass_normals, texel, 0).zw);
        let pixel_world = 2.0 * surface.w / (camera.scale_y * camera.height);
        let centre = FillCentre(texel, surface.xyz, n, pixel_world, surface.w);
        let near = neighbours(centre);
        var visibility: f32;
        var beams = 0.0;
        if near.across && near.highest - near.lowest <= FILL_SPREAD {
            visibility = near.sum / near.weight;
        } else {
            let origin = surface_ray_origin(centre.world, n, surface.w);
            let pattern = entry.pixel ^ lowbias32(light.rays.frame + 0x68e31da4u);
            visibility = area_visibility(origin, centre.world, n, pattern).x;
            beams = 1.0;
        }
        textureStore(refined_mask, texel, vec4<f32>(2.0 * f32(entry.layer) + visibility, 0.0, 0.0, 0.0));
        textureStore(traced_history, texel, vec4<f32>(visibility, beams, 0.0, 0.0));
    }
}

// The most the answered neighbours of a pixel may differ for the fill to take their
// mean rather than beam it.
const FILL_SPREAD: f32 = 0.15;

// The centre of a fill: its pixel, surface point and geometric normal, a pixel's
// width in world units at its depth, and that depth.
struct FillCentre {
    texel: vec2<i32>,
    world: vec3<f32>,
    n: vec3<f32>,
    pixel_world: f32,
    view_depth: f32,
};

// Neighbours on the centre's surface: within this many pixel widths of its tangent
// plane, with normals within about 25° of its own.
const SURFACE_PIXELS: f32 = 2.0;
const SURFACE_COS: f32 = 0.9;
// Neighbours near enough along the surface to interpolate between: within this many
// pixel widths (a face-on pixel's diagonal neighbour lies 1.4 away). Seen at a
// grazing angle, a pixel's neighbours along the view lie far apart on the surface,
// and a shadow as narrow as a pixel's height there (a far post's, along a low sun)
// lies between them unseen.
const FILL_REACH_PIXELS: f32 = 3.0;

// What a fill's answered neighbours say: their weighted sum and weight, their least
// and greatest answer, and whether two of them on either side of the pixel both lie
// inside a penumbra (strictly between 0 and 1), so that their mean interpolates
// across it. One side's answer carried over an edge the pixel may lie beyond (a
// penumbra a pixel or two wide, whose answered neighbours all lie on its lit side)
// would be wrong; so would the mean of a pair of which one is lit or umbra: the pixel
// between them is unsure because a caster reaches its cone and not theirs, a shadow
// a pixel wide (a wire's, a contact's first pixels, a far post's seen along a low
// sun), which the mean would erase. (Taking such pairs made `grazing`'s first frame
// under a sun 10° up 0.073 off in its penumbrae, where its 16th is 0.004.)
struct Neighbours {
    sum: f32,
    weight: f32,
    lowest: f32,
    highest: f32,
    across: bool,
};

// The answered neighbours within one pixel of `c` on its surface
// (`cs_fill_penumbra`).
fn neighbours(c: FillCentre) -> Neighbours {
    let size = vec2<i32>(textureDimensions(traced_mask));
    var near = Neighbours(0.0, 0.0, 1.0, 0.0, false);
    // Which of the 3 × 3 answered inside a penumbra, bit k for neighbour k (row by
    // row).
    var partial = 0u;
    for (var k = 0; k < 9; k++) {
        let d = vec2<i32>(k % 3 - 1, k / 3 - 1);
        let q = c.texel + d;
        if k == 4 || any(q < vec2<i32>(0)) || any(q >= size) {
            continue;
        }
        let packed = textureLoad(traced_mask, q, 0).x;
        // Not answered yet (PENUMBRA_PENDING), or the background.
        let q_surface = textureLoad(prepass_surface, q, 0);
        if packed < 0.0 || q_surface.w <= 0.0 {
            continue;
        }
        let q_n = octahedron_decode(textureLoad(prepass_normals, q, 0).zw);
        let apart = q_surface.xyz - c.world;
        if abs(dot(c.n, apart)) > SURFACE_PIXELS * c.pixel_world || dot(c.n, q_n) < SURFACE_COS {
            continue;
        }
        if dot(apart, apart) > FILL_REACH_PIXELS * FILL_REACH_PIXELS * c.pixel_world * c.pixel_world {
            continue;
        }
        // A neighbour facing away from the light or outside its cone is dark by
        // definition, not by a caster: it says nothing of this pixel's penumbra.
        let q_light = light_geometry(q_surface.xyz);
        if dot(q_n, q_light.xyz) <= 0.0 || q_light.w <= 0.0 {
            continue;
        }
        let visibility = packed - 2.0 * floor(packed * 0.5);
        let w = 1.0 / f32(dot(d, d));
        near.sum += w * visibility;
        near.weight += w;
        near.lowest = min(near.lowest, visibility);
        near.highest = max(near.highest, visibility);
        if visibility > 0.0 && visibility < 1.0 {
            partial |= 1u << u32(k);
        }
    }
    // Either side along a row, a column or a diagonal: neighbours 3 and 5, 1 and 7,
    // 0 and 8, 2 and 6.
    for (var pair = 0u; pair < 4u; pair++) {
        let sides = (1u << FILL_OPPOSITE[pair].x) | (1u << FILL_OPPOSITE[pair].y);
        near.across = near.across || (partial & sides) == sides;
    }
    return near;
}

const FILL_OPPOSITE: array<vec2<u32>, 4> = array<vec2<u32>, 4>(vec2<u32>(3u, 5u), vec2<u32>(1u, 7u), vec2<u32>(0u, 8u), vec2<u32>(2u, 6u));
