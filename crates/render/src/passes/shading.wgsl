// What the passes that shade from the camera (lighting, shadow mask, ray trace) and the
// shadow receiver share about a surface point and its light: the light's direction
// and cone at the point, the normal-offset floor, and an orthonormal basis.

// A surface facing the light keeps this fraction of the offset, against the depth
// quantisation that the slope bias (zero for it) cannot cover.
const MIN_NORMAL_OFFSET_SCALE: f32 = 0.2;

// Fraction of the light arriving at `world` before shadowing: 1 for the sun, the
// cone and range test for a spot (0 outside the outer cone or beyond the range), the
// range test for a point light.
// Returns (unit direction to the light, cone factor in [0, 1]).
fn light_geometry(world: vec3<f32>) -> vec4<f32> {
    if light.kind == LIGHT_SUN {
        return vec4<f32>(-light.direction, 1.0);
    }
    let to_light = light.position - world;
    let dist = length(to_light);
    let l = to_light / dist;
    if light.kind == LIGHT_POINT {
        return vec4<f32>(l, select(0.0, 1.0, dist <= light.range));
    }
    let cos_angle = dot(-l, light.direction);
    let inside = cos_angle >= light.cos_outer && dist <= light.range;
    let falloff = smoothstep(light.cos_outer, light.cos_inner, cos_angle);
    return vec4<f32>(l, select(0.0, falloff, inside));
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
