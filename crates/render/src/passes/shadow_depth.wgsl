// Shadow pass: depth only, from the light. No fragment stage, so the cheapest path
// the rasterizer has; bias and culling come from the pipeline state.
import package::passes::light_binding::light;
import package::passes::scene_common::{InstanceTransform, VertexIn, alpha_cut, instances, world_from_object_of};

// It reads the position-only vertex stream and the instance's matrix as attributes:
// nothing else, and no storage buffer (a test holds it to that).
@vertex
fn vs_shadow(@location(0) position: vec3<f32>, transform: InstanceTransform) -> @builtin(position) vec4<f32> {
    let world = world_from_object_of(transform) * vec4<f32>(position, 1.0);
    return light.clip_from_world * world;
}

// Alpha-masked casters: the same projection, plus the cut-out test, so leaves and
// fences cast their holes. The texture is bound as group 1 (material_bindings.wgsl).

struct MaskedOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) instance: u32,
};

@vertex
fn vs_shadow_masked(
    v: VertexIn,
    transform: InstanceTransform,
    @builtin(instance_index) instance_index: u32,
) -> MaskedOut {
    var out: MaskedOut;
    out.clip = light.clip_from_world * (world_from_object_of(transform) * vec4<f32>(v.position, 1.0));
    out.uv = v.uv;
    out.instance = instance_index;
    return out;
}

@fragment
fn fs_shadow_masked(in: MaskedOut) {
    if alpha_cut(instances[in.instance], in.uv) {
        discard;
    }
}

// A point light's cube faces store distance from the light over its range, not the
// face's projected depth, so that a filter tap compares the same quantity on every
// face (and across seams). The fragment stage writes it, with the bias the rasterizer
// would have applied to projected depth: a constant in units of the last mantissa
// bit of a 32-bit float at that depth, and a slope-scaled term of the depth's
// screen derivatives (Vulkan spec, "Depth Bias").
struct DistanceOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) @interpolate(flat) instance: u32,
};

@vertex
fn vs_shadow_distance(
    v: VertexIn,
    transform: InstanceTransform,
    @builtin(instance_index) instance_index: u32,
) -> DistanceOut {
    let world = world_from_object_of(transform) * vec4<f32>(v.position, 1.0);
    var out: DistanceOut;
    out.clip = light.clip_from_world * world;
    out.world = world.xyz;
    out.uv = v.uv;
    out.instance = instance_index;
    return out;
}

fn biased_distance(world: vec3<f32>) -> f32 {
    let d = length(world - light.emitter.position) / light.emitter.range;
    let slope = max(abs(dpdx(d)), abs(dpdy(d)));
    let unit = exp2(floor(log2(max(d, 1e-30))) - 23.0);
    return d + light.bias.depth * unit + light.bias.slope * slope;
}

@fragment
fn fs_shadow_distance(in: DistanceOut) -> @builtin(frag_depth) f32 {
    return biased_distance(in.world);
}

@fragment
fn fs_shadow_distance_masked(in: DistanceOut) -> @builtin(frag_depth) f32 {
    // Derivatives first, in uniform control flow.
    let depth = biased_distance(in.world);
    if alpha_cut(instances[in.instance], in.uv) {
        discard;
    }
    return depth;
}

// A point light's dual-paraboloid hemisphere (Brabec, Annen & Seidel 2002): here
// `light.clip_from_world` holds the hemisphere's frame (light_from_world, its axis
// along +z), and a vertex lands at (x, y) / (1 + z) of its unit direction. Depth is
// distance over range, as for the cube. The rasterizer interpolates linearly between
// vertices where the true image of an edge is curved: the method's known error, which
// finer tessellation would reduce. Fragments of the other hemisphere are discarded.
@vertex
fn vs_shadow_paraboloid(
    v: VertexIn,
    transform: InstanceTransform,
    @builtin(instance_index) instance_index: u32,
) -> DistanceOut {
    let world = world_from_object_of(transform) * vec4<f32>(v.position, 1.0);
    let d = (light.clip_from_world * world).xyz;
    let n = d / max(length(d), 1e-20);
    var out: DistanceOut;
    // Directions far behind the hemisphere go far outside the disk, not to infinity.
    out.clip = vec4<f32>(n.xy / max(1.0 + n.z, 1e-3), clamp(length(d) / light.emitter.range, 0.0, 1.0), 1.0);
    out.world = world.xyz;
    out.uv = v.uv;
    out.instance = instance_index;
    return out;
}

@fragment
fn fs_shadow_paraboloid(in: DistanceOut) -> @builtin(frag_depth) f32 {
    let depth = biased_distance(in.world);
    if (light.clip_from_world * vec4<f32>(in.world, 1.0)).z < 0.0 {
        discard;
    }
    return depth;
}

@fragment
fn fs_shadow_paraboloid_masked(in: DistanceOut) -> @builtin(frag_depth) f32 {
    let depth = biased_distance(in.world);
    if (light.clip_from_world * vec4<f32>(in.world, 1.0)).z < 0.0 || alpha_cut(instances[in.instance], in.uv) {
        discard;
    }
    return depth;
}
