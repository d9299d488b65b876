// The surface a camera depth prepass saw, as the page requests read it
// (`page_requests.wgsl`): each pixel's world point and view depth, unprojected from
// its depth through the camera's inverse projection; zeros where the prepass saw
// nothing (the far plane).

struct SurfaceParams {
    world_from_clip: mat4x4<f32>,
    // The camera's view-space z as a function of a world point (view_from_world's
    // third row): its view depth is −z.
    view_z_from_world: vec4<f32>,
    width: u32,
    height: u32,
    _pad0: u32,
    _pad1: u32,
}

@group(0) @binding(0) var surface_depth: texture_depth_2d;
@group(0) @binding(1) var surface_out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(2) var<uniform> surface_params: SurfaceParams;

@compute @workgroup_size(8, 8)
fn surface_from_depth(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= surface_params.width || id.y >= surface_params.height) {
        return;
    }
    let depth = textureLoad(surface_depth, vec2<i32>(id.xy), 0);
    if (depth >= 1.0) {
        textureStore(surface_out, vec2<i32>(id.xy), vec4<f32>(0.0));
        return;
    }
    // The pixel's centre in NDC: x right, y up.
    let size = vec2<f32>(f32(surface_params.width), f32(surface_params.height));
    let uv = (vec2<f32>(id.xy) + vec2<f32>(0.5)) / size;
    let ndc = vec2<f32>(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
    let world = surface_params.world_from_clip * vec4<f32>(ndc, depth, 1.0);
    let point = world.xyz / world.w;
    let view_depth = -dot(surface_params.view_z_from_world, vec4<f32>(point, 1.0));
    textureStore(surface_out, vec2<i32>(id.xy), vec4<f32>(point, view_depth));
}
