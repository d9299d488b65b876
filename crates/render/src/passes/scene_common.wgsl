// Declarations shared by every pass that draws scene geometry: the per-instance
// data, the vertex layout, and the light uniform. Concatenated before a pass's own
// WGSL by `passes::compose_wgsl`.

struct Instance {
    world_from_object: mat4x4<f32>,
    // Inverse transpose of world_from_object's upper 3×3, stored as a mat4 for alignment.
    normal_from_object: mat4x4<f32>,
    base_color: vec4<f32>,  // rgb: base colour, a: base alpha
    // x: specular weight, y: Blinn-Phong exponent, z: object id (instance index + 1),
    // w: alpha cutoff of a MASK material, −1 for none.
    material: vec4<f32>,
    texturing: vec4<f32>,   // x: 1 when the base colour texture is used
};

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
};

// The light and its shadow map. Field meanings are documented in `gpu_types.rs`.
struct Light {
    clip_from_world: mat4x4<f32>,
    light_from_world: mat4x4<f32>,
    radiance: vec4<f32>,     // rgb: colour × intensity
    direction: vec4<f32>,    // xyz: travel direction (sun) or cone axis (spot); w: 0 sun, 1 spot
    position: vec4<f32>,     // xyz: spot position; w: range
    cone: vec4<f32>,         // x: cos inner, y: cos outer, z: near, w: far
    texel: vec4<f32>,        // x: ortho texel size, y: texel size per unit distance, z: normal offset (texels), w: map size
    params: vec4<f32>,       // technique parameters, see each technique
    ambient: vec4<f32>,      // rgb: ambient light
};

@group(0) @binding(0) var<storage, read> instances: array<Instance>;
@group(0) @binding(1) var<uniform> light: Light;

// The base colour of an instance, with alpha: the factor times the texture when it
// has one. Sampled at mip 0, as the reference ray tracer samples it.
fn base_color_of(inst: Instance, uv: vec2<f32>) -> vec4<f32> {
    var c = inst.base_color;
    if inst.texturing.x > 0.5 {
        c *= textureSampleLevel(base_color_texture, base_color_sampler, uv, 0.0);
    }
    return c;
}

// Whether an instance's surface is cut away at this point (alpha-masked materials).
fn alpha_cut(inst: Instance, uv: vec2<f32>) -> bool {
    return inst.material.w >= 0.0 && base_color_of(inst, uv).a < inst.material.w;
}
