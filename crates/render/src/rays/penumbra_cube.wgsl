// The penumbra classification (penumbra_classify.wgsl) of a point light's cube: a
// receiver is placed on the face its direction from the light falls on
// (`cube_face`), in that face's own projection, at `cube_depth` of its distance
// along the face's axis. Where the cone from it to the light may reach a caster
// another face holds (a receiver near a face's edge), that face is searched too,
// with the receiver placed in its projection, past its edge.
import package::passes::cube_visibility::cube_face;
import package::passes::light_binding::light;
import package::rays::map_step::map_step;
import package::rays::penumbra_classify::{CLASSIFIED_UNSURE, Receiver, casters_reach, classified, cube_depth, cube_reach, layer_distance, layer_nearest, plane_gradient, pyramid_levels, receiver_placed, receiver_tolerance, seen_plane_normal, unplaced_receiver};

// The receiver at `world` on face `face` of a point light's cube: the face's
// projection places it (past the face's edge where its direction falls on another
// face), and its depth is `cube_depth` of its distance along the face's axis (the
// face's clip w), whose change along a tangent t is near Δw / w².
fn cube_receiver(face: u32, world: vec3<f32>, world_dx: vec3<f32>, world_dy: vec3<f32>) -> Receiver {
    let clip_from_world = light.cascade_clip_from_world[face];
    let clip = clip_from_world * vec4<f32>(world, 1.0);
    if clip.w <= 0.0 {
        return unplaced_receiver(face, true);
    }
    let ndc = clip.xyz / clip.w;
    let step = light.map.near / (clip.w * clip.w);
    let a = vec3<f32>(map_step(clip_from_world, ndc, clip.w, world_dx).xy, step * (clip_from_world * vec4<f32>(world_dx, 0.0)).w);
    let b = vec3<f32>(map_step(clip_from_world, ndc, clip.w, world_dy).xy, step * (clip_from_world * vec4<f32>(world_dy, 0.0)).w);
    if abs(a.x * b.y - a.y * b.x) <= 1e-20 {
        return unplaced_receiver(face, true);
    }
    let texel = (ndc.xy * vec2<f32>(0.5, -0.5) + vec2<f32>(0.5)) * light.map.resolution - vec2<f32>(0.5);
    return Receiver(texel, cube_depth(clip.w), plane_gradient(a, b), clip.w, face, true);
}

// A face's axis, as `cube_face` numbers the faces: +x, −x, +y, −y, +z, −z.
fn face_axis(face: u32) -> vec3<f32> {
    var axis = vec3<f32>(0.0);
    axis[face / 2u] = select(1.0, -1.0, (face & 1u) == 1u);
    return axis;
}

// The sine of the widest angle, at the light's centre C, between a receiver's
// direction and a caster on face `face` that can hide part of the light from it.
// Such a caster P lies on a segment from the receiver R to the light's visible cap,
// where the angle β at R between P and C is at most α, sin α = size / |RC|; by the
// law of sines, sin φ = |RP| sin β / |CP| ≤ |RC| sin α / ρ = size / ρ, ρ = |CP|, and φ
// stays under 90° from R to the cap. No caster on the face stands nearer C than the
// face's nearest depth, as a distance along its axis (at most ρ).
fn face_reach_sine(face: u32) -> f32 {
    let rho = layer_distance(true, layer_nearest(face));
    return light.emitter.size / max(rho, light.emitter.size);
}

// Whether a caster another face than `own` holds may hide part of the light from
// the receiver at `world`, in direction u from the light. A face is searched unless
// every direction it holds lies farther from u than its casters reach
// (`face_reach_sine`): its directions v have v·b ≥ v·a (b its axis, a own's), a
// half-space whose nearest direction to u lies asin(u·(a − b) / |a − b|) away.
fn other_faces_reach(own: u32, world: vec3<f32>, world_dx: vec3<f32>, world_dy: vec3<f32>) -> bool {
    let offset = world - light.emitter.position;
    let u = normalize(offset);
    let a = face_axis(own);
    for (var face = 0u; face < 6u; face++) {
        let between = a - face_axis(face);
        if face == own || dot(u, between) / length(between) > face_reach_sine(face) {
            continue;
        }
        let r = cube_receiver(face, world, world_dx, world_dy);
        // Behind the face's plane, seen edge-on, or too near it for the cone's bound
        // (`cube_reach`, which holds where the receiver's distance along the axis
        // exceeds the light's size): the map cannot say.
        if !receiver_placed(r) || r.distance <= 2.0 * light.emitter.size {
            return true;
        }
        if casters_reach(r, cube_reach(r, offset), layer_nearest(face), receiver_tolerance(r), pyramid_levels()) {
            return true;
        }
    }
    return false;
}

// `lookup_visibility` for a point light with an area whose penumbrae are traced, on
// its cube: (`CLASSIFIED_*`, the face that holds the receiver).
fn penumbra_cube_lookup(
    world: vec3<f32>,
    n: vec3<f32>,
    l: vec3<f32>,
    world_dx: vec3<f32>,
    world_dy: vec3<f32>,
    pixel: vec2<f32>,
    view_depth: f32,
) -> vec2<f32> {
    let offset = world - light.emitter.position;
    let own = cube_face(offset);
    let r = cube_receiver(own, world, world_dx, world_dy);
    if !receiver_placed(r) {
        return vec2<f32>(CLASSIFIED_UNSURE, f32(own));
    }
    let reach = cube_reach(r, offset);
    let reached = casters_reach(r, reach, layer_nearest(own), receiver_tolerance(r), pyramid_levels())
        || other_faces_reach(own, world, world_dx, world_dy);
    let visibility = classified(r, reach, reached, seen_plane_normal(n, world_dx, world_dy), world);
    return vec2<f32>(visibility, f32(own));
}

// The face that holds the receiver at `world`, for a pixel whose classification the
// penumbra history kept (penumbra_mask.wgsl).
fn cube_penumbra_layer(world: vec3<f32>, n: vec3<f32>, l: vec3<f32>, view_depth: f32) -> f32 {
    return f32(cube_face(world - light.emitter.position));
}
