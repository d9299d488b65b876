// Light kinds: everything a shader does differently for a sun, a spot and a point
// light, and nowhere else. Every other file asks these functions and never reads
// `Emitter::kind` (a test in passes/interface_tests.rs holds that), so a new kind is
// one more branch in each function here, with its constant in `LightKindGpu`
// (uniforms.rs). Composed wherever the light's structs are (`passes::LIGHT_WGSL`);
// each function takes the emitter, so the light list's elements use it as the light
// uniform's does. It needs only the generated constants and the sampling maps
// (light_shapes.wgsl).
import package::constants::{FALLOFF_INVERSE_SQUARE, LIGHT_POINT, LIGHT_SPOT, LIGHT_SUN};
import package::passes::light::{Emitter, SamplePlane};
import package::passes::light_shapes::{concentric_disk, cone_direction, orthonormal_pair};

// Distances below this count as this, so that a surface touching a light gets a
// large but finite irradiance (`Falloff::MIN_DISTANCE`).
const MIN_FALLOFF_DISTANCE: f32 = 1e-3;

// A sun's rays run past every caster: a ray's length beyond the scene's bounds.
const SUN_RAY_LENGTH: f32 = 3.0e38;

// The factor on a light's colour × intensity at `distance` from it: 1 for a constant
// falloff; for KHR_lights_punctual's, the inverse square times the window
// clamp(1 − (d / window)⁴, 0, 1) that reaches 0 at `window` (none when 0).
// `gnomon_scene::Falloff::at` on the CPU.
fn distance_falloff(falloff: u32, window: f32, distance: f32) -> f32 {
    if falloff != FALLOFF_INVERSE_SQUARE {
        return 1.0;
    }
    var windowed = 1.0;
    if window > 0.0 {
        let r = distance / window;
        windowed = clamp(1.0 - r * r * r * r, 0.0, 1.0);
    }
    let d = max(distance, MIN_FALLOFF_DISTANCE);
    return windowed / (d * d);
}

// What of emitter `e`'s colour × intensity arrives at `world` before shadowing: 1
// for the sun; for a spot, its cone's fade (0 outside the outer cone) times its
// distance falloff, 0 beyond its range; for a point light, the falloff within its range.
// Returns (unit direction to the light, that factor: > 0 exactly where light arrives).
fn emitter_geometry(e: Emitter, world: vec3<f32>) -> vec4<f32> {
    if e.kind == LIGHT_SUN {
        return vec4<f32>(-e.direction, 1.0);
    }
    let to_light = e.position - world;
    let dist = length(to_light);
    let l = to_light / dist;
    let falloff = distance_falloff(e.falloff, e.falloff_window, dist);
    if e.kind == LIGHT_POINT {
        return vec4<f32>(l, select(0.0, falloff, dist <= e.range));
    }
    let cos_angle = dot(-l, e.direction);
    let inside = cos_angle >= e.cos_outer && dist <= e.range;
    let cone = smoothstep(e.cos_outer, e.cos_inner, cos_angle);
    return vec4<f32>(l, select(0.0, cone * falloff, inside));
}

// Whether no light of `e` arrives where `emitter_geometry`'s factor is `factor`:
// outside a spot's cone or a local light's range. A sun's light arrives everywhere.
fn emitter_unlit(e: Emitter, factor: f32) -> bool {
    return e.kind != LIGHT_SUN && factor <= 0.0;
}

// How far a ray from `world` toward `e` runs before it reaches the light: to a spot's
// or point's centre, past every caster for a sun.
fn emitter_ray_length(e: Emitter, world: vec3<f32>) -> f32 {
    if e.kind == LIGHT_SUN {
        return SUN_RAY_LENGTH;
    }
    return length(e.position - world);
}

// Distance along the light's axis (light view −z) of a point whose shadow-map depth
// is `depth`, between the map's `near` and `far` planes. A sun's orthographic map
// stores it linearly; a spot's perspective one the D3D-style f(z − n) / (z (f − n)).
fn emitter_distance_from_depth(e: Emitter, near: f32, far: f32, depth: f32) -> f32 {
    if e.kind == LIGHT_SUN {
        return near + depth * (far - near);
    }
    return near * far / (far - depth * (far - near));
}

