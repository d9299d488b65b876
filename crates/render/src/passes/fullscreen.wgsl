// The vertex stage of the passes that cover their whole target (the map preview and
// scroll, the shadow mask, the copy into a host's texture): one triangle, three vertices, no buffers.

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    // Vertices 0, 1, 2 at uv (0, 0), (2, 0), (0, 2): a triangle that covers the target.
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}
