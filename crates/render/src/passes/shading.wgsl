// What the passes that shade from the camera (lighting, shadow mask, ray trace) and the
// shadow receiver share about a surface point and its light: the light's direction
// and cone at the point (`emitter_geometry`, light_kinds.wgsl, of the uniform's light),
// the normal-offset floor, and the normal's side.
import package::passes::light::Emitter;
import package::passes::light_binding::light;
import package::passes::light_kinds::emitter_geometry;

// A surface facing the light keeps this fraction of the offset, against the depth
// quantisation that the slope bias (zero for it) cannot cover.
const MIN_NORMAL_OFFSET_SCALE: f32 = 0.2;

// The light uniform's emitter.
fn light_emitter() -> Emitter {
    return light.emitter;
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
