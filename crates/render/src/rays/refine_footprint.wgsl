// The footprint test that 2D maps (refine_map.wgsl) and a point light's cube faces
// (refine_cube.wgsl) share: the stored depths around a lookup against the receiver's
// plane. Each caller works out the plane's depth and slope in its own map's terms.

// Texels of ring around the bilinear footprint.
const UNSURE_RING_TEXELS: i32 = 2;
// The depth band, in texel world sizes along the light's ray, inside which a stored
// depth is too close to the receiver's to trust.
const UNSURE_DEPTH_TEXELS: f32 = 2.0;

// The map's (u, v, depth) moved by a world-space step `t` from a point of clip-space
// w `w` and normalized device coordinates `ndc` in a layer with `clip_from_world`,
// to first order: clip moves by M·(t, 0), so NDC by the quotient rule's
// (Δclip.xyz − ndc·Δclip.w) / w. Exact for orthographic maps, where w ≡ 1.
fn map_step(clip_from_world: mat4x4<f32>, ndc: vec3<f32>, w: f32, t: vec3<f32>) -> vec3<f32> {
    let d = clip_from_world * vec4<f32>(t, 0.0);
    return (d.xyz - ndc * d.w) / w * vec3<f32>(0.5, -0.5, 1.0);
}

// Whether the footprint of a lookup at `uv` (in [0, 1]) in layer `layer` is unsure:
// the bilinear 2×2 and a ring of UNSURE_RING_TEXELS texels, each texel's stored depth
// against the receiver's plane there, which the including file's
// `footprint_receiver(x, y)` gives for a 2×2 block of texels (in gather's order). A
// texel within `tolerance` behind or in front of the plane, or farther behind, is
// evidence of light; one more than `margin` in front, of a caster; one in between, or
// both kinds together, make the pixel unsure. A footprint that leaves the layer is
// `FOOTPRINT_EDGE_UNSURE`.
fn footprint_unsure(uv: vec2<f32>, tolerance: f32, margin: f32, layer: u32) -> bool {
    let size = light.resolution;
    // Texel (i, j) holds the depth at its centre, (i + ½, j + ½) texels.
    let base = vec2<i32>(floor(uv * size - vec2<f32>(0.5)));
    let first = base - vec2<i32>(UNSURE_RING_TEXELS);
    let end = base + vec2<i32>(2 + UNSURE_RING_TEXELS);
    if any(first < vec2<i32>(0)) || any(end > vec2<i32>(i32(size))) {
        return FOOTPRINT_EDGE_UNSURE;
    }
    var lit = false;
    var shadowed = false;
    // The footprint, 2 + 2 × UNSURE_RING_TEXELS texels a side, in 2×2 blocks, each
    // gathered at its texels' shared corner (gather's order: (x, y+1), (x+1, y+1),
    // (x+1, y), (x, y)).
    for (var y = first.y; y < end.y; y += 2) {
        for (var x = first.x; x < end.x; x += 2) {
            let corner = vec2<f32>(f32(x + 1), f32(y + 1)) / size;
            let stored = textureGather(shadow_map, shadow_gather, corner, layer);
            let receiver = footprint_receiver(x, y);
            let is_lit = stored >= receiver - vec4<f32>(tolerance);
            let is_shadowed = stored <= receiver - vec4<f32>(margin);
            if !all(is_lit | is_shadowed) {
                return true;
            }
            lit = lit || any(is_lit);
            shadowed = shadowed || any(is_shadowed);
        }
    }
    return lit && shadowed;
}
