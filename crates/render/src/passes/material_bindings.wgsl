// The material texture that scene_common.wgsl's helpers sample (`base_color_of`,
// `alpha_cut`), declared once, at the group and first binding the composing pass's
// generated constants name (`material_bindings_wgsl` in passes/mod.rs): group 3 in
// the passes that draw from the camera, group 1 in the shadow-map pass, both from
// binding 0. A pass that never calls the helpers still declares it, since they read it.
import package::variant::{MATERIAL_BINDING, MATERIAL_GROUP};

@group(MATERIAL_GROUP) @binding(MATERIAL_BINDING) var base_color_texture: texture_2d<f32>;
@group(MATERIAL_GROUP) @binding(MATERIAL_BINDING + 1u) var base_color_sampler: sampler;
