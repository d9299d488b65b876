// The camera uniform (group 1, binding 0) of the passes that shade from the camera:
// the lighting pass and the screen-space shadow mask. Mirrors `CameraGpu`.

struct Camera {
    clip_from_world: mat4x4<f32>,
    view_from_world: mat4x4<f32>,
    world_from_view: mat4x4<f32>,
    eye: vec4<f32>,
    debug: vec4<f32>,       // x: 1 to tint pixels by their cascade
    // x: clip_from_view[0][0], y: clip_from_view[1][1] (a symmetric perspective),
    // z: near plane, w: far plane.
    projection: vec4<f32>,
    viewport: vec4<f32>,    // x, y: width and height in pixels; z, w: their inverses
};

@group(1) @binding(0) var<uniform> camera: Camera;
