// The shadow lookup of a point light's dual-paraboloid map: the (normal-offset)
// receiver's direction picks the hemisphere, the paraboloid mapping gives its
// texture coordinates, and the technique's 2D `sample_shadow` compares distance over
// range there. Layer i's `cascade_clip_from_world` holds hemisphere i's frame.
import package::passes::light_binding::light;
import package::passes::shading::MIN_NORMAL_OFFSET_SCALE;
import package::techniques::common::ShadowQuery;
import package::variant::sample_shadow;

// Texture coordinates and depth (distance over range) of `world` in hemisphere `layer`.
fn paraboloid_map_coords(layer: u32, world: vec3<f32>) -> vec3<f32> {
    let d = (light.cascade_clip_from_world[layer] * vec4<f32>(world, 1.0)).xyz;
    let len = length(d);
    let xy = d.xy / max(len + d.z, 1e-20);
    return vec3<f32>(xy * vec2<f32>(0.5, -0.5) + vec2<f32>(0.5), len / light.emitter.range);
}

// World size of a texel across the ray at `world`: xy = tan(θ/2) has dxy/dθ =
// 1 / (1 + cos θ), so a texel (2 / resolution in xy) spans (1 + cos θ)·2/resolution
// radians: 4/resolution on the axis, half that at the rim
// (gnomon_math::omni::paraboloid_texel_world_size).
fn paraboloid_texel_world_size(layer: u32, world: vec3<f32>) -> f32 {
    let d = (light.cascade_clip_from_world[layer] * vec4<f32>(world, 1.0)).xyz;
    let len = max(length(d), 1e-20);
    return (len + d.z) * 2.0 / light.map.resolution;
}

fn paraboloid_lookup_visibility(
    world: vec3<f32>,
    n: vec3<f32>,
    l: vec3<f32>,
    world_dx: vec3<f32>,
    world_dy: vec3<f32>,
    pixel: vec2<f32>,
    view_depth: f32,
) -> vec2<f32> {
    let below = (light.cascade_clip_from_world[0u] * vec4<f32>(world, 1.0)).z >= 0.0;
    let layer = select(1u, 0u, below);
    let slope = max(1.0 - clamp(dot(n, l), 0.0, 1.0), MIN_NORMAL_OFFSET_SCALE);
    let p = world + n * (light.bias.normal_offset * paraboloid_texel_world_size(layer, world) * slope);
    var q: ShadowQuery;
    q.coords = paraboloid_map_coords(layer, p);
    q.coords_dx = paraboloid_map_coords(layer, p + world_dx) - q.coords;
    q.coords_dy = paraboloid_map_coords(layer, p + world_dy) - q.coords;
    q.pixel = pixel;
    q.distance = length(p - light.emitter.position);
    q.layer = layer;
    return vec2<f32>(sample_shadow(q), f32(layer));
}
