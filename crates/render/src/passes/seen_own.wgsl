// The surface a forward lighting pass shades: the fragment's own, from its
// interpolated world point and its normals (surface.wgsl). Every fragment the depth
// test keeps is the pixel's surface. (seen_prepass.wgsl is the mask path's.)
import package::passes::camera_binding::camera;
import package::passes::lighting_common::SeenSurface;
import package::passes::octahedron::octahedron_encode;
import package::passes::surface::{SurfaceVertex, surface_normals};

// Must be called in uniform control flow (the normals take derivatives).
fn own_seen_surface(in: SurfaceVertex) -> SeenSurface {
    let normals = surface_normals(in);
    let view_depth = -(camera.view_from_world * vec4<f32>(in.world, 1.0)).z;
    let encoded = vec4<f32>(octahedron_encode(normals.shading), octahedron_encode(normals.geometric));
    return SeenSurface(in.world, view_depth, normals.shading, normals.geometric, encoded);
}

fn own_is_seen_surface(in: SurfaceVertex) -> bool {
    return true;
}
