// The camera uniform of the passes that shade from the camera (the lighting pass and
// the screen-space shadow mask), bound at group 1; the host's shader binds its own
// through the shadow receiver (receiver.wgsl).

@group(1) @binding(0) var<uniform> camera: Camera;
