// Lighting pass: Lambert diffuse + Blinn-Phong specular + ambient, with the shadow
// factor of the selected technique multiplying only the direct term. Also writes the
// per-pixel visibility, world position, normal, view depth and object id.
//
// `pixel_visibility` comes from resolve_visibility.wgsl on the forward path (the
// technique's lookup, per fragment, which `refine_forward` refines by rays where
// asked) or from mask_lookup.wgsl on the mask path (what the screen-space shadow
// mask stored for the pixel). Camera: camera.wgsl; the
// vertex stage and normals: surface.wgsl; the light's direction and cone:
// shading.wgsl.

// Cascade tints of the debug view.
const CASCADE_TINTS: array<vec3<f32>, MAX_CASCADES> = array<vec3<f32>, MAX_CASCADES>(
    vec3<f32>(1.0, 0.35, 0.35), vec3<f32>(0.35, 1.0, 0.35), vec3<f32>(0.4, 0.5, 1.0), vec3<f32>(1.0, 1.0, 0.3),
    vec3<f32>(1.0, 0.35, 1.0), vec3<f32>(0.3, 1.0, 1.0), vec3<f32>(1.0, 0.65, 0.2), vec3<f32>(0.65, 0.4, 1.0),
);

struct FragmentOut {
    @location(0) color: vec4<f32>,
    @location(1) visibility: f32,
    @location(2) position: vec4<f32>,
    @location(3) normal: vec4<f32>,
    @location(4) object_id: u32,
};

@fragment
fn fs_main(in: SurfaceVertex) -> FragmentOut {
    let inst = instances[in.instance];
    let normals = surface_normals(in);
    let n = normals.shading;
    let geometric_n = normals.geometric;
    let geometry = light_geometry(in.world);
    let l = geometry.xyz;
    let cone = geometry.w;

    // The world position's screen derivatives, taken here in uniform control flow;
    // each lookup carries them into its own cascade's texture space.
    let world_dx = dpdx(in.world);
    let world_dy = dpdy(in.world);
    let view_depth = -(camera.view_from_world * vec4<f32>(in.world, 1.0)).z;
    let looked_up = pixel_visibility(in.world, n, geometric_n, l, cone, world_dx, world_dy, in.clip.xy, view_depth);
    // Where the forward path refines and the map is unsure, the fragment's rays
    // decide (rays/refine_forward.wgsl).
    let shadow = refine_forward(looked_up, in.world, n, geometric_n, geometry, view_depth, in.clip.xy);
    let visibility = shadow.x;
    // Under the traced view, a layer past TRACED_LAYER_FLAG marks a pixel whose
    // shadow rays decided (shadow_mask.wgsl, refine_forward.wgsl).
    let traced = u32(shadow.y) >= TRACED_LAYER_FLAG;
    let layer = u32(shadow.y) % TRACED_LAYER_FLAG;

    if alpha_cut(inst, in.uv) {
        discard;
    }
    let albedo = base_color_of(inst, in.uv).rgb;
    let n_dot_l = max(dot(n, l), 0.0);
    let v = normalize(camera.eye - in.world);
    let h = normalize(l + v);
    let specular = inst.specular * pow(max(dot(n, h), 0.0), inst.shininess) * select(0.0, 1.0, n_dot_l > 0.0);
    let direct = light.radiance * cone * (albedo * n_dot_l + vec3<f32>(specular));
    var color = light.ambient * albedo + visibility * direct;
    if camera.debug_view == DEBUG_VIEW_CASCADES {
        color *= CASCADE_TINTS[layer];
    }
    if camera.debug_view == DEBUG_VIEW_TRACED && traced {
        color = mix(color, vec3<f32>(1.0, 0.0, 1.0), 0.6);
    }

    var out: FragmentOut;
    out.color = vec4<f32>(color, 1.0);
    out.visibility = visibility;
    out.position = vec4<f32>(in.world, view_depth);
    out.normal = vec4<f32>(n, 0.0);
    out.object_id = inst.object_id;
    return out;
}
