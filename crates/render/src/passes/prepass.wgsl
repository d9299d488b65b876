// Depth-and-normal prepass of the mask path: every surface the camera sees, once, with
// the depth the lighting passes then test for equality, its linear view depth (to
// rebuild its position exactly; a Depth32Float perspective depth loses millimetres
// at a distance), and its shading and geometric normals, octahedron-encoded.

@group(3) @binding(0) var base_color_texture: texture_2d<f32>;
@group(3) @binding(1) var base_color_sampler: sampler;

struct PrepassOut {
    // Invariant, and computed exactly as the lighting pass's vs_main computes it, so
    // that the lighting passes find the same depths.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) instance: u32,
    @location(3) uv: vec2<f32>,
};

@vertex
fn vs_prepass(v: VertexIn, @builtin(instance_index) instance_index: u32) -> PrepassOut {
    let inst = instances[instance_index];
    let world = inst.world_from_object * vec4<f32>(v.position, 1.0);
    var out: PrepassOut;
    out.clip = camera.clip_from_world * world;
    out.world = world.xyz;
    out.normal = (inst.normal_from_object * vec4<f32>(v.normal, 0.0)).xyz;
    out.instance = instance_index;
    out.uv = v.uv;
    return out;
}

struct PrepassTargets {
    // xy: shading normal, zw: geometric normal, both facing the camera.
    @location(0) normals: vec4<f32>,
    @location(1) view_depth: f32,
};

@fragment
fn fs_prepass(in: PrepassOut, @builtin(front_facing) front: bool) -> PrepassTargets {
    // The same normals the forward lighting pass derives (lighting.wgsl's fs_main).
    var geometric_n = normalize(cross(dpdx(in.world), dpdy(in.world)));
    if dot(geometric_n, camera.eye.xyz - in.world) < 0.0 {
        geometric_n = -geometric_n;
    }
    var n = normalize(in.normal);
    if !front {
        n = -n;
    }
    if alpha_cut(instances[in.instance], in.uv) {
        discard;
    }
    var out: PrepassTargets;
    out.normals = vec4<f32>(octahedron_encode(n), octahedron_encode(geometric_n));
    out.view_depth = -(camera.view_from_world * vec4<f32>(in.world, 1.0)).z;
    return out;
}
