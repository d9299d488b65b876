// No refinement in the lighting pass: the map's answer, or the mask's, stands.
fn unrefined_refine_forward(
    shadow: vec2<f32>,
    world: vec3<f32>,
    n: vec3<f32>,
    geometric_n: vec3<f32>,
    geometry: vec4<f32>,
    view_depth: f32,
    frag: vec2<f32>,
    facing_error: f32,
) -> vec2<f32> {
    return shadow;
}
