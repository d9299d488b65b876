// Depth-and-normal prepass of the mask path: every surface the camera sees, once, with
// the depth the lighting passes then test for equality, the surface's point and
// linear view depth, and its shading and geometric normals, octahedron-encoded.
//
// The point is the rasterizer's interpolation of the vertices' world positions, which
// lies on the triangle to within rounding. It is not rebuilt from the depth along
// the ray through the pixel's centre: a GPU snaps vertices to its sub-pixel grid and
// interpolates at the snapped triangle, so the depth at the pixel's centre describes
// a slightly tilted plane. Its distance from the true one is far more than the rounding a shadow ray's origin
// allows for: on an NVIDIA H200 a point rebuilt from depth started rays under large
// grounds, which then shadowed themselves (`raytraced` 6.1 % wrong on Florence and
// 20 % on `environment`, against 0.001 % on lavapipe, which interpolates at the
// unsnapped triangle).
import package::passes::camera_binding::camera;
import package::passes::octahedron::octahedron_encode;
import package::passes::scene_common::{alpha_cut, hidden_face, instances};
import package::passes::surface::{SurfaceVertex, surface_normals};

struct PrepassTargets {
    // xy: shading normal, zw: geometric normal, both facing the camera.
    @location(0) normals: vec4<f32>,
    // xyz: the world point, w: its view depth (0 where no surface is seen).
    @location(1) surface: vec4<f32>,
    // The instance drawn (its index in the instance buffer) + 1; 0 where no surface
    // is seen. The lighting pass shades only this instance's fragments (seen_prepass.wgsl).
    @location(2) object: u32,
};

// The vertex stage is surface.wgsl's vs_surface, the lighting pass's own.
@fragment
fn fs_prepass(in: SurfaceVertex, @builtin(front_facing) front: bool) -> PrepassTargets {
    let normals = surface_normals(in);
    if alpha_cut(instances[in.instance], in.uv) || hidden_face(instances[in.instance], front) {
        discard;
    }
    var out: PrepassTargets;
    out.normals = vec4<f32>(octahedron_encode(normals.shading), octahedron_encode(normals.geometric));
    out.surface = vec4<f32>(in.world, -(camera.view_from_world * vec4<f32>(in.world, 1.0)).z);
    out.object = in.instance + 1u;
    return out;
}
