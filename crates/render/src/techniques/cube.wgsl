// What every technique's `sample_shadow_cube` receives, and the helpers they share:
// a point light's cube map is sampled by direction, and the hardware picks the face
// and filters across face seams (Vulkan always filters cube maps seamlessly), so
// kernels are laid out in the plane across the ray and never meet a face edge.
import package::constants::MAX_KERNEL_TEXELS;
import package::passes::light_binding::light;
import package::techniques::bindings::{shadow_compare, shadow_cube};
import package::techniques::common::disk_rotation;
import package::variant::POISSON_DISK;

// One cube lookup.
struct CubeQuery {
    // From the light to the (biased) receiver, in world units.
    offset: vec3<f32>,
    // |offset| / range: the receiver's depth as the cube stores it.
    depth: f32,
    // World size of one texel across the ray at the receiver.
    texel_world: f32,
    // Fragment position in pixels, for per-pixel noise.
    pixel: vec2<f32>,
    // Orthonormal axes across the ray, for kernel offsets.
    tangent: vec3<f32>,
    bitangent: vec3<f32>,
    // Unit normal of the receiver's plane, for receiver-plane depth bias; zero
    // without it.
    plane_normal: vec3<f32>,
};

// The steepest receiver plane a tap follows, as depth change per unit of offset
// across the ray (tan 76°): steeper planes come from silhouettes and slivers, and
// following them across a kernel would open leaks.
const MAX_CUBE_RECEIVER_SLOPE: f32 = 4.0;

// The depth the receiver's plane has along `direction` (from the light): where the
// ray meets the plane through the receiver, n · (s·direction − offset) = 0. A kernel
// tap compares with it instead of the receiver's own depth, so that a plane tilted
// away from the light does not shadow itself across a wide kernel (receiver-plane
// depth bias, exact for a planar receiver; the 2D maps' version is
// `receiver_depth_gradient`).
fn cube_tap_depth(q: CubeQuery, direction: vec3<f32>) -> f32 {
    let along = dot(q.plane_normal, direction);
    if abs(along) < 1e-6 * length(direction) {
        return q.depth;
    }
    let s = dot(q.plane_normal, q.offset) / along;
    if s <= 0.0 {
        return q.depth;
    }
    let depth = s * length(direction) / light.emitter.range;
    let reach = MAX_CUBE_RECEIVER_SLOPE * length(direction - q.offset) / light.emitter.range;
    return clamp(depth, q.depth - reach, q.depth + reach);
}

// World size of one cube texel across the ray to `offset`: a face texel at
// major-axis distance m is 2m / resolution wide in the face plane, and m / |offset|
// of that across the ray (gnomon_math::omni::cube_texel_world_size).
fn cube_texel_world_size(offset: vec3<f32>) -> f32 {
    let m = max(abs(offset.x), max(abs(offset.y), abs(offset.z)));
    return 2.0 * m * m / (light.map.resolution * max(length(offset), 1e-20));
}

// The lookup direction `texels` (across the ray) from the receiver's.
fn cube_direction(q: CubeQuery, texels: vec2<f32>) -> vec3<f32> {
    return q.offset + (q.tangent * texels.x + q.bitangent * texels.y) * q.texel_world;
}

// One bilinear comparison tap `texels` from the lookup.
fn cube_compare_tap(q: CubeQuery, texels: vec2<f32>) -> f32 {
    let direction = cube_direction(q, texels);
    return textureSampleCompareLevel(shadow_cube, shadow_compare, direction, cube_tap_depth(q, direction));
}

// A rotated Poisson disk of `count` bilinear taps, `radius` texels wide.
fn cube_pcf_poisson(q: CubeQuery, radius: f32, count: u32) -> f32 {
    let rotation = disk_rotation(q.pixel);
    var sum = 0.0;
    for (var i = 0u; i < count; i++) {
        sum += cube_compare_tap(q, rotation * POISSON_DISK[i] * radius);
    }
    return sum / f32(count);
}

// A box or tent kernel `width` texels wide: a regular grid of bilinear taps one
// texel apart or closer, weighted by the kernel. Texel centres on the cube do not
// line up with a grid across the ray, so the exact-weight pairing of the 2D maps
// (pcf.wgsl) does not apply; the bilinear taps smooth the grid instead.
fn cube_pcf_grid(q: CubeQuery, width: f32, tent: bool) -> f32 {
    let n = i32(ceil(max(width, 1.0)));
    let step = width / f32(n);
    let h = 0.5 * width;
    var sum = 0.0;
    var total = 0.0;
    for (var j = 0; j < n; j++) {
        let y = (f32(j) + 0.5) * step - h;
        for (var i = 0; i < n; i++) {
            let x = (f32(i) + 0.5) * step - h;
            var w = 1.0;
            if tent {
                w = max(1.0 - abs(x) / h, 0.0) * max(1.0 - abs(y) / h, 0.0);
            }
            sum += w * cube_compare_tap(q, vec2<f32>(x, y));
            total += w;
        }
    }
    return sum / max(total, 1e-12);
}

// The kernel width in texels at this receiver (kernel_width_texels for the cube).
fn cube_kernel_width_texels(q: CubeQuery) -> f32 {
    if light.pcf.kernel_in_world == 1u {
        return clamp(light.pcf.kernel_width / q.texel_world, 1.0, MAX_KERNEL_TEXELS);
    }
    return light.pcf.kernel_width;
}
