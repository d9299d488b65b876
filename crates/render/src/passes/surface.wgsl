// The camera's view of the scene's surfaces, shared by the lighting pass and the
// mask path's prepass: one vertex stage, so that both rasterize the same depths
// (the lighting passes test the prepass's for equality), and the normals both
// derive per fragment. Also the material bindings (group 3) both read.
import package::passes::camera_binding::camera;
import package::passes::scene_common::{InstanceTransform, VertexIn, normal_from_object, world_from_object_of};
import package::passes::shading::facing_side;

struct SurfaceVertex {
    // Invariant: every pass drawing from the camera must rasterize the same depths.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) instance: u32,
    @location(3) uv: vec2<f32>,
};

@vertex
fn vs_surface(
    v: VertexIn,
    transform: InstanceTransform,
    @builtin(instance_index) instance_index: u32,
) -> SurfaceVertex {
    let world_from_object = world_from_object_of(transform);
    let world = world_from_object * vec4<f32>(v.position, 1.0);
    var out: SurfaceVertex;
    out.clip = camera.clip_from_world * world;
    out.world = world.xyz;
    out.normal = normal_from_object(world_from_object) * v.normal;
    out.instance = instance_index;
    out.uv = v.uv;
    return out;
}

struct SurfaceNormals {
    // The interpolated normal, turned to the side the camera sees: two-sided shading,
    // so that a back face seen by the camera is lit as its flipped side, as a ray
    // tracer sees it.
    shading: vec3<f32>,
    // The triangle's plane normal, facing the camera: the world position's
    // derivatives are constant across a triangle.
    geometric: vec3<f32>,
};

// Must be called in uniform control flow (it takes derivatives).
//
// The shading normal is turned into the geometric normal's hemisphere rather than
// flipped by `@builtin(front_facing)`: the winding says which side the camera sees
// only when the authored normals agree with it, and exported cards often disagree
// (the `environment` scene's double-sided mountain cards and bamboo leaves point
// their normals against their winding). Turned by the winding, such a card's normal
// points away from the camera and the sun it faces, and the normal offset then looks
// the shadow up behind the card itself: the whole card fell in its own shadow. The
// same rule serves mirrored instances, whose transform reverses the winding.
fn surface_normals(in: SurfaceVertex) -> SurfaceNormals {
    var out: SurfaceNormals;
    out.geometric = normalize(cross(dpdx(in.world), dpdy(in.world)));
    if dot(out.geometric, camera.eye - in.world) < 0.0 {
        out.geometric = -out.geometric;
    }
    out.shading = facing_side(normalize(in.normal), out.geometric);
    return out;
}
