// How a 2D shadow map's coordinates follow a small step in the world, which the
// classifications of rays (refine_map.wgsl, refine_cube.wgsl,
// penumbra_classify.wgsl) fit a receiver's plane with.

// The map's (u, v, depth) moved by a world-space step `t` from a point of clip-space
// w `w` and normalized device coordinates `ndc` in a layer with `clip_from_world`,
// to first order: clip moves by M·(t, 0), so NDC by the quotient rule's
// (Δclip.xyz − ndc·Δclip.w) / w. Exact for orthographic maps, where w ≡ 1.
fn map_step(clip_from_world: mat4x4<f32>, ndc: vec3<f32>, w: f32, t: vec3<f32>) -> vec3<f32> {
    let d = clip_from_world * vec4<f32>(t, 0.0);
    return (d.xyz - ndc * d.w) / w * vec3<f32>(0.5, -0.5, 1.0);
}
