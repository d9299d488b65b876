// The camera uniform of the passes that shade from the camera: the lighting pass and
// the screen-space shadow mask (group 1, binding 0), and the host's shader through
// the shadow receiver (receiver.wgsl). Mirrors `CameraGpu`.

struct Camera {
    clip_from_world: mat4x4<f32>,
    view_from_world: mat4x4<f32>,
    world_from_view: mat4x4<f32>,
    eye: vec3<f32>,
    debug_view: u32,        // DEBUG_VIEW_NONE, _CASCADES or _TRACED
    scale_x: f32,           // clip_from_view[0][0] and [1][1] (a symmetric perspective)
    scale_y: f32,
    near: f32,
    far: f32,
    width: f32,             // the image in pixels
    height: f32,
    inv_width: f32,
    inv_height: f32,
};
