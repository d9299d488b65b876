// Whether a 2D shadow map (a sun's map or cascades, a spot's map) is unsure of a
// pixel. Its footprint is the bilinear 2×2 of the lookup and a ring of
// `UNSURE_RING_TEXELS` around it; each texel's stored depth is compared with the
// receiver's own depth there (following the receiver's plane, so that a tilted
// receiver is not taken for a caster of itself):
// - at or behind the receiver, within `tolerance` (half a texel of the receiver's
//   depth slope, for the plane's fit to a curved surface): the receiver itself or
//   something behind it, evidence of light;
// - in front of it by more than `margin` (the slope bias the map was drawn with, and
//   `UNSURE_DEPTH_TEXELS` texels of depth along the light's ray): a caster, evidence
//   of shadow;
// - in between: a caster touching the receiver, or the receiver's own surface bent
//   toward the light. This is where light leaks and acne live: unsure.
// The pixel is unsure when any texel is, or when the footprint holds both kinds.
//
// What this cannot see: a caster thinner than a texel that the map's rasterization
// missed altogether leaves no depth to disagree with.

// Texels of ring around the bilinear footprint.
const UNSURE_RING_TEXELS: i32 = 2;
// The depth band, in texel world sizes along the light's ray, inside which a stored
// depth is too close to the receiver's to trust.
const UNSURE_DEPTH_TEXELS: f32 = 2.0;

// `n` is the normal the lookup is offset along; `geometric_n` gives the receiver's plane.
fn map_unsure(world: vec3<f32>, n: vec3<f32>, geometric_n: vec3<f32>, l: vec3<f32>, view_depth: f32) -> bool {
    let layer = select_cascade(view_depth, world, n, l);
    let c = shadow_coords(layer, world, n, l);
    if c.w < 0.5 {
        // Outside every layer: the map has nothing to say.
        return true;
    }
    let size = light.resolution;
    let distance = -(light.light_from_world * vec4<f32>(world, 1.0)).z;
    let texel_world = local_texel_world_size(layer, world, distance);
    // The receiver's plane, through two tangents a texel long, in map coordinates.
    let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(geometric_n.x) > 0.9);
    let tangent = normalize(cross(geometric_n, helper));
    let t1 = tangent * texel_world;
    let t2 = cross(geometric_n, tangent) * texel_world;
    let a = shadow_coords(layer, world + t1, n, l).xyz - c.xyz;
    let b = shadow_coords(layer, world + t2, n, l).xyz - c.xyz;
    let det = a.x * b.y - a.y * b.x;
    if abs(det) < 1e-12 / (size * size) {
        // The receiver is seen edge-on from the light.
        return true;
    }
    // ∂depth/∂(u, v), by the 2×2 inverse, then per texel.
    let gradient = vec2<f32>(b.y * a.z - a.y * b.z, a.x * b.z - b.x * a.z) / det / size;
    let along_ray = abs(shadow_coords(layer, world - l * texel_world, n, l).z - c.z);
    let slope = abs(gradient.x) + abs(gradient.y);
    let tolerance = 0.5 * slope;
    let margin = UNSURE_DEPTH_TEXELS * along_ray + (light.slope_bias + 1.0) * slope;

    let p = c.xy * size - vec2<f32>(0.5);
    let base = vec2<i32>(floor(p));
    let last = i32(size) - 1;
    var lit = false;
    var shadowed = false;
    for (var dy = -UNSURE_RING_TEXELS; dy <= 1 + UNSURE_RING_TEXELS; dy++) {
        for (var dx = -UNSURE_RING_TEXELS; dx <= 1 + UNSURE_RING_TEXELS; dx++) {
            let texel = base + vec2<i32>(dx, dy);
            if any(texel < vec2<i32>(0)) || any(texel > vec2<i32>(last)) {
                return true;
            }
            let stored = textureLoad(shadow_map, texel, i32(layer), 0);
            let receiver = c.z + dot(gradient, vec2<f32>(texel) - p);
            if stored >= receiver - tolerance {
                lit = true;
            } else if stored <= receiver - margin {
                shadowed = true;
            } else {
                return true;
            }
        }
    }
    return lit && shadowed;
}
