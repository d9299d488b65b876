// Copies Gnomon's colour image into a host's texture of any colour format, texel for
// texel (the two are the same size). The source is sRGB-encoded and read as linear
// colour; an sRGB target encodes it again, a linear one keeps it linear.

@group(0) @binding(0) var image: texture_2d<f32>;

@fragment
fn fs_blit(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(image, vec2<i32>(frag.xy), 0);
}
