// No refinement: the map's answer stands everywhere.
fn unrefined_ray_decides(
    shadow: vec2<f32>,
    world: vec3<f32>,
    n: vec3<f32>,
    geometric_n: vec3<f32>,
    l: vec3<f32>,
    cone: f32,
    facing_error: f32,
) -> bool {
    return false;
}

fn unrefined_defer_to_ray(pixel: vec2<u32>, layer: u32) {}