// The inverse of `emitter_distance_from_depth`: the depth a map of `e` stores for a
// point at light distance `distance` along its axis.
fn emitter_depth_from_distance(e: Emitter, near: f32, far: f32, distance: f32) -> f32 {
    if e.kind == LIGHT_SUN {
        return (distance - near) / (far - near);
    }
    return far * (distance - near) / (distance * (far - near));
}

// Whether all of `e`'s area lies above the plane through `world` with unit normal
// `normal`: no ray to it from there is below the surface's horizon. A sun's disk
// lies within its angular radius of its direction; a spot's disk within its radius
// of its centre, across its axis; a point light's sphere within its radius.
fn emitter_above_plane(e: Emitter, world: vec3<f32>, normal: vec3<f32>) -> bool {
    if e.kind == LIGHT_SUN {
        return dot(normal, -e.direction) > e.size * inverseSqrt(1.0 + e.size * e.size);
    }
    let height = dot(normal, e.position - world);
    if e.kind == LIGHT_SPOT {
        let across = dot(normal, e.direction);
        return height > e.size * sqrt(max(1.0 - across * across, 0.0));
    }
    return height > e.size;
}

// The radius, in world units, of the cone from a receiver at light distance
// `receiver` to the light's area, at light distance `at`: e.size × (d − at) for a sun
// (the tangent of its angular radius), e.size × (d − at) / d for a spot's disk or a
// point's sphere (similar triangles from the light's centre). PCSS's blocker search
// and refinement's footprint both read it.
fn emitter_cone_radius(e: Emitter, receiver: f32, at: f32) -> f32 {
    let reach = e.size * max(receiver - at, 0.0);
    return select(reach / receiver, reach, e.kind == LIGHT_SUN);
}

// The penumbra's half-width, in world units, at a receiver `gap` behind a blocker
// that lies `light_to_blocker` from the light, by similar triangles (Fernando,
// "Percentage-Closer Soft Shadows", 2005): e.size × gap / light_to_blocker for a
// spot's disk or a point's sphere, e.size × gap for a sun.
fn emitter_penumbra_radius(e: Emitter, gap: f32, light_to_blocker: f32) -> f32 {
    let reach = e.size * gap;
    if e.kind == LIGHT_SUN {
        return reach;
    }
    return reach / light_to_blocker;
}

// A shadow ray from `p` toward the point `u` of `e`'s area: its direction, and its
// length (past every caster for a sun). `e.size` is the tangent of the sun's angular
// radius, or the spot's disk or point's sphere radius. The CPU reference's
// `Emitter::sample` maps the unit square the same way.
fn emitter_sample(e: Emitter, p: vec3<f32>, u: vec2<f32>) -> vec4<f32> {
    if e.kind == LIGHT_SUN {
        return vec4<f32>(cone_direction(u, -e.direction, atan(e.size)), SUN_RAY_LENGTH);
    }
    if e.kind == LIGHT_SPOT {
        // A disk facing along the spot's axis.
        let basis = orthonormal_pair(e.direction);
        let q = concentric_disk(u) * e.size;
        let to = e.position + basis[0] * q.x + basis[1] * q.y - p;
        let len = length(to);
        return vec4<f32>(to / len, len);
    }
    // A sphere of uniform radiance: uniform over the cone it subtends, which is
    // uniform over its visible area; the ray ends where it enters the sphere.
    let to = e.position - p;
    let dist = length(to);
    let axis = to / dist;
    let radius = e.size;
    if radius >= dist {
        return vec4<f32>(axis, dist);
    }
    let d = cone_direction(u, axis, asin(radius / dist));
    let along = dot(d, to);
    let entry = along - sqrt(max(radius * radius - (dist * dist - along * along), 0.0));
    return vec4<f32>(d, max(entry, 0.0));
}

