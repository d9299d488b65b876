// Lighting pass: Lambert diffuse + Blinn-Phong specular + ambient, with the shadow
// factor of the selected technique multiplying only the direct term. Also writes the
// per-pixel visibility, world position, normal, view depth and object id.
//
// `pixel_visibility` comes from resolve_visibility.wgsl on the forward path (the
// technique's lookup, per fragment) or from mask_lookup.wgsl on the mask path (what
// the screen-space shadow mask stored for the pixel). Camera: camera.wgsl; the
// light's direction and cone: shading.wgsl.

// Cascade tints of the debug view.
const CASCADE_TINTS: array<vec3<f32>, 8> = array<vec3<f32>, 8>(
    vec3<f32>(1.0, 0.35, 0.35), vec3<f32>(0.35, 1.0, 0.35), vec3<f32>(0.4, 0.5, 1.0), vec3<f32>(1.0, 1.0, 0.3),
    vec3<f32>(1.0, 0.35, 1.0), vec3<f32>(0.3, 1.0, 1.0), vec3<f32>(1.0, 0.65, 0.2), vec3<f32>(0.65, 0.4, 1.0),
);

@group(3) @binding(0) var base_color_texture: texture_2d<f32>;
@group(3) @binding(1) var base_color_sampler: sampler;

struct VertexOut {
    // Invariant: every light's pass must rasterize the same depths, to test Equal.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) instance: u32,
    @location(3) uv: vec2<f32>,
};

@vertex
fn vs_main(v: VertexIn, @builtin(instance_index) instance_index: u32) -> VertexOut {
    let inst = instances[instance_index];
    let world = inst.world_from_object * vec4<f32>(v.position, 1.0);
    var out: VertexOut;
    out.clip = camera.clip_from_world * world;
    out.world = world.xyz;
    out.normal = (inst.normal_from_object * vec4<f32>(v.normal, 0.0)).xyz;
    out.instance = instance_index;
    out.uv = v.uv;
    return out;
}

struct FragmentOut {
    @location(0) color: vec4<f32>,
    @location(1) visibility: f32,
    @location(2) position: vec4<f32>,
    @location(3) normal: vec4<f32>,
    @location(4) object_id: u32,
};

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front: bool) -> FragmentOut {
    let inst = instances[in.instance];
    // The triangle's geometric normal, facing the camera: the derivatives of the world
    // position are constant across a triangle, so this is its plane's normal. Taken
    // first, in uniform control flow.
    var geometric_n = normalize(cross(dpdx(in.world), dpdy(in.world)));
    if dot(geometric_n, camera.eye.xyz - in.world) < 0.0 {
        geometric_n = -geometric_n;
    }
    // Two-sided shading: a back face seen by the camera is lit as its flipped side, as
    // a ray tracer would see it.
    var n = normalize(in.normal);
    if !front {
        n = -n;
    }
    let geometry = light_geometry(in.world);
    let l = geometry.xyz;
    let cone = geometry.w;

    // The world position's screen derivatives, taken here in uniform control flow;
    // each lookup carries them into its own cascade's texture space.
    let world_dx = dpdx(in.world);
    let world_dy = dpdy(in.world);
    let view_depth = -(camera.view_from_world * vec4<f32>(in.world, 1.0)).z;
    let shadow = pixel_visibility(in.world, n, geometric_n, l, cone, world_dx, world_dy, in.clip.xy, view_depth);
    let visibility = shadow.x;
    let layer = u32(shadow.y);

    if alpha_cut(inst, in.uv) {
        discard;
    }
    let albedo = base_color_of(inst, in.uv).rgb;
    let n_dot_l = max(dot(n, l), 0.0);
    let v = normalize(camera.eye.xyz - in.world);
    let h = normalize(l + v);
    let specular = inst.material.x * pow(max(dot(n, h), 0.0), inst.material.y) * select(0.0, 1.0, n_dot_l > 0.0);
    let direct = light.radiance.rgb * cone * (albedo * n_dot_l + vec3<f32>(specular));
    var color = light.ambient.rgb * albedo + visibility * direct;
    if camera.debug.x > 0.5 {
        color *= CASCADE_TINTS[layer];
    }

    var out: FragmentOut;
    out.color = vec4<f32>(color, 1.0);
    out.visibility = visibility;
    out.position = vec4<f32>(in.world, view_depth);
    out.normal = vec4<f32>(n, 0.0);
    out.object_id = u32(inst.material.z);
    return out;
}
