// Lighting pass: Lambert diffuse + Blinn-Phong specular + ambient, with the shadow
// factor of the selected technique multiplying only the direct term. Also writes the
// per-pixel visibility, world position, normal, view depth and object id.
//
// A technique provides `fn sample_shadow(q: ShadowQuery) -> f32` (techniques/common.wgsl).

struct Camera {
    clip_from_world: mat4x4<f32>,
    view_from_world: mat4x4<f32>,
    eye: vec4<f32>,
    debug: vec4<f32>,   // x: 1 to tint pixels by their cascade
};

// Cascade tints of the debug view.
const CASCADE_TINTS: array<vec3<f32>, 8> = array<vec3<f32>, 8>(
    vec3<f32>(1.0, 0.35, 0.35), vec3<f32>(0.35, 1.0, 0.35), vec3<f32>(0.4, 0.5, 1.0), vec3<f32>(1.0, 1.0, 0.3),
    vec3<f32>(1.0, 0.35, 1.0), vec3<f32>(0.3, 1.0, 1.0), vec3<f32>(1.0, 0.65, 0.2), vec3<f32>(0.65, 0.4, 1.0),
);

@group(1) @binding(0) var<uniform> camera: Camera;
@group(3) @binding(0) var base_color_texture: texture_2d<f32>;
@group(3) @binding(1) var base_color_sampler: sampler;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
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

// Shadow-map coordinates of a receiver at `world` with unit normal `n`, lit from `l`:
// the point is first pushed along its normal by the normal-offset bias (in texels of
// the map at the receiver, times 1 − N·L: a surface facing the light needs no offset,
// and offsetting it only shifts its shadows sideways), then projected: clip → NDC →
// texture space with v flipped.
// Returns (u, v, depth, inside) where inside is 1 when the point projects into the
// map's frustum.
// A surface facing the light keeps this fraction of the offset, against the depth
// quantisation that the slope bias (zero for it) cannot cover.
const MIN_NORMAL_OFFSET_SCALE: f32 = 0.2;

// Texture coordinates of `world` in layer `layer`, before any bias.
fn project_to_map(layer: u32, world: vec3<f32>) -> vec2<f32> {
    let clip = light.cascade_clip_from_world[layer] * vec4<f32>(world, 1.0);
    return clip.xy / clip.w * vec2<f32>(0.5, -0.5) + vec2<f32>(0.5, 0.5);
}

// World size of a texel of layer `layer` at `world`. Orthographic and spot maps have a
// closed form; a warped map (LiSPSM, TSM) is measured: the largest extent of a texel
// across the light's rays, 1 / σ_min of the Jacobian of texel coordinates along the
// light's x and y axes, by differences `cascade_texel.z` world units apart.
fn local_texel_world_size(layer: u32, world: vec3<f32>, distance: f32) -> f32 {
    if light.cascade_texel[layer].y < 0.5 {
        return texel_world_size_at(layer, distance);
    }
    let step = light.cascade_texel[layer].z;
    // The light's x and y axes in world space: the first two rows of light_from_world.
    let m = light.light_from_world;
    let axis_x = vec3<f32>(m[0].x, m[1].x, m[2].x);
    let axis_y = vec3<f32>(m[0].y, m[1].y, m[2].y);
    let t = project_to_map(layer, world);
    let dx = (project_to_map(layer, world + axis_x * step) - t) * light.texel.w / step;
    let dy = (project_to_map(layer, world + axis_y * step) - t) * light.texel.w / step;
    let squares = dot(dx, dx) + dot(dy, dy);
    let det = abs(dx.x * dy.y - dy.x * dx.y);
    let sigma_max = sqrt(0.5 * (squares + sqrt(max(squares * squares - 4.0 * det * det, 0.0))));
    return sigma_max / max(det, 1e-20);
}

fn shadow_coords(layer: u32, world: vec3<f32>, n: vec3<f32>, l: vec3<f32>) -> vec4<f32> {
    let distance = -(light.light_from_world * vec4<f32>(world, 1.0)).z;
    let texel_world = local_texel_world_size(layer, world, distance);
    let slope = max(1.0 - clamp(dot(n, l), 0.0, 1.0), MIN_NORMAL_OFFSET_SCALE);
    let p = world + n * (light.texel.z * texel_world * slope);
    let clip = light.cascade_clip_from_world[layer] * vec4<f32>(p, 1.0);
    if clip.w <= 0.0 {
        return vec4<f32>(0.0, 0.0, 0.0, 0.0);
    }
    let ndc = clip.xyz / clip.w;
    let uv = ndc.xy * vec2<f32>(0.5, -0.5) + vec2<f32>(0.5, 0.5);
    let inside = all(uv >= vec2<f32>(0.0)) && all(uv <= vec2<f32>(1.0)) && ndc.z >= 0.0 && ndc.z <= 1.0;
    return vec4<f32>(uv, ndc.z, select(0.0, 1.0, inside));
}

