// Shadow pass: depth only, from the light. No fragment stage, so the cheapest path
// the rasterizer has; bias and culling come from the pipeline state.

@vertex
fn vs_shadow(v: VertexIn, @builtin(instance_index) instance_index: u32) -> @builtin(position) vec4<f32> {
    let inst = instances[instance_index];
    let world = inst.world_from_object * vec4<f32>(v.position, 1.0);
    return light.clip_from_world * world;
}

// Alpha-masked casters: the same projection, plus the cut-out test, so leaves and
// fences cast their holes. The texture is bound as group 1.
@group(1) @binding(0) var base_color_texture: texture_2d<f32>;
@group(1) @binding(1) var base_color_sampler: sampler;

struct MaskedOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) instance: u32,
};

@vertex
fn vs_shadow_masked(v: VertexIn, @builtin(instance_index) instance_index: u32) -> MaskedOut {
    let inst = instances[instance_index];
    var out: MaskedOut;
    out.clip = light.clip_from_world * (inst.world_from_object * vec4<f32>(v.position, 1.0));
    out.uv = v.uv;
    out.instance = instance_index;
    return out;
}

@fragment
fn fs_shadow_masked(in: MaskedOut) {
    if alpha_cut(instances[in.instance], in.uv) {
        discard;
    }
}
