// Scrolls a kept shadow-map layer by whole texels, as a clipmap does
// (`frame/map_cache.rs`): each texel of the target takes the depth of the source
// texel `offset` away, and a texel that no source texel covers gets the far plane,
// for the casters to be drawn into.

struct Scroll {
    offset: vec2<i32>,
    size: vec2<i32>,
};

@group(0) @binding(0) var source: texture_depth_2d;
@group(0) @binding(1) var<uniform> scroll: Scroll;

@fragment
fn fs_scroll(@builtin(position) position: vec4<f32>) -> @builtin(frag_depth) f32 {
    let source_texel = vec2<i32>(floor(position.xy)) + scroll.offset;
    if any(source_texel < vec2<i32>(0)) || any(source_texel >= scroll.size) {
        return 1.0;
    }
    return textureLoad(source, source_texel, 0);
}
