// Hybrid ray-traced shadows (after Story's HFTS, GDC 2016, and Unreal's shadow-map
// ray tracing): the map answers where it is sure, a ray where it is not. This is the
// mask pass's half: it classifies each pixel, and lists the unsure ones for the trace
// pass (refine_trace.wgsl), which casts their rays in a compute pass dispatched over
// the list alone. Tracing in the mask pass itself would hold every lane of a group
// for its slowest ray: lockstep made a frame 3.3× dearer where 2 % of pixels traced.
//
// A pixel is unsure when its filtered visibility is strictly between 0 and 1 (the
// taps disagree: the edge band), or when `map_unsure` (refine_map.wgsl,
// refine_cube.wgsl, refine_omni.wgsl) finds its footprint in the map ambiguous. `REFINE_EVERY_PIXEL`
// lists every pixel instead: the exact baseline.

// The first three words are the trace pass's `dispatch_workgroups_indirect`
// arguments: one workgroup per REFINE_GROUP_SIZE pixels listed (at most
// REFINE_MAX_GROUPS, which then loop), by 1, by 1. All four start at zero, which
// dispatches nothing.
struct RefineCounters {
    groups_x: atomic<u32>,
    groups_y: u32,
    groups_z: u32,
    count: atomic<u32>,
};

@group(1) @binding(3) var<storage, read_write> unsure_pixels: array<UnsurePixel>;
@group(1) @binding(4) var<storage, read_write> refine_counters: RefineCounters;

// Whether a ray decides the pixel: it faces the light, lies inside its cone and range,
// and the map is unsure of it (or every pixel traces). `shadow` is the lookup's
// (visibility, layer).
fn ray_decides(
    shadow: vec2<f32>,
    world: vec3<f32>,
    n: vec3<f32>,
    geometric_n: vec3<f32>,
    l: vec3<f32>,
    cone: f32,
) -> bool {
    // Facing away from the light, or outside its cone or range: dark by definition,
    // which the map's answer already says.
    if dot(geometric_n, l) <= 0.0 || (light.kind != LIGHT_SUN && cone <= 0.0) {
        return false;
    }
    return REFINE_EVERY_PIXEL || (shadow.x > 0.0 && shadow.x < 1.0)
        || map_unsure(world, facing_side(n, geometric_n), geometric_n, l, u32(shadow.y));
}

// Appends `pixel` to the list, and counts one more workgroup for the trace pass at
// the start of every REFINE_GROUP_SIZE pixels.
fn defer_to_ray(pixel: vec2<u32>, layer: u32) {
    let index = atomicAdd(&refine_counters.count, 1u);
    if index == 0u {
        refine_counters.groups_y = 1u;
        refine_counters.groups_z = 1u;
    }
    if index % REFINE_GROUP_SIZE == 0u && index / REFINE_GROUP_SIZE < REFINE_MAX_GROUPS {
        atomicAdd(&refine_counters.groups_x, 1u);
    }
    // The list holds a pixel per pixel of the screen, and each pixel lists itself at
    // most once per light: the index is in bounds.
    unsure_pixels[index] = UnsurePixel(pixel.x | (pixel.y << 16u), layer);
}
