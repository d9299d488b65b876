// The shadow-mask pass of a light with an area whose penumbrae rays trace
// (`rays::classifies_penumbrae`): each pixel is lit or in umbra by the map's
// classification (penumbra_classify.wgsl), or unsure, and then answered by a
// penumbra beam (penumbra_beam.wgsl) in the trace pass. A frame beams a quarter of
// the unsure pixels, one of each 2 × 2 block in turn (`PENUMBRA_PHASES`), and keeps
// what its beams found in the light's penumbra history, which the next frame starts
// from where nothing changed: a still view's unsure pixels gather a beam every fourth
// frame until they hold `beams_gathered`, and the map's classification is read back
// rather than made again. Where the
// history does not hold (the first frame, or a camera, light or caster that moved:
// `light.rays.history` 0), an unsure pixel that this frame does not beam is filled
// from its neighbours' answers (`cs_fill_penumbra`, refine_trace.wgsl).
//
// The history holds, per pixel, (value, beams): beams −1 for a pixel the map
// decided, whose value is its visibility; beams ≥ 1 for an unsure pixel, whose value
// is the mean of its beams; 0 for an unsure pixel filled, whose value is no estimate
// of its own.
import package::constants::{DEBUG_VIEW_TRACED, TRACED_LAYER_FLAG};
import package::passes::camera_binding::camera;
import package::passes::contact::contact_visibility;
import package::passes::light_binding::light;
import package::passes::octahedron::octahedron_decode;
import package::passes::screen_common::{plane_point, prepass_normals, prepass_surface};
import package::passes::shading::{facing_error, light_geometry};
import package::rays::penumbra_classify::CLASSIFIED_UNSURE;
import package::rays::refine_append::{count_kept, listed_defer_beam, listed_defer_to_fill};
import package::variant::{penumbra_layer, pixel_visibility, ray_decides};

// Last frame's history, read; this frame's, written (two textures in turn,
// `frame/penumbra_history.rs`).
@group(3) @binding(0) var penumbra_history: texture_2d<f32>;
@group(3) @binding(1) var penumbra_history_written: texture_storage_2d<rg32float, write>;

// The blocks a frame beams one pixel of: 2 × 2, so four frames beam them all.
const PENUMBRA_PHASES: u32 = 4u;

// The beams an unsure pixel of a still view gathers before it is beamed no more: those
// `light.rays.penumbra_frames` frames give it, one every PENUMBRA_PHASES-th. Past
// them the history answers it alone, so a settled still view (a viewer's, a lab's)
// costs its mask pass and no beam, and its image stays the one the last beam left;
// anything the history depends on moving starts the gathering again.
fn beams_gathered() -> f32 {
    return f32(max((light.rays.penumbra_frames + PENUMBRA_PHASES - 1u) / PENUMBRA_PHASES, 1u));
}

// What the mask holds, until the trace or fill pass writes it, for an unsure pixel:
// below every packed visibility, so that the fill pass takes no neighbour's answer
// that is not there yet.
const PENUMBRA_PENDING: f32 = -1.0e6;

// Whether this frame beams the unsure pixel at `texel`: one of each 2 × 2 block, a
// different one each frame.
fn beamed_this_frame(texel: vec2<u32>) -> bool {
    return (texel.x & 1u) + 2u * (texel.y & 1u) == light.rays.frame % PENUMBRA_PHASES;
}

@fragment
fn fs_penumbra_mask(@builtin(position) frag: vec4<f32>) -> @location(0) f32 {
    let texel = vec2<i32>(frag.xy);
    let surface = textureLoad(prepass_surface, texel, 0);
    let view_depth = surface.w;
    if view_depth <= 0.0 {
        textureStore(penumbra_history_written, texel, vec4<f32>(1.0, -1.0, 0.0, 0.0));
        return 1.0;
    }
    let normals = textureLoad(prepass_normals, texel, 0);
    let n = octahedron_decode(normals.xy);
    let geometric_n = octahedron_decode(normals.zw);
    let world = surface.xyz;
    let quad = floor(frag.xy * 0.5) * 2.0 + vec2<f32>(0.5);
    let world_dx = plane_point(vec2<f32>(quad.x + 1.0, frag.y), world, geometric_n)
        - plane_point(vec2<f32>(quad.x, frag.y), world, geometric_n);
    let world_dy = plane_point(vec2<f32>(frag.x, quad.y + 1.0), world, geometric_n)
        - plane_point(vec2<f32>(frag.x, quad.y), world, geometric_n);
    let geometry = light_geometry(world);
    let l = geometry.xyz;

    let past = textureLoad(penumbra_history, texel, 0).xy;
    let kept = light.rays.history == 1u;
    // The map's answer: kept from last frame where it decided the pixel, else made
    // again (lit 1, umbra 0, unsure ½: `penumbra_map_lookup`).
    var shadow: vec2<f32>;
    if kept {
        // Decided (beams −1), or unsure: ½, as the classification says it.
        let value = select(CLASSIFIED_UNSURE, past.x, past.y < 0.0);
        shadow = vec2<f32>(value, penumbra_layer(world, n, l, view_depth));
    } else {
        shadow = pixel_visibility(world, n, geometric_n, l, geometry.w, world_dx, world_dy, frag.xy, view_depth);
    }
    let unsure = ray_decides(shadow, world, n, geometric_n, l, geometry.w, facing_error(world, world_dx, world_dy));
    if !unsure {
        var visibility = shadow.x;
        textureStore(penumbra_history_written, texel, vec4<f32>(visibility, -1.0, 0.0, 0.0));
        if light.contact.steps > 0u && visibility > 0.0 {
            visibility = min(visibility, contact_visibility(world, geometric_n, l, frag.xy, view_depth));
        }
        return visibility + 2.0 * shadow.y;
    }
    // Unsure: beamed now, answered by its history's beams, or filled.
    var layer = shadow.y;
    if camera.debug_view == DEBUG_VIEW_TRACED {
        layer += f32(TRACED_LAYER_FLAG);
    }
    let beams = select(0.0, past.y, kept && past.y >= 1.0);
    let texel_u = vec2<u32>(texel);
    // A pixel unsure for another reason than the casters the map holds (the
    // horizon: `CLASSIFIED_HORIZON`; a surface within the error of its normal of
    // edge-on, which the map called lit or dark) is beamed whenever its history has
    // no answer: its neighbours' would not say.
    let own = shadow.x != CLASSIFIED_UNSURE && beams == 0.0;
    let gathering = beams < beams_gathered();
    if gathering && (beamed_this_frame(texel_u) || own) {
        listed_defer_beam(texel_u, u32(layer), vec2<f32>(select(0.0, past.x, beams > 0.0), beams));
        return PENUMBRA_PENDING;
    }
    if beams > 0.0 {
        count_kept();
        textureStore(penumbra_history_written, texel, vec4<f32>(past.x, beams, 0.0, 0.0));
        return past.x + 2.0 * layer;
    }
    listed_defer_to_fill(texel_u, u32(layer));
    return PENUMBRA_PENDING;
}
