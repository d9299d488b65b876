// The shadow lookup of a point light: the receiver, pushed along its normal by the
// normal offset (in texels of the cube at the receiver, times 1 − N·L, as for 2D
// maps), is looked up by direction in the cube with the technique's
// `sample_shadow_cube`. The cube stores distance over range, so the compared depth
// is the same whichever face a filter tap lands on.
import package::passes::light_binding::light;
import package::passes::light_shapes::orthonormal_pair;
import package::passes::shading::MIN_NORMAL_OFFSET_SCALE;
import package::techniques::cube::{CubeQuery, cube_texel_world_size};
import package::variant::sample_shadow_cube;

// The lit fraction at `world` and the cube face its direction falls on, as
// (visibility, face). The screen derivatives give the receiver's plane, for
// receiver-plane depth bias (when it is on).
fn cube_lookup_visibility(
    world: vec3<f32>,
    n: vec3<f32>,
    l: vec3<f32>,
    world_dx: vec3<f32>,
    world_dy: vec3<f32>,
    pixel: vec2<f32>,
    view_depth: f32,
) -> vec2<f32> {
    let slope = max(1.0 - clamp(dot(n, l), 0.0, 1.0), MIN_NORMAL_OFFSET_SCALE);
    let offset_world = light.bias.normal_offset * cube_texel_world_size(world - light.emitter.position) * slope;
    var q: CubeQuery;
    q.offset = world + n * offset_world - light.emitter.position;
    q.depth = length(q.offset) / light.emitter.range;
    q.texel_world = cube_texel_world_size(q.offset);
    q.pixel = pixel;
    let frame = orthonormal_pair(normalize(q.offset));
    q.tangent = frame[0];
    q.bitangent = frame[1];
    let plane = cross(world_dx, world_dy);
    if light.bias.receiver_plane == 1u && dot(plane, plane) > 0.0 {
        q.plane_normal = normalize(plane);
    }
    return vec2<f32>(sample_shadow_cube(q), f32(cube_face(q.offset)));
}

// The face (layer) a direction is sampled from: its major axis, ties to x then y
// (gnomon_math::omni::CubeFace::of_direction).
fn cube_face(d: vec3<f32>) -> u32 {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return select(1u, 0u, d.x >= 0.0);
    }
    if a.y >= a.z {
        return select(3u, 2u, d.y >= 0.0);
    }
    return select(5u, 4u, d.z >= 0.0);
}
