// What the passes that shade from the camera (lighting, shadow mask, ray trace) and the
// shadow receiver share about a surface point and its light: the light's direction
// and cone at the point, the normal-offset floor, and an orthonormal basis.

// A surface facing the light keeps this fraction of the offset, against the depth
// quantisation that the slope bias (zero for it) cannot cover.
const MIN_NORMAL_OFFSET_SCALE: f32 = 0.2;

// The light uniform's emitter.
fn light_emitter() -> Emitter {
    return light.emitter;
}

// Distances below this count as this, so that a surface touching a light gets a
// large but finite irradiance (`Falloff::MIN_DISTANCE`).
const MIN_FALLOFF_DISTANCE: f32 = 1e-3;

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

// `emitter_geometry` of the light uniform's light.
fn light_geometry(world: vec3<f32>) -> vec4<f32> {
    return emitter_geometry(light_emitter(), world);
}

// The light a surface reflects toward `v` per unit of arriving radiance: Lambert
// diffuse and a Blinn-Phong lobe of weight `specular` and exponent `shininess`, with
// no highlight on the side facing away from the light.
fn blinn_phong(albedo: vec3<f32>, specular: f32, shininess: f32, n: vec3<f32>, l: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    let n_dot_l = max(dot(n, l), 0.0);
    let h = normalize(l + v);
    let highlight = specular * pow(max(dot(n, h), 0.0), shininess) * select(0.0, 1.0, n_dot_l > 0.0);
    return albedo * n_dot_l + vec3<f32>(highlight);
}

// `n` turned into the hemisphere of `toward`: the side of a surface a given
// direction sees. Two-sided surfaces take their shading normal from the side the
// camera sees this way, not from the winding (see surface.wgsl).
fn facing_side(n: vec3<f32>, toward: vec3<f32>) -> vec3<f32> {
    return select(n, -n, dot(n, toward) < 0.0);
}

// An orthonormal pair perpendicular to unit `n`, the columns of the matrix; the cube
// lookups and the light's samples share it (Duff et al., "Building an
// orthonormal basis, revisited", JCGT 2017).
fn orthonormal_pair(n: vec3<f32>) -> mat2x3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return mat2x3<f32>(
        vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        vec3<f32>(b, sign + n.y * n.y * a, -n.y),
    );
}

// A bound on the error of N·L where the geometric normal `geometric_n` of the point
// `world` comes from its screen derivatives `world_dx`, `world_dy` (dpdx and dpdy of
// an interpolated f32 position, or the shadow-mask pass's rebuild of them): each
// difference is off by up to two units in the last place of the point's largest
// coordinate, which turns the normal by up to that over each derivative's length.
// Within it, whether the surface faces the light at all is not known: on Sponza's
// arcade under a 70° sun, one face lies at N·L = 3.5e-5, and a normal rebuilt from
// neighbouring pixels' exact points swings by ±1.4e-4. Refinement lets a ray decide
// there (`ray_decides`).
fn facing_error(world: vec3<f32>, world_dx: vec3<f32>, world_dy: vec3<f32>) -> f32 {
    let ulp = 2.0 * 1.1920929e-7 * max(abs(world.x), max(abs(world.y), abs(world.z)));
    return ulp * (1.0 / max(length(world_dx), 1e-30) + 1.0 / max(length(world_dy), 1e-30));
}
