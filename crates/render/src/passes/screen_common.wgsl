// What every pass reading the mask path's prepass shares: the prepass's outputs (with
// the camera, camera.wgsl, at group 1 binding 0) and the point each pixel sees.
import package::passes::camera_binding::camera;

// xyz: the world point the pixel sees, on its triangle (prepass.wgsl says why it is
// not rebuilt from depth); w: its view depth, 0 for the background.
@group(1) @binding(1) var prepass_surface: texture_2d<f32>;
@group(1) @binding(2) var prepass_normals: texture_2d<f32>;

// The world point that the ray through pixel position `pixel` (in pixels, centres at
// .5) meets at view depth `view_depth`: for directions and the planes of screen
// derivatives, not for the surface's own point, which `prepass_surface` holds.
fn world_at(pixel: vec2<f32>, view_depth: f32) -> vec3<f32> {
    let ndc = vec2<f32>(pixel.x * camera.inv_width * 2.0 - 1.0, 1.0 - pixel.y * camera.inv_height * 2.0);
    let view = vec3<f32>(ndc * view_depth / vec2<f32>(camera.scale_x, camera.scale_y), -view_depth);
    return (camera.world_from_view * vec4<f32>(view, 1.0)).xyz;
}

// Where the ray through `pixel` meets the plane through `origin` with normal `n`.
fn plane_point(pixel: vec2<f32>, origin: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let direction = world_at(pixel, 1.0) - camera.eye;
    let along = dot(direction, n);
    if abs(along) < 1e-12 {
        return origin;
    }
    return camera.eye + direction * (dot(origin - camera.eye, n) / along);
}
