// What every technique's `sample_shadow` receives, and helpers they share.
import package::constants::MAX_KERNEL_TEXELS;
import package::passes::light_binding::{light, texel_world_size_at};
import package::techniques::bindings::{shadow_compare, shadow_map};
import package::variant::POISSON_DISK;

// One shadow lookup. `coords` is (u, v, depth) in shadow-map texture space (v down,
// depth as stored in the map); the derivatives are those of `coords` across the
// screen, taken in uniform control flow by the lighting pass.
struct ShadowQuery {
    coords: vec3<f32>,
    coords_dx: vec3<f32>,
    coords_dy: vec3<f32>,
    // Fragment position in pixels, for per-pixel noise.
    pixel: vec2<f32>,
    // Distance of the receiver along the light's axis (light view −z).
    distance: f32,
    // The shadow map's layer: the cascade.
    layer: u32,
};

// World size of one shadow texel at the receiver.
fn texel_world_size(q: ShadowQuery) -> f32 {
    return texel_world_size_at(q.layer, q.distance);
}

// Interleaved gradient noise in [0, 1) (Jimenez, "Next generation post processing in
// Call of Duty: Advanced Warfare", SIGGRAPH 2014): cheap, and its gradient pattern
// averages out well over small pixel neighbourhoods.
fn interleaved_gradient_noise(pixel: vec2<f32>) -> f32 {
    return fract(52.9829189 * fract(dot(floor(pixel), vec2<f32>(0.06711056, 0.00583715))));
}

// A rotation by a per-pixel angle from interleaved gradient noise: a Poisson disk
// turned differently at each pixel trades the banding of one fixed pattern for
// noise that neighbouring pixels average out.
fn disk_rotation(pixel: vec2<f32>) -> mat2x2<f32> {
    let angle = 6.2831853 * interleaved_gradient_noise(pixel);
    return mat2x2<f32>(cos(angle), sin(angle), -sin(angle), cos(angle));
}

// The largest depth slope, per texel, that the receiver plane may have: beyond it
// the screen-space derivatives come from a silhouette or a sliver triangle, not a
// plane, and extrapolating them across a kernel would do more harm than good.
const MAX_RECEIVER_SLOPE_PER_TEXEL: f32 = 0.01;

// ∂depth/∂(u, v) of the receiver's plane, or 0 when receiver-plane bias is off.
// The screen derivatives of (u, v, depth) satisfy
//   [∂u/∂x ∂v/∂x; ∂u/∂y ∂v/∂y] · (∂d/∂u, ∂d/∂v) = (∂d/∂x, ∂d/∂y),
// solved by the 2×2 inverse (Isidoro, "Shadow mapping: GPU-based tips and
// techniques", GDC 2006; Schüler, "Eliminating surface acne with gradient shadow
// mapping", ShaderX4 2006).
fn receiver_depth_gradient(q: ShadowQuery) -> vec2<f32> {
    if light.bias.receiver_plane == 0u {
        return vec2<f32>(0.0);
    }
    let a = q.coords_dx;
    let b = q.coords_dy;
    let det = a.x * b.y - a.y * b.x;
    if abs(det) < 1e-24 {
        return vec2<f32>(0.0);
    }
    var g = vec2<f32>(b.y * a.z - a.y * b.z, a.x * b.z - b.x * a.z) / det;
    let limit = MAX_RECEIVER_SLOPE_PER_TEXEL * light.map.resolution;
    let len = length(g);
    if len > limit {
        g *= limit / len;
    }
    return g;
}

// One bilinear comparison tap `offset` texels from the lookup, with the compared
// depth moved along the receiver plane `gradient`.
fn compare_tap(q: ShadowQuery, gradient: vec2<f32>, offset: vec2<f32>) -> f32 {
    let duv = offset / light.map.resolution;
    return textureSampleCompareLevel(
        shadow_map, shadow_compare, q.coords.xy + duv, q.layer, q.coords.z + dot(gradient, duv)
    );
}

// Rotates the first `count` points of the Poisson disk by a per-pixel angle, scales
// them to `radius` texels along each of the map's axes (a disk in the world is an
// ellipse in oblong texels: `texel_shape`), and averages the comparison taps there.
fn pcf_poisson(q: ShadowQuery, radius: vec2<f32>, count: u32) -> f32 {
    let gradient = receiver_depth_gradient(q);
    let rotation = disk_rotation(q.pixel);
    var sum = 0.0;
    for (var i = 0u; i < count; i++) {
        sum += compare_tap(q, gradient, rotation * POISSON_DISK[i] * radius);
    }
    return sum / f32(count);
}

// The kernel width in texels at this receiver: --pcf-kernel as given, or converted
// from world units by the texel size there (at least 1, at most 32 texels).
fn kernel_width_texels(q: ShadowQuery) -> f32 {
    if light.pcf.kernel_in_world == 1u {
        return clamp(light.pcf.kernel_width / texel_world_size(q), 1.0, MAX_KERNEL_TEXELS);
    }
    return light.pcf.kernel_width;
}
