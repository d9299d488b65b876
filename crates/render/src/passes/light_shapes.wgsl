// Maps from the unit square onto the shapes lights have (a disk, a cone of
// directions) and the orthonormal pair they are built on: pure geometry, which
// light_kinds.wgsl samples lights with and the cube lookups share.

const TAU: f32 = 6.283185307179586;
const FRAC_PI_4: f32 = 0.7853981633974483;

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

// The unit square to the unit disk, keeping strata compact (Shirley & Chiu, "A Low
// Distortion Map Between Disk and Square", JGT 1997).
fn concentric_disk(u: vec2<f32>) -> vec2<f32> {
    let a = 2.0 * u - vec2<f32>(1.0);
    if a.x == 0.0 && a.y == 0.0 {
        return vec2<f32>(0.0);
    }
    var r: f32;
    var theta: f32;
    if abs(a.x) > abs(a.y) {
        r = a.x;
        theta = FRAC_PI_4 * (a.y / a.x);
    } else {
        r = a.y;
        theta = 2.0 * FRAC_PI_4 - FRAC_PI_4 * (a.x / a.y);
    }
    return r * vec2<f32>(cos(theta), sin(theta));
}

// The unit square to directions within `half_angle` of `axis`, uniform in solid
// angle: cos θ = 1 − u (1 − cos θ_max), φ = 2π v.
fn cone_direction(u: vec2<f32>, axis: vec3<f32>, half_angle: f32) -> vec3<f32> {
    let cos_theta = 1.0 - u.x * (1.0 - cos(half_angle));
    let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    let phi = TAU * u.y;
    let basis = orthonormal_pair(axis);
    return normalize(axis * cos_theta + (basis[0] * cos(phi) + basis[1] * sin(phi)) * sin_theta);
}