// The weight of a penumbra ray of length `len` in the light's visibility, relative to
// its other rays: under an inverse-square falloff, each point of a spot's disk is a
// point light of that falloff, so nearer points count for more (the reference's
// `Emitter::weight`). A sphere's rays are uniform in the solid angle it subtends,
// which already makes its light fall off as the inverse square of the distance, so
// they count alike, as do every ray of a constant light's and a sun's.
fn emitter_sample_weight(e: Emitter, len: f32) -> f32 {
    if e.kind != LIGHT_SPOT {
        return 1.0;
    }
    return distance_falloff(e.falloff, e.falloff_window, len);
}

// The plane of `e`'s samples as seen from `origin` (a penumbra beam's,
// rays/penumbra_beam.wgsl), its axes turned by `turn` radians: the unit disk's point
// x lies in direction `toward + x.x b0 + x.y b1`. A spot's disk faces along its
// axis, its radius the unit; a sun's and a point light's samples lie on the plane
// a unit along the axis, where the cone of the disk or sphere has radius
// tan(half-angle), over that radius. Along with it, where casters can block: their
// depth along `depth_axis` in (0, far), and the axis ray and widening the walk
// bounds the cone with.
fn emitter_sample_plane(e: Emitter, origin: vec3<f32>, turn: f32) -> SamplePlane {
    let rotation = vec2<f32>(cos(turn), sin(turn));
    if e.kind == LIGHT_SPOT {
        let basis = orthonormal_pair(e.direction);
        let to_light = e.position - origin;
        let distance = length(to_light);
        let radius = e.size;
        // As a share of the way to the disk's plane, along the spot's axis.
        let height = dot(to_light, -e.direction);
        return SamplePlane(
            to_light / radius,
            basis[0] * rotation.x + basis[1] * rotation.y,
            basis[1] * rotation.x - basis[0] * rotation.y,
            -e.direction / max(height, 1e-30),
            1.0,
            to_light / distance,
            distance + radius,
            // A point of the cone lies within radius / (distance − radius) of its
            // distance along the axis from the axis.
            select(1e6, radius / (distance - radius), distance > 1.01 * radius),
        );
    }
    var axis = -e.direction;
    var far = SUN_RAY_LENGTH;
    var tan_half = e.size;
    if e.kind != LIGHT_SUN {
        let to_light = e.position - origin;
        let distance = length(to_light);
        axis = to_light / distance;
        let radius = min(e.size, 0.999 * distance);
        tan_half = radius / sqrt(distance * distance - radius * radius);
        // The sphere's nearest point: a caster nearer the light than that, beside
        // the rays to its rim, is missed.
        far = distance - radius;
    }
    let basis = orthonormal_pair(axis);
    return SamplePlane(
        axis / tan_half,
        basis[0] * rotation.x + basis[1] * rotation.y,
        basis[1] * rotation.x - basis[0] * rotation.y,
        axis,
        far,
        axis,
        far,
        tan_half,
    );
}

// The weight of the sample in direction `d` from the receiver (`emitter_sample_plane`'s
// `toward + x.x b0 + x.y b1`) among `e`'s samples, so that they weigh as the
// reference's rays: over a spot's disk, uniform in area, the falloff of the
// distance to the sample's point (`emitter_sample_weight`); over a sun's or point
// light's cone, the density of directions uniform in solid angle on the plane,
// cos³θ.
fn emitter_plane_weight(e: Emitter, plane: SamplePlane, d: vec3<f32>) -> f32 {
    if e.kind == LIGHT_SPOT {
        return distance_falloff(e.falloff, e.falloff_window, length(d) * e.size);
    }
    let c = inverseSqrt(dot(d, d) / dot(plane.toward, plane.toward));
    return c * c * c;
}

// Whether `emitter_plane_weight` weighs all of `e`'s samples alike: a spot whose
// light does not fall off with distance (its samples lie uniform in area).
fn emitter_weighs_samples_alike(e: Emitter) -> bool {
    return e.kind == LIGHT_SPOT && e.falloff != FALLOFF_INVERSE_SQUARE;
}
