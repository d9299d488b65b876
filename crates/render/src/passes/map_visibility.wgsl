// The shadow lookup of a light with 2D layers (a sun's map or cascades, a spot's
// map): pick the cascade, look up the technique's `sample_shadow` there, and blend
// into the next cascade near its end.
import package::passes::light_binding::{cascade_split, light, texel_world_size_at};
import package::passes::shading::MIN_NORMAL_OFFSET_SCALE;
import package::techniques::common::ShadowQuery;
import package::variant::sample_shadow;

// Shadow-map coordinates of a receiver at `world` with unit normal `n`, lit from `l`:
// the point is first pushed along its normal by the normal-offset bias (in texels of
// the map at the receiver, times 1 − N·L: a surface facing the light needs no offset,
// and offsetting it only shifts its shadows sideways), then projected: clip → NDC →
// texture space with v flipped.
// Returns (u, v, depth, inside) where inside is 1 when the point projects into the
// map's frustum.

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
    if light.cascades[layer].warped == 0u {
        return texel_world_size_at(layer, distance);
    }
    let step = light.cascades[layer].warp_step;
    // The light's x and y axes in world space: the first two rows of light_from_world.
    let m = light.light_from_world;
    let axis_x = vec3<f32>(m[0].x, m[1].x, m[2].x);
    let axis_y = vec3<f32>(m[0].y, m[1].y, m[2].y);
    let t = project_to_map(layer, world);
    let dx = (project_to_map(layer, world + axis_x * step) - t) * light.map.resolution / step;
    let dy = (project_to_map(layer, world + axis_y * step) - t) * light.map.resolution / step;
    let squares = dot(dx, dx) + dot(dy, dy);
    let det = abs(dx.x * dy.y - dy.x * dx.y);
    let sigma_max = sqrt(0.5 * (squares + sqrt(max(squares * squares - 4.0 * det * det, 0.0))));
    return sigma_max / max(det, 1e-20);
}

fn shadow_coords(layer: u32, world: vec3<f32>, n: vec3<f32>, l: vec3<f32>) -> vec4<f32> {
    let distance = -(light.light_from_world * vec4<f32>(world, 1.0)).z;
    let texel_world = local_texel_world_size(layer, world, distance);
    let slope = max(1.0 - clamp(dot(n, l), 0.0, 1.0), MIN_NORMAL_OFFSET_SCALE);
    let p = world + n * (light.bias.normal_offset * texel_world * slope);
    let clip = light.cascade_clip_from_world[layer] * vec4<f32>(p, 1.0);
    if clip.w <= 0.0 {
        return vec4<f32>(0.0, 0.0, 0.0, 0.0);
    }
    let ndc = clip.xyz / clip.w;
    let uv = ndc.xy * vec2<f32>(0.5, -0.5) + vec2<f32>(0.5, 0.5);
    let inside = all(uv >= vec2<f32>(0.0)) && all(uv <= vec2<f32>(1.0)) && ndc.z >= 0.0 && ndc.z <= 1.0;
    return vec4<f32>(uv, ndc.z, select(0.0, 1.0, inside));
}

// The cascade that shades a point at `view_depth`: by depth, the one whose split
// range holds it; by projection, the first whose map holds its lookup.
fn select_cascade(view_depth: f32, world: vec3<f32>, n: vec3<f32>, l: vec3<f32>) -> u32 {
    let count = light.map.layer_count;
    if light.cascade_choice.by_projection == 0u {
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
        let margin = 4.0 / light.map.resolution;
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

// The lit fraction at `world` and the layer that shaded it (the cascade), as
// (visibility, layer).
fn map_lookup_visibility(
    world: vec3<f32>,
    n: vec3<f32>,
    l: vec3<f32>,
    world_dx: vec3<f32>,
    world_dy: vec3<f32>,
    pixel: vec2<f32>,
    view_depth: f32,
) -> vec2<f32> {
    let layer = select_cascade(view_depth, world, n, l);
    var visibility = shadow_lookup(layer, world, n, l, world_dx, world_dy, pixel);
    // Blend into the next cascade over the last `cascades.z` of this one's depth range.
    let count = light.map.layer_count;
    if light.cascade_choice.by_projection == 0u && layer + 1u < count && light.cascade_choice.blend > 0.0 {
        let start = cascade_split(layer);
        let end = cascade_split(layer + 1u);
        let band = light.cascade_choice.blend * (end - start);
        if view_depth > end - band {
            let next = shadow_lookup(layer + 1u, world, n, l, world_dx, world_dy, pixel);
            visibility = mix(visibility, next, clamp((view_depth - (end - band)) / band, 0.0, 1.0));
        }
    }
    return vec2<f32>(visibility, f32(layer));
}
