// Declarations shared by every pass that draws scene geometry: the per-instance
// data, the vertex layout, and the light uniform's binding (its struct is in
// light.wgsl), imported by the passes that draw geometry.
import package::constants::{SEEN_CCW, SEEN_CW};
import package::passes::material_bindings::{base_color_sampler, base_color_texture};

struct Instance {
    world_from_object: mat4x4<f32>,
    base_color: vec4<f32>,  // rgb: base colour, a: base alpha
    specular: f32,          // specular weight
    shininess: f32,         // Blinn-Phong exponent
    object_id: u32,         // the scene's instance index + 1
    alpha_cutoff: f32,      // of a MASK material; −1 for none
    textured: u32,          // 1 when the base colour is multiplied by the bound texture
    seen_faces: u32,        // the faces the camera draws: SEEN_BOTH, SEEN_CCW or SEEN_CW
    _pad1: u32,
    _pad2: u32,
};

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
};

// An instance's world_from_object, fetched once per instance by the vertex stage from
// the instance buffer bound as a per-instance vertex buffer (InstanceGpu::
// transform_layout). Vertex stages read the matrix from here, never from
// `instances[instance_index]`: a storage read in every vertex invocation made the
// shadow pass cost 1.6-1.8x a pass without it on a CPU rasterizer.
struct InstanceTransform {
    @location(3) c0: vec4<f32>,
    @location(4) c1: vec4<f32>,
    @location(5) c2: vec4<f32>,
    @location(6) c3: vec4<f32>,
};

fn world_from_object_of(t: InstanceTransform) -> mat4x4<f32> {
    return mat4x4<f32>(t.c0, t.c1, t.c2, t.c3);
}

// Fragment stages read the rest of an instance (material, alpha cut-off) here, by the
// instance index the vertex stage passes on flat.
@group(0) @binding(0) var<storage, read> instances: array<Instance>;

// What carries object-space normals to world space: the cofactor matrix of
// world_from_object's upper 3×3, which is its inverse transpose times the
// determinant, with the determinant's sign restored so a mirroring transform keeps
// normals outward. The scale does not matter, normals are normalized after
// interpolation; computing it here keeps 64 bytes per instance out of memory.
fn normal_from_object(m: mat4x4<f32>) -> mat3x3<f32> {
    let c0 = m[0].xyz;
    let c1 = m[1].xyz;
    let c2 = m[2].xyz;
    let cofactor = mat3x3<f32>(cross(c1, c2), cross(c2, c0), cross(c0, c1));
    return select(1.0, -1.0, dot(c0, cross(c1, c2)) < 0.0) * cofactor;
}

// The base colour of an instance, with alpha: the factor times the texture when it
// has one. Sampled at mip 0, as the reference ray tracer samples it.
fn base_color_of(inst: Instance, uv: vec2<f32>) -> vec4<f32> {
    var c = inst.base_color;
    if inst.textured == 1u {
        c *= textureSampleLevel(base_color_texture, base_color_sampler, uv, 0.0);
    }
    return c;
}

// Whether an instance's surface is cut away at this point (alpha-masked materials).
// Whether the camera's passes drop a fragment of `inst` whose face is `front` (its
// winding on screen counter-clockwise): a face inside a closed mesh, which from
// outside it shows only through the gaps that snapping a sliver's vertices opens
// (gpu_types.rs's `SeenFaces`).
fn hidden_face(inst: Instance, front: bool) -> bool {
    return (inst.seen_faces == SEEN_CCW && !front) || (inst.seen_faces == SEEN_CW && front);
}

fn alpha_cut(inst: Instance, uv: vec2<f32>) -> bool {
    return inst.alpha_cutoff >= 0.0 && base_color_of(inst, uv).a < inst.alpha_cutoff;
}
