// Clears one page of a virtual shadow map's pool to the far plane: a triangle over
// the whole viewport (the page's tile) at depth 1, drawn with depth test "always".
// A render pass can only clear its whole attachment, and the pool's other pages are
// kept.

@vertex
fn vs_page_clear(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 1.0, 1.0);
}
