// Depth-and-normal prepass of the mask path: every surface the camera sees, once, with
// the depth the lighting passes then test for equality, its linear view depth (to
// rebuild its position exactly; a Depth32Float perspective depth loses millimetres
// at a distance), and its shading and geometric normals, octahedron-encoded.

struct PrepassTargets {
    // xy: shading normal, zw: geometric normal, both facing the camera.
    @location(0) normals: vec4<f32>,
    @location(1) view_depth: f32,
};

// The vertex stage is surface.wgsl's vs_surface, the lighting pass's own.
@fragment
fn fs_prepass(in: SurfaceVertex) -> PrepassTargets {
    let normals = surface_normals(in);
    if alpha_cut(instances[in.instance], in.uv) {
        discard;
    }
    var out: PrepassTargets;
    out.normals = vec4<f32>(octahedron_encode(normals.shading), octahedron_encode(normals.geometric));
    out.view_depth = -(camera.view_from_world * vec4<f32>(in.world, 1.0)).z;
    return out;
}