// Fraction of the light arriving at `world` before shadowing: 1 for the sun, the
// cone and range test for a spot (0 outside the outer cone or beyond the range).
// Returns (unit direction to the light, cone factor in [0, 1]).
fn light_geometry(world: vec3<f32>) -> vec4<f32> {
    if light.direction.w < 0.5 {
        return vec4<f32>(-light.direction.xyz, 1.0);
    }
    let to_light = light.position.xyz - world;
    let dist = length(to_light);
    let l = to_light / dist;
    let cos_angle = dot(-l, light.direction.xyz);
    let inside = cos_angle >= light.cone.y && dist <= light.position.w;
    let falloff = smoothstep(light.cone.y, light.cone.x, cos_angle);
    return vec4<f32>(l, select(0.0, falloff, inside));
}

// The cascade that shades a point at `view_depth`: by depth, the one whose split
// range holds it; by projection, the first whose map holds its lookup.
fn select_cascade(view_depth: f32, world: vec3<f32>, n: vec3<f32>, l: vec3<f32>) -> u32 {
    let count = u32(light.cascades.x);
    if light.cascades.y < 0.5 {
        var layer = 0u;
        for (var i = 1u; i < count; i++) {
            if view_depth > cascade_split(i) {
                layer = i;
            }
        }
        return layer;
    }
    for (var i = 0u; i + 1u < count; i++) {
        let c = shadow_coords(i, world, n, l);
        // A margin of a few texels keeps the filter's footprint inside the map.
        let margin = 4.0 / light.texel.w;
        if c.w > 0.5 && all(c.xy > vec2<f32>(margin)) && all(c.xy < vec2<f32>(1.0 - margin)) {
            return i;
        }
    }
    return count - 1u;
}

// The shadow lookup in layer `layer`: 1 (lit) outside the map.
fn shadow_lookup(
    layer: u32,
    world: vec3<f32>,
    n: vec3<f32>,
    l: vec3<f32>,
    world_dx: vec3<f32>,
    world_dy: vec3<f32>,
    pixel: vec2<f32>,
) -> f32 {
    let coords = shadow_coords(layer, world, n, l);
    if coords.w < 0.5 {
        return 1.0;
    }
    var query: ShadowQuery;
    query.coords = coords.xyz;
    // Screen derivatives of the lookup, for receiver-plane bias and mip selection.
    query.coords_dx = shadow_coords(layer, world + world_dx, n, l).xyz - coords.xyz;
    query.coords_dy = shadow_coords(layer, world + world_dy, n, l).xyz - coords.xyz;
    query.pixel = pixel;
    query.distance = -(light.light_from_world * vec4<f32>(world, 1.0)).z;
    query.layer = layer;
    return sample_shadow(query);
}

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
    let layer = select_cascade(view_depth, in.world, n, l);
    var visibility = shadow_lookup(layer, in.world, n, l, world_dx, world_dy, in.clip.xy);
    // Blend into the next cascade over the last `cascades.z` of this one's depth range.
    let count = u32(light.cascades.x);
    if light.cascades.y < 0.5 && layer + 1u < count && light.cascades.z > 0.0 {
        let start = cascade_split(layer);
        let end = cascade_split(layer + 1u);
        let band = light.cascades.z * (end - start);
        if view_depth > end - band {
            let next = shadow_lookup(layer + 1u, in.world, n, l, world_dx, world_dy, in.clip.xy);
            visibility = mix(visibility, next, clamp((view_depth - (end - band)) / band, 0.0, 1.0));
        }
    }
    if light.direction.w > 0.5 && cone <= 0.0 {
        // Outside a spot's cone or range no light arrives: visibility 0 by definition.
        visibility = 0.0;
    }
    if dot(geometric_n, l) <= 0.0 {
        // A surface turned away from the light is shadowed by itself, whatever the map
        // says (the reference ray tracer uses the same geometric test).
        visibility = 0.0;
    }

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
