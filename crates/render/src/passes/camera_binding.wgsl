// The camera uniform, declared once for every pass that reads it, at the group and
// binding its pass's generated constants name (`camera_binding_wgsl` in
// passes/mod.rs): group 1 binding 0 in the passes that shade from the camera (the
// lighting pass and the screen-space shadow mask); binding 1 of the host's group in
// the shadow receiver.
import package::passes::camera::Camera;
import package::variant::{CAMERA_BINDING, CAMERA_GROUP};

@group(CAMERA_GROUP) @binding(CAMERA_BINDING) var<uniform> camera: Camera;
