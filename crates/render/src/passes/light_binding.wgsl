// The light uniform, declared once for every pass that reads it, at the group and
// binding its pass's generated constants name (`light_binding_wgsl` in passes/mod.rs):
// group 0 binding 1 in Gnomon's own passes, beside the instances; binding 0 of the
// host's group in the shadow receiver.
import package::passes::light::Light;
import package::variant::{LIGHT_BINDING, LIGHT_GROUP};

@group(LIGHT_GROUP) @binding(LIGHT_BINDING) var<uniform> light: Light;
