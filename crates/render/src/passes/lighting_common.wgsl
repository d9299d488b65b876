// What the lighting passes share: their outputs, in `lighting::TARGETS` order, the
// surface each pixel shades, and the cascade debug view's tint of each shadow-map
// layer.
import package::constants::{MAX_CASCADES, TRACED_LAYER_FLAG};

struct FragmentOut {
    @location(0) color: vec4<f32>,
    @location(1) visibility: f32,
    @location(2) position: vec4<f32>,
    // xy: the shading normal, zw: the geometric normal, both octahedron-encoded
    // (octahedron.wgsl) and facing the camera, as the prepass stores them.
    @location(3) normal: vec4<f32>,
    @location(4) object_id: u32,
};

// The surface a pixel shows, which its colour, its visibility and its outputs all
// describe: on the forward path the fragment's own (seen_own.wgsl), on the mask path
// the one the prepass kept and the shadow mask was resolved for (seen_prepass.wgsl).
struct SeenSurface {
    world: vec3<f32>,
    view_depth: f32,
    // The interpolated normal and the triangle's plane, both facing the camera.
    shading_n: vec3<f32>,
    geometric_n: vec3<f32>,
    // Both normals, octahedron-encoded, for the normal output.
    encoded_normals: vec4<f32>,
};

// The tints are indexed only under their view: a dynamically indexed constant array costs a
// copy per invocation on some compilers (on lavapipe, 8–17 ms of a frame when the light
// list indexed it for every light).
const CASCADE_TINTS: array<vec3<f32>, MAX_CASCADES> = array<vec3<f32>, MAX_CASCADES>(
    vec3<f32>(1.0, 0.35, 0.35), vec3<f32>(0.35, 1.0, 0.35), vec3<f32>(0.4, 0.5, 1.0), vec3<f32>(1.0, 1.0, 0.3),
    vec3<f32>(1.0, 0.35, 1.0), vec3<f32>(0.3, 1.0, 1.0), vec3<f32>(1.0, 0.65, 0.2), vec3<f32>(0.65, 0.4, 1.0),
);

// The cascade view's tint of `color` for map layer `layer` (a virtual map's level,
// up to 15: the tints in turn).
fn layer_tint(color: vec3<f32>, layer: u32) -> vec3<f32> {
    return color * CASCADE_TINTS[layer % MAX_CASCADES];
}

// The pages view's tint of `color` for a mask's layer `code` (virtual_visibility.wgsl:
// the level, plus TRACED_LAYER_FLAG times its page's flags): the level's tint,
// brighter over a page drawn this frame, reddened where a coarser page stands in,
// darkened on a page's border.
fn pages_tint(color: vec3<f32>, code: u32) -> vec3<f32> {
    var tinted = layer_tint(color, code % TRACED_LAYER_FLAG);
    let flags = code / TRACED_LAYER_FLAG;
    if (flags & 1u) != 0u {
        // Brighter, keeping the shadows' contrast.
        tinted *= 1.5;
    }
    if (flags & 2u) != 0u {
        tinted = mix(tinted, vec3<f32>(1.0, 0.0, 0.0), 0.5);
    }
    if (flags & 4u) != 0u {
        tinted *= 0.25;
    }
    return tinted;
}
