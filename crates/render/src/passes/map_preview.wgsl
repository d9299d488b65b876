// The shadow map preview: every layer of a depth map side by side, in grayscale
// (near black, far white), for the viewer's debug panel.
import package::constants::MAX_CASCADES;

struct PreviewLayer {
    perspective: u32,  // 1: its depth is linearized first
    near: f32,
    far: f32,
    _pad: f32,
}

struct Preview {
    tile: f32,         // tile side in pixels
    layer_count: u32,
    resolution: f32,   // the map's texels per side
    _pad: f32,
    layers: array<PreviewLayer, MAX_CASCADES>,
}

@group(0) @binding(0) var map: texture_depth_2d_array;
@group(0) @binding(1) var<uniform> preview: Preview;

@fragment
fn fs_preview(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let tile = preview.tile;
    let layer = min(u32(frag.x / tile), preview.layer_count - 1u);
    let local = vec2<f32>(frag.x - f32(layer) * tile, frag.y);
    // A dark seam between layers.
    if (layer > 0u && local.x < 2.0) {
        return vec4<f32>(0.45, 0.08, 0.08, 1.0);
    }
    let resolution = preview.resolution;
    let texel = vec2<i32>(clamp(local / tile * resolution, vec2<f32>(0.0), vec2<f32>(resolution - 1.0)));
    let depth = textureLoad(map, texel, i32(layer), 0);
    let params = preview.layers[layer];
    var shade = depth;
    if (params.perspective == 1u && depth < 1.0) {
        // Reversed from the [0, 1] perspective depth d = f (z - n) / (z (f - n)) to the
        // distance z, then stretched over n..f so that the gradient is visible.
        let near = params.near;
        let far = params.far;
        let distance = near * far / (far - depth * (far - near));
        shade = (distance - near) / (far - near);
    }
    return vec4<f32>(vec3<f32>(shade), 1.0);
}
