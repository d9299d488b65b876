// The light-list lighting pass (tiled forward shading, Olsson & Assarsson 2011): the
// scene drawn once over the prepass's depths, each pixel summing the lights its
// 16 × 16 tile lists. A light's visibility comes from its layer of the shadow mask,
// which its own mask pass filled with its own technique (shadow_mask.wgsl), so lights
// of every technique and kind share this one pipeline. The sum is the per-light
// passes' sum, shaded by the same functions (shading.wgsl), quantised once. Under
// the cascade view the sum is tinted by the reported light's layer (the per-light
// passes tint each light's term by its own). Camera: camera.wgsl; vertex stage and
// normals: surface.wgsl; their outputs and tints: lighting_common.wgsl.
import package::constants::{DEBUG_VIEW_CASCADES, DEBUG_VIEW_PAGES, DEBUG_VIEW_TRACED, LIGHT_TILE, LIGHT_WORDS, TRACED_LAYER_FLAG};
import package::passes::camera_binding::camera;
import package::passes::light::Emitter;
import package::passes::light_kinds::emitter_geometry;
import package::passes::lighting_common::{FragmentOut, layer_tint, pages_tint};
import package::passes::scene_common::{alpha_cut, base_color_of, hidden_face, instances};
import package::passes::shading::blinn_phong;
import package::passes::surface::SurfaceVertex;
import package::variant::{is_seen_surface, seen_surface};

struct LightList {
    ambient: vec3<f32>,
    shown: u32,      // the reported light: its visibility goes to the visibility target
    tiles_x: u32,    // tiles per row
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(2) @binding(0) var<uniform> list: LightList;
@group(2) @binding(1) var<storage, read> emitters: array<Emitter>;
// LIGHT_WORDS words per tile, row by row: bit i of the tile's words is light i.
@group(2) @binding(2) var<storage, read> tile_lights: array<u32>;
// Layer i: light i's visibility + 2 × the shadow-map layer that shaded it.
@group(2) @binding(3) var shadow_masks: texture_2d_array<f32>;

// Light `i`'s mask at `texel`: (visibility, layer code, traced flag). The code is
// the layer, past TRACED_LAYER_FLAG where the traced view flagged it or the pages
// view added its page's flags.
fn listed_visibility(texel: vec2<u32>, i: u32) -> vec3<f32> {
    let packed = textureLoad(shadow_masks, texel, i, 0).x;
    let layer = floor(packed * 0.5);
    let flagged = u32(layer) >= TRACED_LAYER_FLAG;
    return vec3<f32>(packed - 2.0 * layer, layer, select(0.0, 1.0, flagged));
}

@fragment
fn fs_light_list(in: SurfaceVertex, @builtin(front_facing) front: bool) -> FragmentOut {
    let inst = instances[in.instance];
    if alpha_cut(inst, in.uv) || hidden_face(inst, front) {
        discard;
    }
    // The prepass's surface at this pixel, which every light's mask was resolved
    // for; a fragment of another instance on the same depth is not it
    // (seen_prepass.wgsl).
    if !is_seen_surface(in) {
        discard;
    }
    let seen = seen_surface(in);
    let n = seen.shading_n;
    let albedo = base_color_of(inst, in.uv).rgb;
    let v = normalize(camera.eye - seen.world);
    let texel = vec2<u32>(in.clip.xy);

    // The reported light's layer covers every pixel; the others only the tiles that
    // list them.
    let shown = listed_visibility(texel, list.shown);
    var color = list.ambient * albedo;
    var traced = false;
    let tile = (texel.y / LIGHT_TILE) * list.tiles_x + texel.x / LIGHT_TILE;
    for (var word = 0u; word < LIGHT_WORDS; word++) {
        var bits = tile_lights[tile * LIGHT_WORDS + word];
        while bits != 0u {
            let i = word * 32u + firstTrailingBit(bits);
            bits &= bits - 1u;
            let e = emitters[i];
            let geometry = emitter_geometry(e, seen.world);
            if geometry.w <= 0.0 {
                continue;
            }
            let shadow = listed_visibility(texel, i);
            let direct = e.radiance * geometry.w * blinn_phong(albedo, inst.specular, inst.shininess, n, geometry.xyz, v);
            color += shadow.x * direct;
            traced = traced || shadow.z > 0.0;
        }
    }
    // The cascade view tints by the reported light's layers.
    if camera.debug_view == DEBUG_VIEW_CASCADES {
        color = layer_tint(color, u32(shown.y) % TRACED_LAYER_FLAG);
    }
    if camera.debug_view == DEBUG_VIEW_PAGES {
        color = pages_tint(color, u32(shown.y));
    }
    if camera.debug_view == DEBUG_VIEW_TRACED && traced {
        color = mix(color, vec3<f32>(1.0, 0.0, 1.0), 0.6);
    }

    var out: FragmentOut;
    out.color = vec4<f32>(color, 1.0);
    out.visibility = shown.x;
    out.position = vec4<f32>(seen.world, seen.view_depth);
    out.normal = seen.encoded_normals;
    out.object_id = inst.object_id;
    return out;
}
