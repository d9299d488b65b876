// The surface a lighting pass on the mask path shades: the one the prepass kept at
// the pixel, for which the shadow mask holds the visibility. The lighting pass draws
// over the prepass's depths with an equal test, and where two triangles reach the
// pixel at the same depth (along an edge they share, a roof meeting a wall) both
// pass it; the prepass kept the first. So the fragment takes its point and normals
// from the prepass, and a fragment of another instance than the prepass's is
// discarded: colour, visibility and outputs then describe one surface. (Before, such
// a pixel showed the roof's colour and normal with the wall's shadow.)
// (seen_own.wgsl is the forward path's.) Needs screen_common.wgsl.
import package::passes::lighting_common::SeenSurface;
import package::passes::octahedron::octahedron_decode;
import package::passes::screen_common::{prepass_normals, prepass_surface};
import package::passes::surface::SurfaceVertex;

// The instance the prepass kept at each pixel, + 1 (0 for the background).
@group(1) @binding(3) var prepass_object: texture_2d<u32>;

fn prepass_seen_surface(in: SurfaceVertex) -> SeenSurface {
    let texel = vec2<i32>(in.clip.xy);
    let surface = textureLoad(prepass_surface, texel, 0);
    let normals = textureLoad(prepass_normals, texel, 0);
    return SeenSurface(surface.xyz, surface.w, octahedron_decode(normals.xy), octahedron_decode(normals.zw), normals);
}

fn prepass_is_seen_surface(in: SurfaceVertex) -> bool {
    return textureLoad(prepass_object, vec2<i32>(in.clip.xy), 0).x == in.instance + 1u;
}
