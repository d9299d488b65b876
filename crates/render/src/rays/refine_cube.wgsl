// Whether a point light's cube map is unsure of a pixel: the footprint test of 2D
// maps (refine_footprint.wgsl; the rules are refine_map.wgsl's) on the face the
// lookup fell on, read as one layer of `shadow_map` through that face's own
// projection, the one its depths were drawn with. A face stores distance over range
// (shadow_depth.wgsl), which is not affine across a plane: each texel's receiver
// distance is where the ray from the light through the texel's centre meets the
// receiver's plane, exactly. A receiver seen edge-on from the light is unsure.
import package::passes::light_binding::light;
import package::passes::shading::MIN_NORMAL_OFFSET_SCALE;
import package::rays::refine_footprint::{FootprintBounds, UNSURE_DEPTH_TEXELS, UNSURE_GRAZING_COS, footprint_unsure, receiver_bias};
import package::rays::map_step::map_step;
import package::techniques::cube::cube_texel_world_size;

// The receiver's plane, for `footprint_receiver`: its normal, `offset · normal` (the
// lookup point's offset from the light), and the face's directions: a texel at
// NDC (x, y) lies along `face_from_ndc` × (x, y, 1) from the light.
struct CubePlane {
    normal: vec3<f32>,
    reach: f32,
    face_from_ndc: mat3x3<f32>,
};
var<private> cube_plane: CubePlane;

// The receiver's distance over range along texel (x, y)'s centre ray. A texel whose
// ray misses the plane (parallel to it, or meeting it behind the light) gets a
// depth past the range, so whatever it stores counts as a caster: with light
// elsewhere in the footprint, the pixel is traced.
fn texel_receiver(x: i32, y: i32) -> f32 {
    let size = light.map.resolution;
    let ndc = vec2<f32>((f32(x) + 0.5) / size * 2.0 - 1.0, 1.0 - (f32(y) + 0.5) / size * 2.0);
    let direction = cube_plane.face_from_ndc * vec3<f32>(ndc, 1.0);
    let along = dot(direction, cube_plane.normal);
    let s = cube_plane.reach / along;
    if abs(along) < 1e-12 || s <= 0.0 {
        return 2.0;
    }
    return s * length(direction) / light.emitter.range;
}

// The receiver's depth at the texels (x, y + 1), (x + 1, y + 1), (x + 1, y), (x, y).
fn cube_footprint_receiver(x: i32, y: i32) -> vec4<f32> {
    return vec4<f32>(texel_receiver(x, y + 1), texel_receiver(x + 1, y + 1), texel_receiver(x + 1, y), texel_receiver(x, y));
}

// The inverse of the face's projection of directions: rows 0, 1 and 3 of
// `clip_from_world` take a direction d from the light to (clip x, clip y, clip w);
// for a face whose eye is the light, NDC (x, y) is the direction with (x, y, 1).
// (The inverse of the matrix with rows a, b, c has columns b × c, c × a, a × b over
// the determinant a · (b × c).)
fn face_directions(clip_from_world: mat4x4<f32>) -> mat3x3<f32> {
    let m = transpose(clip_from_world);
    let a = m[0].xyz;
    let b = m[1].xyz;
    let c = m[3].xyz;
    let bc = cross(b, c);
    return mat3x3<f32>(bc, cross(c, a), cross(a, b)) * (1.0 / dot(a, bc));
}

// `layer` is the face the lookup shaded with; `n` is the normal it was offset along;
// `geometric_n` gives the receiver's plane.
fn cube_map_unsure(world: vec3<f32>, n: vec3<f32>, geometric_n: vec3<f32>, l: vec3<f32>, layer: u32) -> bool {
    // The lookup's own point: the receiver pushed along its normal, as
    // cube_visibility.wgsl pushes it.
    let to_world = world - light.emitter.position;
    let scale = max(1.0 - clamp(dot(n, l), 0.0, 1.0), MIN_NORMAL_OFFSET_SCALE);
    let offset = to_world + n * (light.bias.normal_offset * cube_texel_world_size(to_world) * scale);
    let clip_from_world = light.cascade_clip_from_world[layer];
    let clip = clip_from_world * vec4<f32>(light.emitter.position + offset, 1.0);
    if clip.w <= 0.0 {
        return true;
    }
    let ndc = clip.xyz / clip.w;
    let uv = ndc.xy * vec2<f32>(0.5, -0.5) + vec2<f32>(0.5, 0.5);
    let distance = length(offset);
    let texel_world = cube_texel_world_size(offset);
    // The receiver's plane, through two tangents a texel long, in the face's (u, v)
    // and in distance over range.
    let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(geometric_n.x) > 0.9);
    let ta = normalize(cross(geometric_n, helper)) * texel_world;
    let tb = cross(geometric_n, normalize(ta)) * texel_world;
    let per_range = 1.0 / (distance * light.emitter.range);
    let a = vec3<f32>(map_step(clip_from_world, ndc, clip.w, ta).xy, dot(offset, ta) * per_range);
    let b = vec3<f32>(map_step(clip_from_world, ndc, clip.w, tb).xy, dot(offset, tb) * per_range);
    let size = light.map.resolution;
    let det = a.x * b.y - a.y * b.x;
    if abs(det) < 1e-12 / (size * size) {
        return true;
    }
    // ∂(distance / range)/∂(u, v), by the 2×2 inverse, then per texel.
    let gradient = vec2<f32>(b.y * a.z - a.y * b.z, a.x * b.z - b.x * a.z) / det / size;
    let slope = abs(gradient.x) + abs(gradient.y);
    let margin = UNSURE_DEPTH_TEXELS * texel_world / light.emitter.range + (light.bias.slope + 1.0) * slope;
    let own_bias = receiver_bias(max(abs(gradient.x), abs(gradient.y)), distance / light.emitter.range);
    cube_plane = CubePlane(geometric_n, dot(offset, geometric_n), face_directions(clip_from_world));
    // The surface itself lies behind the lookup's plane along the light's ray through
    // the lookup, by the normal offset's push over the ray's cosine with the plane
    // (which faces the light; an edge-on plane was refused above).
    let cosine = max(-dot(offset / distance, geometric_n), 1e-6);
    let surface = (cube_plane.reach - dot(to_world, geometric_n)) / cosine / light.emitter.range;
    let grazing = dot(geometric_n, l) < UNSURE_GRAZING_COS;
    return footprint_unsure(uv, FootprintBounds(0.5 * slope, margin, own_bias, surface, grazing), layer);
}
